"""The equipment's HSMS transport (waferscan/host/hsms.py) against secsgem's own, unmodified
GemHostHandler over 127.0.0.1: probes, quick reconnections, a second host, sends without a
host, a bounded stop, a port in use, the active side and the message log."""

import errno
import logging
import socket
import struct
import threading
import time

import pytest
import secsgem.common
import secsgem.gem
import secsgem.hsms
from secsgem.gem.communication_state_machine import CommunicationState

from hsms_peers import free_port, wait_for
from waferscan.host import hsms
from waferscan.host.messages import registry

COMMUNICATING = CommunicationState.COMMUNICATING


def listening(port):
    """Whether a socket listens on ``port`` (read from /proc: connecting would be a probe)."""
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            with open(table) as rows:
                for row in rows.readlines()[1:]:
                    fields = row.split()
                    if fields[1].endswith(f":{port:04X}") and fields[3] == "0A":
                        return True
        except OSError:
            pass
    return False


def host_handler(port, passive=False, **timeouts):
    """secsgem's GemHostHandler as it is, on this link's registry (for stream 3). A passive
    one listens through this module's Listener: secsgem's own leaves a thread failing."""
    timeouts.setdefault("t3", 5.0)
    timeouts.setdefault("t5", 1.0)
    mode = secsgem.hsms.HsmsConnectMode
    kind = hsms.EquipmentSettings if passive else secsgem.hsms.HsmsSettings
    return secsgem.gem.GemHostHandler(kind(
        address="127.0.0.1", port=port, connect_mode=mode.PASSIVE if passive else mode.ACTIVE,
        device_type=secsgem.common.DeviceType.HOST, streams_functions=registry(), **timeouts))


def equipment_threads(settings):
    """The running threads of the equipment's link: named after its mode, address and port."""
    tag = f"{settings.connect_mode}_{settings.address}:{settings.port}"
    return [thread for thread in threading.enumerate() if thread.name.endswith(tag)]


@pytest.fixture
def equipment():
    """A GemEquipmentHandler on hsms.settings(), listening on a free port; closed after."""
    made = []

    def make(**timeouts):
        timeouts.setdefault("t3", 5.0)
        handler = hsms.attach(secsgem.gem.GemEquipmentHandler(
            hsms.settings("127.0.0.1", free_port(), **timeouts)))
        handler.enable()
        made.append(handler)
        assert wait_for(lambda: listening(handler.settings.port), 3)
        return handler

    yield make
    for handler in made:
        assert hsms.close(handler, 5)


@pytest.fixture
def hosts():
    made = []

    def make(port, **kwargs):
        handler = host_handler(port, **kwargs)
        made.append(handler)
        handler.enable()
        return handler

    yield make
    for handler in made:
        hsms.close(handler, 5)  # a stock host may not stop: not this module's to judge


def communicating(equipment, host, timeout_s=5.0):
    return host.waitfor_communicating(timeout_s) and wait_for(
        lambda: equipment.communication_state.current == COMMUNICATING, timeout_s)


def test_probes_that_connect_and_close_leave_the_equipment_listening(equipment, hosts):
    eq = equipment()
    port = eq.settings.port
    for probe in range(30):
        assert wait_for(lambda: listening(port), 3), f"not listening before probe {probe + 1}"
        sock = socket.create_connection(("127.0.0.1", port), timeout=2)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        sock.close()  # a reset, as a port scanner or a load balancer's check does
        time.sleep(0.02)  # back-to-back loopback connects stall in some VMs, secsgem or not
    host = hosts(port)
    assert communicating(eq, host)
    assert host.are_you_there() is not None


def test_quick_reconnections_select_every_time_and_leave_no_threads(equipment):
    eq = equipment()
    port = eq.settings.port
    idle = len(equipment_threads(eq.settings))
    for cycle in range(10):
        host = host_handler(port)
        host.enable()
        assert communicating(eq, host, 3), f"cycle {cycle + 1}"
        assert host.are_you_there() is not None
        hsms.close(host, 5)
        assert wait_for(lambda: listening(port), 3)
        assert wait_for(lambda: eq.communication_state.current != COMMUNICATING, 3)
        assert wait_for(lambda: len(equipment_threads(eq.settings)) <= idle, 3), (
            [t.name for t in equipment_threads(eq.settings)])


def test_a_second_host_is_refused_while_one_is_selected_and_taken_after(equipment, hosts):
    eq = equipment()
    port = eq.settings.port
    first = hosts(port)
    assert communicating(eq, first)
    assert not listening(port)
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", port), timeout=2).close()
    second = hosts(port)
    time.sleep(0.3)
    assert second.communication_state.current != COMMUNICATING
    assert first.are_you_there() is not None
    hsms.close(first, 5)
    assert communicating(eq, second, 8)  # the second host retries every T5 (1 s)
    assert second.are_you_there() is not None


