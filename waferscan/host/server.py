"""``waferscan serve``: the layout's carriers as load ports of an HSMS equipment (SPEC §14).

The layout (a scenario or a .FCStd) is opened in FreeCAD once; each carrier that arrives is
scanned there, on this thread, by the engine asked for, as ``waferscan scan`` scans it. The
equipment answers the host from secsgem's threads through the ports' E87 model. The server runs
until SIGINT or SIGTERM (a ``StopFlag``); a host that comes and goes does not end it.
"""

from __future__ import annotations

import errno
import ipaddress
import logging
import socket
import sys
from contextlib import contextmanager
from pathlib import Path

from ..core.errors import InputError

DEFAULT_PORT = 5000  # HSMS's customary port


def parse_address(text, option="--hsms"):
    """HOST:PORT (HOST a name or an IPv4 address; the HSMS transport listens on IPv4) as
    (host, port); an InputError naming the option otherwise."""
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = text, str(DEFAULT_PORT)
    if not host or ":" in host or host.startswith("["):
        raise InputError(option, None, f"expected HOST:PORT with an IPv4 address or a host "
                                       f"name, got {text!r}")
    try:
        number = int(port)
    except ValueError:
        number = -1
    if not 1 <= number <= 65535:
        raise InputError(option, None, f"port: expected a whole number 1-65535, got {port!r}")
    try:
        ipaddress.ip_address(host)
    except ValueError:
        try:
            socket.getaddrinfo(host, number, proto=socket.IPPROTO_TCP)
        except OSError as exc:
            raise InputError(option, None, f"cannot resolve {host!r}: {exc.strerror or exc}") \
                from None
    return host, number


def check_port_free(host, port, option="--hsms"):
    """An InputError when nothing can listen on host:port (in use, or not this machine's)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as exc:
            reason = "in use" if exc.errno == errno.EADDRINUSE else (exc.strerror or str(exc))
            raise InputError(option, None, f"cannot listen on {host}:{port}: {reason}") from None


class _LibraryErrors(logging.Handler):
    """secsgem's own log on stderr, one line a record: its errors only (a connection reset by
    a probe, a message that could not be sent). Its warnings (the crossing S1F14s of both sides
    establishing communications at once) say nothing an operator can act on."""

    def emit(self, record):
        first = record.getMessage().splitlines()[0] if record.getMessage() else ""
        cause = f" ({record.exc_info[1]!r})" if record.exc_info else ""
        print(f"waferscan: hsms: {first}{cause}", file=sys.stderr, flush=True)


@contextmanager
def library_log_on_stderr():
    """While serving: secsgem's errors on stderr as single lines, not Python's tracebacks."""
    handler = _LibraryErrors(logging.ERROR)
    loggers = [logging.getLogger(name) for name in ("secsgem", "waferscan.host")]
    saved = [(logger.propagate, logger.level) for logger in loggers]
    for logger in loggers:
        logger.addHandler(handler)
        logger.propagate = False
        logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        for logger, (propagate, level) in zip(loggers, saved):
            logger.removeHandler(handler)
            logger.propagate, logger.level = propagate, level


def layout_scanner(doc, source, engine):
    """``scan(carrier)`` for a HostLink: the document's layout scanned for one carrier."""
    from ..cad.document_scan import scan_document
    from ..core.files.mcs import Parameters
    from ..core.scan.engine_choice import check_engine

    def scan(carrier):
        def check(layout):
            check_engine(layout, engine, source)

        return scan_document(doc, engine, parameters=Parameters({"carrier": carrier}, {},
                                                                str(source)), check=check)

    return scan


MAX_CARRIER_ID = 64  # characters of a CarrierID given by LOAD


def load_command(link, command, source):
    """``<seq> LOAD <carrier-id> [<port>]`` of the MCS link: the carrier placed on the port (a
    port number or the layout's carrier name; needed only when there are several ports) and
    mapped. Returns the MCS answer (``Scanned``); an InputError naming commands.txt's line for a
    LOAD that cannot be carried out."""
    from ..core.files.mcs_link import Scanned

    def refuse(message):
        return InputError(source, command.line, f"LOAD: {message}")

    if not 1 <= len(command.args) <= 2:
        raise refuse("expected LOAD <carrier-id> [<port>]")
    carrier_id = command.args[0]
    if not carrier_id.isascii() or not carrier_id.isprintable() \
            or len(carrier_id) > MAX_CARRIER_ID:
        raise refuse(f"a carrier ID is 1 to {MAX_CARRIER_ID} printable ASCII characters")
    if len(command.args) == 2:
        port = link.port_of(command.args[1])
        if port is None:
            raise refuse(f"no port {command.args[1]!r} (ports: " + ", ".join(
                f"{p.number} = {p.carrier}" for p in link.port_ids) + ")")
    elif len(link.port_ids) == 1:
        port = link.port_ids[0].number
    else:
        raise refuse("the layout has several ports (" + ", ".join(
            f"{p.number} = {p.carrier}" for p in link.port_ids) + "): say which, "
            f"LOAD {carrier_id} <port>")
    try:
        arrival = link.load(port, carrier_id)
    except InputError as exc:
        raise refuse(exc.message) from None
    if len(arrival.transitions) == 1:
        return Scanned(arrival.result, f"carrier {carrier_id} at port {port}: cancelled by the "
                                       "host while it was mapped (its map was not reported)")
    return Scanned(arrival.result, f"carrier {carrier_id} at port {port}: "
                                   f"{arrival.transitions[-1].status_name}")


