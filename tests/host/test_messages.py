"""SECS-II definitions of the host link (waferscan/host/messages.py): S3F17/S3F18 in the shape a
real host sends, byte for byte and over HSMS against secsgem's own GemHostHandler; typed values
read back as sent; messages no registry can decode, answered instead of dropped."""

import doctest
import time

import pytest
import secsgem.common
import secsgem.gem
import secsgem.hsms
from secsgem.hsms.message import HsmsMessage
from secsgem.hsms.stream_function_header import HsmsStreamFunctionHeader
from secsgem.secs import variables as V
from secsgem.secs.variables.dynamic import ANYVALUE

from hsms_peers import Raw, free_port, wait_for
from waferscan.host import hsms, messages
from waferscan.host.messages import Undecodable, is_u1_list, plain, registry, slot_map_item, typed

SLOTS = [1] * 10 + [0] * 15


def as_message(function, system=1):
    """The HSMS message a peer would receive for ``function`` (its encoded bytes)."""
    header = HsmsStreamFunctionHeader(system, function.stream, function.function,
                                      function.is_reply_required, 0)
    return HsmsMessage(header, function.encode())


def raw_message(stream, function, body=b"", reply=True):
    return HsmsMessage(HsmsStreamFunctionHeader(7, stream, function, reply, 0), body)


