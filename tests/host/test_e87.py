"""SEMI E87's slot-map state model of a load port (SPEC §14), without SECS/GEM: the transitions,
the host's carrier actions and what each is answered, and GetAttr's attributes."""

import doctest
import threading

import pytest

from waferscan.core.mapping import E87, EMPTY, PRESENT, UNSCANNED
from waferscan.host import e87, ids
from waferscan.host.e87 import (
    ACKNOWLEDGED,
    CANNOT_PERFORM_NOW,
    INVALID_COMMAND,
    INVALID_DATA,
    REJECTED_INVALID_STATE,
    SLOT_MAP_NOT_READ,
    VERIFICATION_FAILED,
    VERIFICATION_OK,
    WAITING_FOR_HOST,
    LoadPort,
    LoadPorts,
)

PAPER_E87 = tuple(int(c) for c in "3313553113551113131111131")


@pytest.mark.parametrize("module", [e87, ids])
def test_doctests(module):
    failures, tried = doctest.testmod(module)
    assert tried > 0 and failures == 0


def waiting(slot_map=PAPER_E87, carrier_id="FOUP1"):
    ports = LoadPorts([LoadPort(1, "LP1", len(slot_map)), LoadPort(2, "LP2", 25)])
    ports.arrive(1, carrier_id)
    ports.slot_map_read(1, slot_map)
    return ports


def test_a_carrier_goes_through_the_states_each_a_transition_with_its_data():
    ports = LoadPorts([LoadPort(1, "LP1", 25)])
    arrived = ports.arrive(1, "FOUP1")
    assert (arrived.port, arrived.carrier_id, arrived.status) == (1, "FOUP1", SLOT_MAP_NOT_READ)
    assert arrived.slot_map == (0,) * 25  # not read: undefined, never "empty"
    read = ports.slot_map_read(1, PAPER_E87, warnings=("a warning",))
    assert (read.status, read.slot_map, read.status_name) == (
        WAITING_FOR_HOST, PAPER_E87, "WAITING FOR HOST")
    reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1,
                                         [("SlotMap", list(PAPER_E87))])
    assert reply == e87.ActionReply(ACKNOWLEDGED)
    assert [(t.status, t.slot_map, t.reason) for t in events] == [
        (VERIFICATION_OK, PAPER_E87, "")]
    assert ports.port(1).status == VERIFICATION_OK and ports.port(1).warnings == ("a warning",)


def test_proceed_without_a_map_accepts_the_map_as_read():
    ports = waiting()
    reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [])
    assert reply.caack == ACKNOWLEDGED and events[0].status == VERIFICATION_OK


def test_the_real_hosts_attributes_are_accepted_and_kept():
    ports = waiting()
    content = [["LOT1", f"W{i:02d}"] for i in range(1, 26)]
    reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [
        ("Capacity", 25), ("Usage", "PRODUCT"), ("SlotMap", list(PAPER_E87)),
        ("ContentMap", content), ("SubstrateCount", 12)])
    assert reply.caack == ACKNOWLEDGED, reply
    found, errors = ports.attributes("FOUP1", ["Usage", "ContentMap", "SlotMapStatus",
                                               "SubstrateCount"])
    assert errors == []
    assert found == [("Usage", "PRODUCT"), ("ContentMap", content),
                     ("SlotMapStatus", VERIFICATION_OK), ("SubstrateCount", 12)]


def test_a_differing_map_is_refused_naming_the_first_differing_slot():
    ports = waiting()
    expected = list(PAPER_E87)
    expected[2] = 3  # slot 3 occupied, the carrier's is empty
    expected[6] = 1  # and a later difference, not the one named
    reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1,
                                         [("SlotMap", expected)])
    assert reply.caack == INVALID_DATA
    assert [(e.code, e.text) for e in reply.errors] == [
        (e87.VERIFICATION_ERROR, "SlotMap slot 3: the host expects 3 (correctly occupied), "
                                 "the equipment read 1 (empty)")]
    assert events[0].status == VERIFICATION_FAILED and events[0].reason == reply.errors[0].text
    assert ports.port(1).status == VERIFICATION_FAILED
    # once failed, a second proceed is in the wrong state
    again, more = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [])
    assert again.caack == REJECTED_INVALID_STATE and more == []
    assert "VERIFICATION FAILED" in again.errors[0].text


@pytest.mark.parametrize("attributes, reason", [
    ([("Capacity", 24)], "Capacity 24: the carrier has 25 slots"),
    ([("SubstrateCount", 10)], "SubstrateCount 10: the equipment read 12 slots holding a substrate"),
    ([("SlotMap", [3] * 24)], "SlotMap has 24 slots, the carrier 25"),
])
def test_capacity_count_and_length_are_verified(attributes, reason):
    ports = waiting()
    reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP1", 0, attributes)
    assert (reply.caack, reply.errors[0].text, events[0].status) == (
        INVALID_DATA, reason, VERIFICATION_FAILED)


def test_an_unscanned_slot_never_passes_for_empty():
    code = (E87[PRESENT], E87[UNSCANNED], E87[EMPTY])
    assert code == (3, 0, 1)
    ports = waiting(code)
    reply, _ = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [("SlotMap", [3, 1, 1])])
    assert reply.errors[0].text == ("SlotMap slot 2: the host expects 1 (empty), the equipment "
                                    "read 0 (undefined) - the slot was not wholly scanned")