def mcs_scanner(doc, folder, engine, link):
    """The MCS link's scan function of ``waferscan serve --mcs``: LOAD places carriers, the
    other commands are carried out as ``waferscan watch`` carries them out."""
    from ..cad.mcs_watch import document_scanner
    from ..core.files.mcs import COMMANDS

    others = document_scanner(doc, folder, engine)

    def scan(command, should_stop):
        if command.name == "LOAD":
            return load_command(link, command, folder / COMMANDS)
        return others(command, should_stop)

    scan.close = others.close
    return scan


def serve(source, address, active=False, ids_path=None, engine="analytic", stopping=None,
          out=None, messages_out=None, mcs_folder=None, empty=False):
    """Run the host link until ``stopping`` (a StopFlag) is set. ``out(text)`` gets the log;
    ``messages_out(text)``, if given, every HSMS message in SML; ``mcs_folder``: an MCS link
    folder whose LOAD commands place carriers (and whose other commands are carried out as
    ``waferscan watch`` does); ``empty``: no carrier arrives at the start. Returns the exit
    status; InputError for bad input found before the link starts (nothing is listening
    then)."""
    from ..cad.layout_files import opened_layout
    from ..cad.reader import read_layout
    from ..core.files.mcs_link import LockLost, McsLink, StopFlag
    from . import hsms, messages
    from .equipment import LoadPortEquipment
    from .ids import default_ids, read_ids
    from .link import HostLink

    out = out or (lambda text: print(text, flush=True))
    stopping = stopping or StopFlag()
    if mcs_folder is not None and not Path(mcs_folder).is_dir():
        raise InputError(mcs_folder, None, "no such folder")
    ids = read_ids(ids_path) if ids_path else default_ids()
    host, port = parse_address(address, "--hsms")
    if not active:
        check_port_free(host, port)
    with opened_layout(source) as doc, library_log_on_stderr():
        layout = read_layout(doc)
        carriers = [(c.name, c.slot_count) for c in layout.carriers]
        link = HostLink(ids, carriers, layout_scanner(doc, source, engine), log=out)
        settings = hsms.settings(host, port, active=active, session_id=ids.device_id,
                                 registry=messages.registry())
        equipment = LoadPortEquipment(settings, link, log=out)
        link.report = equipment.report
        message_log = hsms.attach_log(messages_out, settings.name) if messages_out else None
        mcs = None
        try:
            if mcs_folder is not None:  # a folder another link holds is refused before listening
                scanner = mcs_scanner(doc, Path(mcs_folder), engine, link)
                try:
                    mcs = McsLink(Path(mcs_folder), scanner, log=out,
                                  report=lambda text: print(f"waferscan: {text}",
                                                            file=sys.stderr, flush=True))
                except BaseException:
                    scanner.close()
                    raise
            try:
                equipment.enable()
            except OSError as exc:
                raise InputError("--hsms", None, f"cannot {'connect to' if active else 'listen on'}"
                                 f" {host}:{port}: {exc.strerror or exc}") from None
            ports = ", ".join(f"{p.number} = {p.carrier} ({p.carrier_id})"
                              for p in link.port_ids)
            out(f"{'connecting to' if active else 'listening on'} {host}:{port} as equipment "
                f"{ids.mdln} {ids.softrev} (device {ids.device_id}); ports {ports}; "
                "Ctrl-C to stop")
            if mcs is not None:
                out(f"MCS link on {mcs_folder}: LOAD <carrier-id> [<port>] places a carrier")
            for p in () if empty else link.port_ids:
                if stopping.is_set():
                    break
                link.load(p.number, p.carrier_id)
            while not stopping.wait(0.01 if mcs else 0.2):
                if mcs is not None:
                    mcs.poll(stop=stopping.is_set)
            return 0
        except LockLost as exc:  # another link answers the MCS folder now
            print(f"waferscan: {exc}", file=sys.stderr, flush=True)
            return 1
        finally:
            if mcs is not None:
                mcs.close()
                mcs.scan.close()
            if not equipment.close():
                out("the HSMS link did not stop cleanly")
            if message_log is not None:
                hsms.detach_log(message_log)