def test_sending_with_no_host_fails_at_once_and_nothing_stale_reaches_the_next(equipment,
                                                                               hosts):
    eq = equipment()
    started = time.monotonic()
    assert eq.send_and_waitfor_response(eq.stream_function(1, 1)()) is None
    assert eq.send_stream_function(eq.stream_function(1, 1)()) is False
    assert time.monotonic() - started < 0.5
    host = hosts(eq.settings.port)
    assert communicating(eq, host)
    reply = eq.send_and_waitfor_response(eq.stream_function(1, 1)())
    assert reply is not None and (reply.header.stream, reply.header.function) == (1, 2)


def test_a_lost_host_ends_the_wait_for_its_reply(equipment, hosts):
    eq = equipment(t3=20.0)
    host = hosts(eq.settings.port)
    assert communicating(eq, host)
    host.register_stream_function(1, 1, lambda handler, message: time.sleep(0.3) or None)
    result = []
    waiting = threading.Thread(
        target=lambda: result.append(eq.send_and_waitfor_response(eq.stream_function(1, 1)())))
    waiting.start()
    time.sleep(0.1)
    started = time.monotonic()
    hsms.close(host, 5)
    waiting.join(5)
    assert not waiting.is_alive() and result == [None]
    assert time.monotonic() - started < 3.0  # not T3's 20 s


def test_close_is_bounded_and_leaves_no_thread_of_the_link(hosts):
    before = set(threading.enumerate())
    eq = hsms.attach(secsgem.gem.GemEquipmentHandler(hsms.settings("127.0.0.1", free_port())))
    eq.enable()
    host = hosts(eq.settings.port)
    assert communicating(eq, host)
    started = time.monotonic()
    assert hsms.close(eq, 5)
    took = time.monotonic() - started
    assert took < 2.0
    assert not listening(eq.settings.port) and equipment_threads(eq.settings) == []
    assert hsms.close(eq, 1)  # twice is harmless
    hsms.close(host, 5)

    def left():  # secsgem's host leaks a dispatcher per connection: those are not ours
        return [t for t in set(threading.enumerate()) - before
                if "HsmsConnectMode.ACTIVE" not in t.name and t.is_alive()]

    assert wait_for(lambda: not left(), 3), [t.name for t in left()]


def test_a_port_in_use_or_a_foreign_address_raises_oserror_at_enable():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        eq = secsgem.gem.GemEquipmentHandler(hsms.settings("127.0.0.1", port))
        with pytest.raises(OSError) as raised:
            eq.enable()
        assert raised.value.errno == errno.EADDRINUSE
        assert hsms.close(eq, 2)
    eq = secsgem.gem.GemEquipmentHandler(hsms.settings("192.0.2.1", free_port()))  # TEST-NET-1
    with pytest.raises(OSError) as raised:
        eq.enable()
    assert raised.value.errno == errno.EADDRNOTAVAIL
    assert hsms.close(eq, 2)


def test_the_active_side_connects_to_a_listening_host_and_stops(hosts):
    port = free_port()
    host = hosts(port, passive=True)
    assert wait_for(lambda: listening(port), 3)
    eq = hsms.attach(secsgem.gem.GemEquipmentHandler(
        hsms.settings("127.0.0.1", port, active=True, t5=1.0)))
    eq.enable()
    try:
        assert communicating(eq, host)
        assert host.are_you_there() is not None
    finally:
        assert hsms.close(eq, 5)
    assert equipment_threads(eq.settings) == []


def test_the_message_log_shows_one_handlers_messages_as_sml(equipment, hosts):
    logger = logging.getLogger(hsms.COMMUNICATION_LOGGER)
    level, propagate = logger.level, logger.propagate
    eq = equipment()
    eq_lines, host_lines = [], []
    eq_log = hsms.attach_log(eq_lines.append, eq.settings.name)
    host = hosts(eq.settings.port)
    host_log = hsms.attach_log(host_lines.append, host.settings.name)
    try:
        assert logger.propagate is False and logger.getEffectiveLevel() <= logging.INFO
        assert communicating(eq, host)
        assert host.are_you_there() is not None
        assert wait_for(lambda: "> S1F2\n  <L [2]\n    <A \"secsgem\">\n    <A \"0.3.0\">\n  > ."
                        in eq_lines)
        assert "< Select.req" in eq_lines and "> Select.rsp" in eq_lines
        assert "< S1F1 W ." in eq_lines and "> S1F1 W ." in host_lines
        assert "> S1F1 W ." not in eq_lines and "< Select.req" not in host_lines
    finally:
        hsms.detach_log(host_log)
        hsms.detach_log(eq_log)
    assert (logger.level, logger.propagate) == (level, propagate)