def host_s3f17(carrier_id="CAR001", attributes=None):
    """S3F17 as factory hosts send it: U4 DATAID, U1 PTN, E87's carrier attributes."""
    content = [V.Array(ANYVALUE, [V.String("LOT-A" if s else ""), V.String(f"W{i + 1:02d}")])
               for i, s in enumerate(SLOTS)]
    if attributes is None:
        attributes = [
            {"ATTRID": "Capacity", "ATTRDATA": V.U1(25)},
            {"ATTRID": "Usage", "ATTRDATA": "PRODUCT"},
            {"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U1, SLOTS)},
            {"ATTRID": "ContentMap", "ATTRDATA": V.Array(ANYVALUE, content)},
        ]
    return registry().function(3, 17)({
        "DATAID": V.U4(100), "CARRIERACTION": "ProceedWithCarrier", "CARRIERID": carrier_id,
        "PTN": V.U1(1), "CATTRS": attributes})


def wire_types(item):
    """The wire type names of a decoded item, nested lists as nested lists."""
    while isinstance(item, V.Dynamic):
        item = item.value
    if isinstance(item, V.Array):
        return [wire_types(element) for element in item.data]
    return type(item).__name__


def test_doctests():
    failures, tried = doctest.testmod(messages)
    assert tried > 0 and failures == 0


def test_s3f17_in_a_real_hosts_shape_decodes_to_the_same_values_and_wire_types():
    sent = host_s3f17()
    data = sent.encode()
    got = registry().decode(as_message(sent))
    assert got.encode() == data
    assert (got.DATAID.get(), got.CARRIERACTION.get(), got.CARRIERID.get(), got.PTN.get()) == (
        100, "ProceedWithCarrier", "CAR001", 1)
    assert (wire_types(got.DATAID), wire_types(got.PTN)) == ("U4", "U1")
    attributes = {a.ATTRID.get(): a.ATTRDATA for a in got.CATTRS}
    assert list(attributes) == ["Capacity", "Usage", "SlotMap", "ContentMap"]
    assert plain(attributes["Capacity"]) == 25 and wire_types(attributes["Capacity"]) == "U1"
    assert plain(attributes["Usage"]) == "PRODUCT" and wire_types(attributes["Usage"]) == "String"
    assert plain(attributes["SlotMap"]) == SLOTS
    assert wire_types(attributes["SlotMap"]) == ["U1"] * 25
    assert is_u1_list(attributes["SlotMap"]) and not is_u1_list(attributes["ContentMap"])
    assert plain(attributes["ContentMap"])[0] == ["LOT-A", "W01"]
    assert wire_types(attributes["ContentMap"]) == [["String", "String"]] * 25
    assert messages.sml(got).splitlines()[:3] == ["S3F17 W", "  <L [5]", "    <U4 100 >"]


def test_an_empty_attribute_list_and_a_ptn_sent_as_u4_decode():
    sent = host_s3f17(attributes=[])
    got = registry().decode(as_message(sent))
    assert got.CATTRS.get() == [] and got.encode() == sent.encode()
    as_u4 = registry().function(3, 17)({"DATAID": V.U4(1), "CARRIERACTION": "CancelCarrier",
                                        "CARRIERID": "C", "PTN": V.U4(2), "CATTRS": []})
    got = registry().decode(as_message(as_u4))
    assert got.PTN.get() == 2 and wire_types(got.PTN) == "U4"
    plain_ptn = registry().function(3, 17)({"DATAID": V.U4(1), "CARRIERACTION": "x",
                                            "CARRIERID": "C", "PTN": 3, "CATTRS": []})
    assert wire_types(plain_ptn.PTN) == "U1"


def test_s3f18_and_s14f2_send_errcode_as_u4_and_decode_any_integer_type():
    reply = registry().function(3, 18)({"CAACK": 3, "ERRORS": [{"ERRCODE": 7, "ERRTEXT": "bad"}]})
    got = registry().decode(as_message(reply))
    assert got.CAACK.get() == 3 and got.ERRORS.get() == [{"ERRCODE": 7, "ERRTEXT": "bad"}]
    assert wire_types(got.ERRORS[0].ERRCODE) == "U4"
    i2 = registry().function(3, 18)({"CAACK": 3, "ERRORS": [{"ERRCODE": V.I2(7), "ERRTEXT": ""}]})
    assert registry().decode(as_message(i2)).ERRORS[0].ERRCODE.get() == 7
    s14f2 = registry().function(14, 2)({
        "DATA": [{"OBJID": "CAR001", "ATTRIBS": [{"ATTRID": "SlotMap",
                                                  "ATTRDATA": slot_map_item(SLOTS)}]}],
        "ERRORS": {"OBJACK": 1, "ERROR": [{"ERRCODE": 4, "ERRTEXT": "unknown attribute"}]}})
    got = registry().decode(as_message(s14f2))
    assert wire_types(got.ERRORS.ERROR[0].ERRCODE) == "U4"
    assert plain(got.DATA[0].ATTRIBS[0].ATTRDATA) == SLOTS
    assert is_u1_list(got.DATA[0].ATTRIBS[0].ATTRDATA)


@pytest.mark.parametrize("value, types", [
    (True, "Boolean"), (0, "U1"), (255, "U1"), (256, "U4"), (2**32, "U8"), (-1, "I4"),
    (-(2**40), "I8"), (1.5, "F8"), ("LOT-A", "String"), (b"\x01", "Binary"),
    ([1, 0, 3], ["U1"] * 3), ((1, 300), ["U4", "U4"]), ([1, -1], ["U1", "I4"]),
    (["A", 2], ["String", "U1"]), ([["LOT", "W1"], ["", ""]], [["String"] * 2] * 2), ([], []),
])
def test_typed_values_go_over_the_wire_and_read_back_as_plain_python(value, types):
    sent = typed(value)
    wrapped = registry().function(6, 11)({"DATAID": V.U4(1), "CEID": V.U4(2), "RPT": [
        {"RPTID": V.U4(3), "V": [sent]}]})
    got = registry().decode(as_message(wrapped)).RPT[0].V[0]
    expected = list(value) if isinstance(value, tuple) else value
    if isinstance(value, list):
        expected = [list(v) if isinstance(v, tuple) else v for v in value]
    assert plain(got) == expected
    assert wire_types(got) == types


def test_is_u1_list_refuses_what_a_slot_map_must_not_be():
    def decoded(item):
        function = registry().function(3, 17)({"DATAID": V.U4(1), "CARRIERACTION": "x",
                                               "CARRIERID": "C", "PTN": 1, "CATTRS": [
                                                   {"ATTRID": "SlotMap", "ATTRDATA": item}]})
        return registry().decode(as_message(function)).CATTRS[0].ATTRDATA

    assert is_u1_list(decoded(slot_map_item(SLOTS)))
    assert not is_u1_list(decoded(V.Array(V.U4, SLOTS)))
    assert not is_u1_list(decoded(typed(["1", "0"])))
    assert not is_u1_list(decoded(V.U1(SLOTS)))  # one U1 array item, not a list of U1
    assert not is_u1_list(decoded(V.String("1111")))
    assert is_u1_list(decoded(V.Array(V.U1, [])))


@pytest.mark.parametrize("stream, function, body, s9_function", [
    (99, 1, b"", 3),  # no stream 99
    (1, 99, b"", 5),  # stream 1 has no function 99
    (1, 3, V.U4(5).encode(), 7),  # S1F3 must be a list
    (3, 17, V.String("x").encode(), 7),
])
def test_a_message_that_cannot_be_decoded_names_the_s9_answer(stream, function, body,
                                                             s9_function):
    got = registry().decode(raw_message(stream, function, body))
    assert isinstance(got, Undecodable)
    assert (got.stream, got.function, got.s9_function) == (stream, function, s9_function)
    assert got.reply_wanted and len(got.mhead) == 10
    assert repr(got).startswith(f"S{stream}F{function} W <undecodable: ") and repr(got).endswith(
        "> .")
    with pytest.raises(ValueError):
        registry().decode(None)


@pytest.fixture
def link():
    """A GemEquipmentHandler on this module's registry and secsgem's GemHostHandler, both on
    a registry(), COMMUNICATING over 127.0.0.1; the equipment's message log."""
    port = free_port()
    lines = []
    eq_settings = hsms.settings("127.0.0.1", port, t3=5.0)
    log = hsms.attach_log(lines.append, eq_settings.name)
    equipment = hsms.attach(secsgem.gem.GemEquipmentHandler(eq_settings))
    equipment.enable()
    host = secsgem.gem.GemHostHandler(secsgem.hsms.HsmsSettings(
        address="127.0.0.1", port=port, connect_mode=secsgem.hsms.HsmsConnectMode.ACTIVE,
        device_type=secsgem.common.DeviceType.HOST, streams_functions=registry(), t3=5.0,
        t5=1.0))
    host.enable()
    try:
        assert host.waitfor_communicating(10)
        yield equipment, host, lines
    finally:
        hsms.close(host, 5)
        hsms.close(equipment, 5)
        hsms.detach_log(log)


def test_s3f17_over_hsms_reaches_the_equipment_as_sent_and_s3f18_comes_back(link):
    equipment, host, lines = link
    received = []

    def on_carrier_action(handler, message):
        request = handler.settings.streams_functions.decode(message)
        received.append(request)
        slot_map = {a.ATTRID.get(): a.ATTRDATA for a in request.CATTRS}.get("SlotMap")
        if slot_map is not None and not is_u1_list(slot_map):
            return handler.stream_function(3, 18)(
                {"CAACK": 3, "ERRORS": [{"ERRCODE": 7, "ERRTEXT": "SlotMap must be U1s"}]})
        return handler.stream_function(3, 18)({"CAACK": 0, "ERRORS": []})

    equipment.register_stream_function(3, 17, on_carrier_action)
    reply = registry().decode(host.send_and_waitfor_response(host_s3f17()))
    assert (reply.CAACK.get(), reply.ERRORS.get()) == (0, [])
    assert received[0].encode() == host_s3f17().encode()
    bad = host_s3f17(attributes=[{"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U4, SLOTS)}])
    reply = registry().decode(host.send_and_waitfor_response(bad))
    assert reply.CAACK.get() == 3 and wire_types(reply.ERRORS[0].ERRCODE) == "U4"
    assert any(line.startswith("< S3F17 W\n  <L [5]") for line in lines)
    assert any(line.startswith("> S3F18\n") for line in lines)


def test_an_undecodable_message_is_logged_and_dispatched_not_dropped(link):
    equipment, host, lines = link
    started = time.monotonic()
    # secsgem's stock handler answers these (the equipment's own answer is the S9 function
    # the Undecodable names); with secsgem's registry they are dropped and the host waits T3.
    unknown = host.send_and_waitfor_response(Raw(99, 1))
    assert (unknown.header.stream, unknown.header.function) == (9, 5)
    malformed = host.send_and_waitfor_response(Raw(1, 3, V.U4(5).encode()))
    assert (malformed.header.stream, malformed.header.function) == (1, 0)  # the handler's abort
    assert time.monotonic() - started < 2.0
    assert wait_for(lambda: any(line.startswith("< S99F1 W <undecodable: ") for line in lines))
    assert any(line.startswith("< S1F3 W <undecodable: ") for line in lines)
