"""``waferscan serve`` (SPEC §14) against a SECS/GEM host no one here wrote: secsgem's own
``GemHostHandler``, unmodified, driven by the test over HSMS on 127.0.0.1. The host sets up its
event reports as real hosts do (S2F33/35/37), a carrier arrives on the MCS link's LOAD, and the
host verifies the slot map with S3F17 in the shape a production host sends it."""

import queue
import signal
import socket
import subprocess
import threading

import pytest
import secsgem.common
import secsgem.gem
import secsgem.hsms
from commands import CLI, wait_for
from hsms_peers import Raw, free_port
from scenarios import ROOT, TWO_CARRIERS_TEXT
from secsgem.secs import variables as V
from secsgem.secs.variables.dynamic import ANYVALUE

from waferscan.host import messages
from waferscan.host.ids import DEFAULTS

PAPER = ROOT / "resources" / "examples" / "paper.toml"
PAPER_E87 = [int(c) for c in "3313553113551113131111131"]
EVENTS, DATA, STATUS = DEFAULTS["events"], DEFAULTS["data"], DEFAULTS["status"]
REPORT_ID = 4001


class Server:
    """``waferscan serve`` in a process of its own; its output in files."""

    def __init__(self, tmp_path, *args, layout=PAPER, port=None):
        self.port = port or free_port()
        self.folder = tmp_path / "mcs"
        self.folder.mkdir(exist_ok=True)
        self.out_path, self.err_path = tmp_path / "serve.out", tmp_path / "serve.err"
        self.process = subprocess.Popen(
            [*CLI, "serve", str(layout), "--hsms", f"127.0.0.1:{self.port}",
             "--mcs", str(self.folder), *map(str, args)],
            cwd=ROOT, stdout=self.out_path.open("w"), stderr=self.err_path.open("w"))
        self.seq = 0

    @property
    def out(self):
        return self.out_path.read_text()

    def ready(self, timeout=120):
        assert wait_for(lambda: "Ctrl-C to stop" in self.out or self.process.poll() is not None,
                        timeout), "serve did not start"
        assert self.process.poll() is None, self.err_path.read_text()

    def load(self, *args):
        """``<seq> LOAD ARGS`` on the MCS link; results.txt's answer to it."""
        self.seq += 1
        with (self.folder / "commands.txt").open("a") as commands:
            commands.write(f"{self.seq} LOAD {' '.join(args)}\n")
        results = self.folder / "results.txt"
        assert wait_for(lambda: results.exists()
                        and results.read_text().startswith(f"seq = {self.seq}\n"), 120)
        return dict(line.split(" = ", 1) for line in results.read_text().split("\n\n")[0]
                    .splitlines() if " = " in line)

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            return self.process.wait(30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(10)
            raise


@pytest.fixture
def server(tmp_path):
    servers = []

    def start(*args, **kwargs):
        s = Server(tmp_path, *args, **kwargs)
        servers.append(s)
        s.ready()
        return s

    yield start
    for s in servers:  # every server outlived what its test did to it, and stops cleanly
        alive = s.process.poll() is None
        code = s.stop() if alive else s.process.returncode
        err = s.err_path.read_text()
        assert "Traceback" not in err and "internal error" not in err, err
        if alive:
            assert code == 0, err


class Host:
    """secsgem's GEM host handler, as a host-integration engineer would drive it."""

    def __init__(self, port):
        settings = secsgem.hsms.HsmsSettings(
            address="127.0.0.1", port=port, connect_mode=secsgem.hsms.HsmsConnectMode.ACTIVE,
            device_type=secsgem.common.DeviceType.HOST, streams_functions=messages.registry(),
            t3=10.0, t5=1.0)
        self.handler = secsgem.gem.GemHostHandler(settings)
        self.events = queue.Queue()
        self.closed = False
        self.handler.register_stream_function(6, 11, self._on_event)
        # secsgem starts its connecting and reading threads as non-daemon threads, and a thread
        # inherits that flag from the thread that starts it: enabled from a daemon thread, a
        # host whose threads never end (secsgem 0.3.0's state machine can wedge when a
        # connection is reset as it opens) cannot keep pytest's process from exiting.
        self._in_daemon(self.handler.enable, "enable")

    @staticmethod
    def _in_daemon(call, what, timeout=30):
        thread = threading.Thread(target=call, daemon=True, name=f"test host {what}")
        thread.start()
        thread.join(timeout)
        assert not thread.is_alive(), f"secsgem's host did not {what} within {timeout} s"

    def _on_event(self, handler, message):
        event = handler.settings.streams_functions.decode(message)
        values = {}
        for report in event.RPT:
            values.update(zip(REPORT_VARIABLES, report.V.get()))
        self.events.put((event.CEID.get(), values))
        return handler.stream_function(6, 12)(0)

    def communicating(self, timeout=10):
        return self.handler.waitfor_communicating(timeout)

    def ask(self, stream, function, value=None):
        reply = self.handler.send_and_waitfor_response(
            self.handler.stream_function(stream, function)(value))
        assert reply is not None, f"no answer to S{stream}F{function}"
        return self.handler.settings.streams_functions.decode(reply)

    def subscribe(self):
        """Delete every report, define one with the transition's data, link it to every
        slot-map event and enable them: the acks must all be 0."""
        assert self.ask(2, 33, {"DATAID": V.U4(1), "DATA": []}).get() == 0
        assert self.ask(2, 33, {"DATAID": V.U4(2), "DATA": [{"RPTID": V.U4(REPORT_ID), "VID": [
            V.U4(DATA[key]) for key in REPORT_VARIABLES]}]}).get() == 0
        assert self.ask(2, 35, {"DATAID": V.U4(3), "DATA": [
            {"CEID": V.U4(ceid), "RPTID": [V.U4(REPORT_ID)]} for ceid in EVENTS.values()]}
        ).get() == 0
        assert self.ask(2, 37, {"CEED": True, "CEID": []}).get() == 0

    def event(self, timeout=60):
        return self.events.get(timeout=timeout)

    def proceed(self, carrier_id, port=1, attributes=()):
        reply = self.ask(3, 17, {"DATAID": V.U4(7), "CARRIERACTION": "ProceedWithCarrier",
                                 "CARRIERID": carrier_id, "PTN": V.U1(port),
                                 "CATTRS": list(attributes)})
        return reply.CAACK.get(), [(e.ERRCODE.get(), e.ERRTEXT.get()) for e in reply.ERRORS]

    def close(self):
        if not self.closed:
            self.closed = True
            self._in_daemon(self.handler.disable, "disable")


REPORT_VARIABLES = ("port_id", "carrier_id", "slot_map", "slot_map_status", "reason")


def real_host_attributes(slot_map, lot="LOT0042"):
    """What a production host sends with ProceedWithCarrier (DOMAIN-NOTES)."""
    content = V.Array(ANYVALUE, [V.Array(ANYVALUE, [V.String(lot), V.String(f"{lot}.{i:02d}")])
                                 for i in range(1, 26)])
    return [{"ATTRID": "Capacity", "ATTRDATA": V.U1(25)},
            {"ATTRID": "Usage", "ATTRDATA": V.String("PRODUCT")},
            {"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U1, list(slot_map))},
            {"ATTRID": "ContentMap", "ATTRDATA": content}]


@pytest.fixture
def host():
    hosts = []

    def connect(port, timeout=10):
        h = Host(port)
        hosts.append(h)
        assert h.communicating(timeout), "the host did not reach COMMUNICATING"
        return h

    yield connect
    stuck = []
    for h in hosts:
        try:
            h.close()
        except AssertionError as error:
            stuck.append(str(error))
    assert not stuck, stuck


def test_the_paper_is_mapped_reported_and_verified(server, host):
    s = server("--empty")
    h = host(s.port)
    h.subscribe()
    answer = s.load("FOUP0001")
    assert (answer["command"], answer["status"], answer["code"], answer["e87"]) == (
        "LOAD", "ok", "1101221001220001010000010", "3313553113551113131111131")
    assert answer["message"] == "carrier FOUP0001 at port 1: WAITING FOR HOST"
    ceid, values = h.event()
    assert (ceid, values["carrier_id"], values["slot_map_status"]) == (
        EVENTS["slot_map_not_read"], "FOUP0001", 0)
    assert values["slot_map"] == [0] * 25
    ceid, values = h.event()
    assert (ceid, values["port_id"], values["carrier_id"], values["slot_map"],
            values["slot_map_status"]) == (EVENTS["waiting_for_host"], 1, "FOUP0001", PAPER_E87, 1)
    # the status variables say the same
    status = h.ask(1, 3, [V.U4(STATUS[k] + 1) for k in ("carrier_id", "slot_map",
                                                           "slot_map_status")]).get()
    assert status == ["FOUP0001", PAPER_E87, 1]
    assert h.proceed("FOUP0001", attributes=real_host_attributes(PAPER_E87)) == (0, [])
    ceid, values = h.event()
    assert (ceid, values["slot_map_status"], values["reason"]) == (EVENTS["verification_ok"], 2,
                                                                   "")
    got = h.ask(14, 1, {"OBJSPEC": "", "OBJTYPE": "Carrier", "OBJID": ["FOUP0001"],
                        "FILTER": [], "ATTRID": ["SlotMapStatus", "Usage", "Capacity"]})
    assert got.DATA[0].ATTRIBS.get() == [{"ATTRID": "SlotMapStatus", "ATTRDATA": 2},
                                         {"ATTRID": "Usage", "ATTRDATA": "PRODUCT"},
                                         {"ATTRID": "Capacity", "ATTRDATA": 25}]
    assert s.stop() == 0


def test_a_host_expecting_slot_3_occupied_fails_the_verification(server, host):
    s = server("--empty")
    h = host(s.port)
    h.subscribe()
    s.load("FOUP0002")
    h.event(), h.event()
    expected = list(PAPER_E87)
    expected[2] = 3
    caack, errors = h.proceed("FOUP0002", attributes=real_host_attributes(expected))
    reason = ("SlotMap slot 3: the host expects 3 (correctly occupied), the equipment read 1 "
              "(empty)")
    assert (caack, errors) == (3, [(9, reason)])
    ceid, values = h.event()
    assert (ceid, values["slot_map_status"], values["reason"]) == (
        EVENTS["verification_failed"], 3, reason)
    # and it stays failed: a second proceed is in the wrong state
    assert h.proceed("FOUP0002")[0] == 5


def test_cancel_and_a_carrier_at_start(server, host):
    s = server()  # the paper's carrier arrives at the start, named as the layout names it
    assert wait_for(lambda: "port 1: carrier LP1 WAITING FOR HOST" in s.out, 60)
    h = host(s.port)
    carrier = s.out.split("ports 1 = ")[1].split(" (")[0]
    assert carrier == "LP1"
    reply = h.ask(3, 17, {"DATAID": V.U4(8), "CARRIERACTION": "CancelCarrier",
                          "CARRIERID": carrier, "PTN": V.U1(1), "CATTRS": []})
    assert (reply.CAACK.get(), reply.ERRORS.get()) == (0, [])
    gone = h.ask(14, 1, {"OBJSPEC": "", "OBJTYPE": "Carrier", "OBJID": [carrier], "FILTER": [],
                         "ATTRID": []})
    assert gone.ERRORS.OBJACK.get() == 1
    assert gone.ERRORS.ERROR.get()[0]["ERRCODE"] == 3
    assert "port 1: carrier LP1 CARRIER CANCELLED (cancelled by the host)" in s.out
    assert s.load("FOUP0005")["status"] == "ok"  # the port takes the next carrier


def test_a_host_that_drops_and_comes_back_finds_the_carrier_where_it_was(server, host):
    s = server("--empty")
    first = host(s.port)
    first.subscribe()
    s.load("FOUP0003")
    first.event(), first.event()
    first.close()
    second = host(s.port)
    status = second.ask(1, 3, [V.U4(STATUS["slot_map_status"] + 1)]).get()
    assert status == [1]  # still WAITING FOR HOST
    second.subscribe()
    assert second.proceed("FOUP0003", attributes=real_host_attributes(PAPER_E87)) == (0, [])
    ceid, _ = second.event()
    assert ceid == EVENTS["verification_ok"]
    assert second.events.empty()  # nothing from before the drop is sent again
    assert (s.folder / "results.txt").read_text().startswith("seq = 1\n")


def test_a_second_host_waits_until_the_first_leaves(server, host):
    s = server("--empty")
    first = host(s.port)
    other = Host(s.port)
    try:
        assert not other.communicating(3)  # HSMS: one selected session at a time
        assert first.ask(1, 1).get() == ["WSCAN", "0.1.0"]  # the first is undisturbed
        first.close()
        assert other.communicating(15)
    finally:
        other.close()


@pytest.mark.parametrize("message, answer", [
    (Raw(99, 1), 3),  # no stream 99
    (Raw(1, 99), 5),  # stream 1 has no function 99
    (Raw(3, 17, b"\x01\x02\xa5\x01\x07"), 7),  # an S3F17 whose body is not one
    (Raw(7, 19), 5),  # a function this equipment does not carry out
], ids=["unknown stream", "unknown function", "malformed S3F17", "S7F19"])
def test_what_the_equipment_cannot_understand_is_answered_with_stream_9(server, host, message,
                                                                        answer):
    s = server("--empty")
    h = host(s.port)
    reply = h.handler.send_and_waitfor_response(message)
    assert (reply.header.stream, reply.header.function) == (9, answer)
    assert h.ask(1, 1).get() == ["WSCAN", "0.1.0"]  # the link stays up


def test_a_wrongly_typed_slot_map_is_refused_and_changes_nothing(server, host):
    s = server("--empty")
    h = host(s.port)
    s.load("FOUP0004")
    caack, errors = h.proceed("FOUP0004", attributes=[
        {"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U4, PAPER_E87)}])
    assert caack == 3 and errors[0][0] == 7 and "expected a list of U1" in errors[0][1]
    status = h.ask(1, 3, [V.U4(STATUS["slot_map_status"] + 1)]).get()
    assert status == [1]  # still WAITING FOR HOST: the host may send it again, corrected
    assert h.proceed("FOUP0004", attributes=real_host_attributes(PAPER_E87)) == (0, [])


def test_the_reply_goes_before_the_events_it_causes_and_a_waiting_port_takes_no_carrier(
        server, host):
    from waferscan.host import hsms

    s = server("--empty")
    h = host(s.port)
    received = []
    log = hsms.attach_log(received.append, h.handler.settings.name)
    try:
        h.subscribe()
        s.load("FOUP0006")
        h.event(), h.event()
        answer = s.load("FOUP0007")  # the host has not decided on FOUP0006 yet
        assert answer["status"] == "error" and answer["message"].endswith(
            "LOAD: port 1 holds carrier 'FOUP0006' (WAITING FOR HOST): the host proceeds with "
            "it or cancels it first")
        assert h.proceed("FOUP0006") == (0, [])
        assert h.event()[0] == EVENTS["verification_ok"]
    finally:
        hsms.detach_log(log)
    heads = [line.split("\n")[0].strip() for line in received if line.startswith("<")]
    reply, event = heads.index("< S3F18"), max(i for i, head in enumerate(heads)
                                                if head == "< S6F11 W")
    assert reply < event, heads
    assert s.load("FOUP0007")["status"] == "ok"  # verified: the next carrier may come


def test_a_probe_or_a_dropped_connection_never_kills_the_server(server, host):
    s = server("--empty")
    def probe():
        """A connection that sends garbage and hangs up; True once the server has let it go.

        One connection at a time (HSMS): the server stops listening while it holds one and
        listens again after. Between the two a connection is refused, and is tried again. Each
        probe waits for the server to close it, so no probe (and not the host after them) sits
        in the listening socket's queue when the server takes the one before it and closes that
        socket: a connection queued there is reset, and secsgem 0.3.0's host, reset as it
        connects, can wedge for good (met in CI, both suites side by side)."""
        try:
            connection = socket.create_connection(("127.0.0.1", s.port), timeout=5)
        except (ConnectionRefusedError, ConnectionResetError):
            return False
        with connection:
            connection.settimeout(60)
            try:
                connection.sendall(b"\x00\x00\x00\x05garbage")
                connection.shutdown(socket.SHUT_WR)
                while connection.recv(4096):
                    pass
            except TimeoutError:
                raise  # the server held it a minute: a failure of its own
            except OSError:
                pass  # reset, or closed before our hang-up: let go all the same
        return True

    for _ in range(5):
        assert wait_for(probe, 30)
    h = host(s.port)
    assert h.ask(1, 1).get() == ["WSCAN", "0.1.0"]
    assert s.process.poll() is None


def test_twenty_five_carriers_one_after_another(server, host):
    s = server("--empty")
    h = host(s.port)
    h.subscribe()
    for n in range(1, 26):
        assert s.load(f"FOUP{n:04d}")["status"] == "ok"
        assert [h.event()[0], h.event()[0]] == [EVENTS["slot_map_not_read"],
                                                EVENTS["waiting_for_host"]]
        assert h.proceed(f"FOUP{n:04d}", attributes=real_host_attributes(PAPER_E87)) == (0, [])
        assert h.event()[0] == EVENTS["verification_ok"]
    assert h.events.empty()


@pytest.mark.parametrize("text, line, message", [
    ('[events]\nwaiting_for_hots = 2\n', 2, "[events] waiting_for_hots: unknown key"),
    ('[data]\nslot_map = 8703\n', 2, "ID 8703 is used twice"),
], ids=["unknown key", "duplicate ID"])
def test_a_bad_ids_file_is_exit_2_with_its_line(tmp_path, text, line, message):
    ids = tmp_path / "ids.toml"
    ids.write_text(text)
    done = subprocess.run([*CLI, "serve", str(PAPER), "--hsms", f"127.0.0.1:{free_port()}",
                           "--ids", str(ids)], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {ids}:{line}: {message}")
    assert "Traceback" not in done.stderr


def test_a_port_in_use_and_a_bad_layout_are_exit_2(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        done = subprocess.run([*CLI, "serve", str(PAPER), "--hsms", f"127.0.0.1:{port}"],
                              cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert (done.returncode, done.stderr) == (
        2, f"waferscan: error: --hsms: cannot listen on 127.0.0.1:{port}: in use\n")
    bad = tmp_path / "bad.toml"
    bad.write_text(PAPER.read_text().replace("pitch = 10.0", "pitch = -10.0", 1))
    done = subprocess.run([*CLI, "serve", str(bad), "--hsms", f"127.0.0.1:{free_port()}"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stderr.startswith(f"waferscan: error: {bad}:")
    assert "Traceback" not in done.stderr


def test_a_load_the_link_cannot_carry_out_is_answered_error(server):
    s = server("--empty")
    answer = s.load("FOUP 9")  # two words: the second is taken for a port
    assert answer["status"] == "error" and "no port '9'" in answer["message"]
    answer = s.load("FOUPÉ")
    assert answer["status"] == "error" and "printable ASCII" in answer["message"]
    assert s.load("FOUP0009")["status"] == "ok"


def test_watch_refuses_load(tmp_path):
    from commands import run_watch

    (tmp_path / "commands.txt").write_text("1 LOAD FOUP1\n")
    done = run_watch(tmp_path, "--once")
    text = (tmp_path / "results.txt").read_text()
    assert "status = error" in text and "waferscan serve" in text, (done.stderr, text)


def test_serve_is_in_the_help():
    done = subprocess.run([*CLI, "serve", "--help"], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0 and "--hsms HOST:PORT" in done.stdout


def test_the_bench_measures_the_host_link():
    from waferscan.bench.host_link import bench_host

    rows = []
    figures = bench_host(PAPER, 3, rows.append)  # each carrier verified with CAACK 0
    assert [(r["workload"], r["engine"], r["carriers"]) for r in rows] == [
        ("host", "arrival -> slot-map event", 3), ("host", "S3F17 -> S3F18", 3)]
    assert all(0 < p50 <= p99 for p50, p99 in figures.values())




def test_several_carriers_are_several_ports_and_load_names_the_port(server, host, tmp_path):
    layout = tmp_path / "two.toml"
    layout.write_text(TWO_CARRIERS_TEXT)
    s = server("--empty", layout=layout)
    assert "ports 1 = LP1 (LP1), 2 = LP2 (LP2)" in s.out
    h = host(s.port)
    h.subscribe()
    answer = s.load("FOUPA", "2")  # LP2 lies above the paper's scan: every slot unscanned
    assert (answer["status"], answer["code"], answer["e87"]) == ("ok", "?" * 13, "0" * 13)
    assert answer["warning"].startswith("slots 1, 2, 3")
    ceid, values = h.event()
    ceid, values = h.event()
    assert (ceid, values["port_id"], values["slot_map"]) == (EVENTS["waiting_for_host"], 2,
                                                            [0] * 13)
    # unscanned is never empty: a host expecting an empty carrier is refused
    caack, errors = h.proceed("FOUPA", port=2, attributes=[
        {"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U1, [1] * 13)}])
    assert (caack, errors[0][0]) == (3, 9) and "not wholly scanned" in errors[0][1]
    assert s.load("FOUPB", "LP1")["code"] == "1101221001220001010000010"
    answer = s.load("FOUPC")
    assert answer["status"] == "error" and "several ports" in answer["message"]
    answer = s.load("FOUPA", "1")
    assert answer["message"].endswith("LOAD: carrier 'FOUPA' is already at port 2")


def test_active_the_equipment_connects_to_a_listening_host(server, tmp_path):
    from waferscan.host import hsms

    port = free_port()
    listening = secsgem.gem.GemHostHandler(hsms.EquipmentSettings(
        address="127.0.0.1", port=port, connect_mode=secsgem.hsms.HsmsConnectMode.PASSIVE,
        device_type=secsgem.common.DeviceType.HOST, streams_functions=messages.registry(),
        t3=10.0, t5=1.0))
    listening.enable()
    try:
        s = server("--active", "--empty", port=port)
        assert f"connecting to 127.0.0.1:{port}" in s.out
        assert listening.waitfor_communicating(20)
        reply = listening.send_and_waitfor_response(listening.stream_function(1, 1)())
        assert listening.settings.streams_functions.decode(reply).get() == ["WSCAN", "0.1.0"]
        assert s.stop() == 0
    finally:
        hsms.close(listening, 5)


def test_a_saved_layout_is_served_as_a_scenario_is(server, host, tmp_path):
    layout = tmp_path / "paper.FCStd"
    done = subprocess.run([*CLI, "layout", str(PAPER), "-o", str(layout)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    s = server("--empty", layout=layout)
    h = host(s.port)
    h.subscribe()
    answer = s.load("FOUP0008")
    assert (answer["status"], answer["code"]) == ("ok", "1101221001220001010000010")
    h.event()
    assert h.event()[1]["slot_map"] == PAPER_E87