@pytest.mark.parametrize("action, carrier, port, attributes, caack, code, text", [
    ("ProceedWithCarier", "FOUP1", 1, [], INVALID_COMMAND, e87.UNSUPPORTED_OPTION,
     "unknown carrier action 'ProceedWithCarier' (this load port carries out "
     "ProceedWithCarrier and CancelCarrier)"),
    ("ProceedWithCarrier", "FOUP9", 1, [], INVALID_DATA, e87.UNKNOWN_OBJECT_INSTANCE,
     "no carrier 'FOUP9' at any load port"),
    ("ProceedWithCarrier", "FOUP1", 2, [], INVALID_DATA, e87.INVALID_ATTRIBUTE_VALUE,
     "carrier 'FOUP1' is at port 1, not port 2"),
    ("ProceedWithCarrier", "FOUP1", 7, [], INVALID_DATA, e87.LOAD_PORT_DOES_NOT_EXIST,
     "carrier 'FOUP1' is at port 1, not port 7 (no port 7)"),
    ("ProceedWithCarrier", "FOUP1", 1, [("Colour", "red")], INVALID_DATA, e87.UNKNOWN_ATTRIBUTE,
     "unknown attribute 'Colour' for ProceedWithCarrier (known: Capacity, SubstrateCount, "
     "SlotMap, Usage, ContentMap)"),
    ("ProceedWithCarrier", "FOUP1", 1, [("SlotMap", [3, 9])], INVALID_DATA,
     e87.INVALID_ATTRIBUTE_VALUE, "SlotMap: expected a list of E87 slot values 0-5, got [3, 9]"),
    ("ProceedWithCarrier", "FOUP1", 1, [("Capacity", "25")], INVALID_DATA,
     e87.INVALID_ATTRIBUTE_VALUE, "Capacity: expected an integer, got '25'"),
    ("ProceedWithCarrier", "FOUP1", 1, [("ContentMap", [["L", "W"]])], INVALID_DATA,
     e87.INVALID_ATTRIBUTE_VALUE, "ContentMap has 1 entries, the carrier 25 slots"),
])
def test_a_malformed_or_misdirected_action_is_refused_and_changes_nothing(
        action, carrier, port, attributes, caack, code, text):
    ports = waiting()
    reply, events = ports.carrier_action(action, carrier, port, attributes)
    assert (reply.caack, [(e.code, e.text) for e in reply.errors], events) == (
        caack, [(code, text)], [])
    assert ports.port(1).status == WAITING_FOR_HOST  # the host may send it again, corrected
    assert ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [])[0].caack == ACKNOWLEDGED


def test_proceed_before_the_map_is_read_cannot_be_performed_now():
    ports = LoadPorts([LoadPort(1, "LP1", 25)])
    ports.arrive(1, "FOUP1")
    reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [])
    assert reply.caack == CANNOT_PERFORM_NOW and events == []


def test_cancel_frees_the_port_and_reports_the_carrier_gone():
    ports = waiting()
    reply, events = ports.carrier_action("CancelCarrier", "FOUP1", 1, [])
    assert reply.caack == ACKNOWLEDGED
    assert [(t.carrier_id, t.status, t.status_name, t.reason) for t in events] == [
        ("FOUP1", None, "CARRIER CANCELLED", "cancelled by the host")]
    assert ports.find("FOUP1") is None and ports.port(1).carrier_id is None
    assert ports.carrier_action("CancelCarrier", "FOUP1", 1, [])[0].caack == INVALID_DATA
    # the port takes a new carrier
    assert ports.arrive(1, "FOUP2").status == SLOT_MAP_NOT_READ


def test_get_attributes_of_a_carrier():
    ports = waiting()
    found, errors = ports.attributes("FOUP1")
    assert [name for name, _ in found] == list(e87.CARRIER_ATTRIBUTES)
    values = dict(found)
    assert values["ObjID"] == "FOUP1" and values["SlotMap"] == list(PAPER_E87)
    assert (values["SlotMapStatus"], values["Capacity"], values["SubstrateCount"]) == (1, 25, 12)
    found, errors = ports.attributes("FOUP1", ["Capacity", "Weight"])
    assert found == [("Capacity", 25)] and [e.code for e in errors] == [e87.UNKNOWN_ATTRIBUTE]
    assert ports.attributes("NOPE") is None


def test_a_carrier_cancelled_while_it_is_scanned_is_not_read_and_a_waiting_port_is_occupied():
    ports = LoadPorts([LoadPort(1, "LP1", 25)])
    ports.arrive(1, "FOUP1")
    assert "FOUP1" in ports.occupant(1) and "SLOT MAP NOT READ" in ports.occupant(1)
    assert ports.carrier_action("CancelCarrier", "FOUP1", 1, [])[0].caack == ACKNOWLEDGED
    assert ports.slot_map_read(1, PAPER_E87, carrier_id="FOUP1") is None
    assert ports.occupant(1) is None
    ports.arrive(1, "FOUP2")
    ports.slot_map_read(1, PAPER_E87, carrier_id="FOUP2")
    assert "WAITING FOR HOST" in ports.occupant(1)
    ports.carrier_action("ProceedWithCarrier", "FOUP2", 1, [])
    assert ports.occupant(1) is None  # verified: the next carrier may come


def test_a_map_cannot_be_read_twice_or_of_the_wrong_length():
    ports = waiting()
    with pytest.raises(ValueError, match="no carrier waiting"):
        ports.slot_map_read(1, PAPER_E87)
    ports.arrive(2, "FOUP2")
    with pytest.raises(ValueError, match="24 slots read, capacity 25"):
        ports.slot_map_read(2, PAPER_E87[:24])


def test_only_one_of_two_hosts_racing_gets_the_carrier_verified():
    ports = waiting()
    replies = []
    barrier = threading.Barrier(8)

    def proceed():
        barrier.wait()
        replies.append(ports.carrier_action("ProceedWithCarrier", "FOUP1", 1, [])[0].caack)

    threads = [threading.Thread(target=proceed) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(replies) == [ACKNOWLEDGED] + [REJECTED_INVALID_STATE] * 7
