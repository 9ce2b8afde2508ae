"""The host link as a factory host meets it (SPEC §14): a ``waferscan serve`` process, a
secsgem GEM host on 127.0.0.1 that subscribes to the slot-map events, carriers placed by LOAD on
the MCS link. Two figures: a carrier's arrival (LOAD appended to commands.txt) to the host
holding its WAITING FOR HOST event, and a verification's round trip (S3F17 sent to S3F18
received), each as p50 and p99 over ``count`` carriers.

Exports ``bench_host``."""

from __future__ import annotations

import logging
import queue
import socket
import subprocess
import tempfile
import time
from pathlib import Path

from ..core.files.mcs import COMMANDS
from .processes import cli, process_environment

__all__ = ["bench_host"]

REPORT_ID = 4001


def _free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _percentile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


class _Host:
    """secsgem's GEM host, subscribed to every slot-map event of the default IDs."""

    def __init__(self, port):
        import secsgem.common
        import secsgem.gem
        import secsgem.hsms
        from secsgem.secs import variables as V

        from ..host.ids import DEFAULTS
        from ..host.messages import registry

        self.V = V
        self.handler = secsgem.gem.GemHostHandler(secsgem.hsms.HsmsSettings(
            address="127.0.0.1", port=port, connect_mode=secsgem.hsms.HsmsConnectMode.ACTIVE,
            device_type=secsgem.common.DeviceType.HOST, streams_functions=registry(), t5=1.0))
        self.events = queue.Queue()
        self.handler.register_stream_function(6, 11, self._on_event)
        self.handler.enable()
        if not self.handler.waitfor_communicating(30):
            raise RuntimeError("the host did not reach COMMUNICATING")
        data, events = DEFAULTS["data"], DEFAULTS["events"]
        self.waiting = events["waiting_for_host"]
        self.ask(2, 33, {"DATAID": V.U4(1), "DATA": [{"RPTID": V.U4(REPORT_ID), "VID": [
            V.U4(v) for v in data.values()]}]})
        self.ask(2, 35, {"DATAID": V.U4(2), "DATA": [{"CEID": V.U4(c), "RPTID": [
            V.U4(REPORT_ID)]} for c in events.values()]})
        self.ask(2, 37, {"CEED": True, "CEID": []})

    def _on_event(self, handler, message):
        event = handler.settings.streams_functions.decode(message)
        self.events.put((time.perf_counter(), event.CEID.get(), event.RPT[0].V.get()))
        return handler.stream_function(6, 12)(0)

    def ask(self, stream, function, value=None):
        reply = self.handler.send_and_waitfor_response(
            self.handler.stream_function(stream, function)(value))
        if reply is None:
            raise RuntimeError(f"no answer to S{stream}F{function}")
        return self.handler.settings.streams_functions.decode(reply)

    def wait_event(self, ceid, timeout=120):
        while True:
            at, got, values = self.events.get(timeout=timeout)
            if got == ceid:
                return at, values

    def close(self):
        self.handler.disable()


def bench_host(layout_path, count, add, progress=None):
    """``count`` carriers through the paper's port, one after another: LOAD, the slot-map
    event, ProceedWithCarrier with the map read. ``add(row)`` gets one row per figure; returns
    {figure: (p50, p99)} in milliseconds."""
    # the host's own log: secsgem warns of the S1F14 both sides cross when they establish
    # communications at once; the bench's table is what is printed
    library = logging.getLogger("secsgem")
    level = library.level
    library.setLevel(logging.ERROR)
    try:
        return _bench_host(layout_path, count, add, progress)
    finally:
        library.setLevel(level)


def _bench_host(layout_path, count, add, progress):
    with tempfile.TemporaryDirectory(prefix="waferscan-bench-host-") as tmp:
        folder = Path(tmp) / "mcs"
        folder.mkdir()
        port = _free_port()
        out = (Path(tmp) / "serve.out").open("w+")
        server = subprocess.Popen(cli("serve", layout_path, "--hsms", f"127.0.0.1:{port}",
                                      "--mcs", folder, "--empty"), stdout=out,
                                  stderr=subprocess.DEVNULL, env=process_environment(),
                                  start_new_session=True)
        host = None
        try:
            deadline = time.monotonic() + 120
            while "listening on" not in Path(out.name).read_text():
                if server.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError("waferscan serve did not start")
                time.sleep(0.05)
            host = _Host(port)
            V = host.V
            arrival, round_trip = [], []
            for n in range(1, count + 1):
                carrier = f"BENCH{n:04d}"
                started = time.perf_counter()
                with (folder / COMMANDS).open("a") as commands:
                    commands.write(f"{n} LOAD {carrier}\n")
                at, values = host.wait_event(host.waiting)
                arrival.append((at - started) * 1e3)
                slot_map = values[2]
                sent = time.perf_counter()
                reply = host.ask(3, 17, {
                    "DATAID": V.U4(n), "CARRIERACTION": "ProceedWithCarrier",
                    "CARRIERID": carrier, "PTN": V.U1(1),
                    "CATTRS": [{"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U1, slot_map)}]})
                round_trip.append((time.perf_counter() - sent) * 1e3)
                if reply.CAACK.get() != 0:
                    raise AssertionError(f"{carrier}: CAACK {reply.CAACK.get()}")
                if progress:
                    progress(n, count)
        finally:
            if host is not None:
                host.close()
            server.terminate()
            try:
                server.wait(30)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait(10)
            out.close()
    figures = {"arrival -> slot-map event": arrival, "S3F17 -> S3F18": round_trip}
    summary = {}
    for name, values in figures.items():
        p50, p99 = _percentile(values, 0.5), _percentile(values, 0.99)
        summary[name] = (p50, p99)
        add({"workload": "host", "engine": name, "carriers": count, "p50_ms": round(p50, 2),
             "p99_ms": round(p99, 2), "max_ms": round(max(values), 2)})
    return summary
