"""The host link's load ports with their scans (SPEC §14): a carrier arrives, its map is scanned
by the engines of ``waferscan scan``, and every change of its E87 state is reported to the host.

The scans run on the caller's thread (the one that owns the FreeCAD document); the HSMS side
only reads and changes the ports' state through ``LoadPorts``, which is thread-safe.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.errors import InputError
from .e87 import LoadPort, LoadPorts


@dataclass(frozen=True)
class Arrival:
    """What one carrier's arrival did: its port, the scan and the two transitions reported."""

    port: int
    carrier_id: str
    result: object  # the ScanResult
    transitions: tuple


class HostLink:
    """The ports of a layout's carriers, numbered by ``ids`` (``host.ids.ToolIds``); ``carriers``
    are (name, slot count) in the layout's order; ``scan(name)`` scans one carrier and returns
    its ScanResult. ``report(transition)`` is called for every change of state (the
    equipment's collection events), ``log(text)`` for what the operator should read."""

    def __init__(self, ids, carriers, scan, report=None, log=None):
        self.ids = ids
        self.port_ids = ids.assign_ports([name for name, _ in carriers])
        capacity = dict(carriers)
        self.ports = LoadPorts([LoadPort(p.number, p.carrier, capacity[p.carrier])
                                for p in self.port_ids])
        self.scan = scan
        self.report = report or (lambda transition: None)
        self.log = log or (lambda text: None)
        self.results = {}  # port number -> the last scan's ScanResult

    def port_of(self, carrier):
        """The port number of a layout carrier's name, of a port number given as text, or of a
        carrier ID a port was loaded with; None if none."""
        for p in self.port_ids:
            if carrier in (p.carrier, str(p.number), p.carrier_id):
                return p.number
        return None

    def load_all(self):
        """Every port's carrier arrives, with the ID the IDs file gives it (SPEC §14: at the
        server's start)."""
        return [self.load(p.number, p.carrier_id) for p in self.port_ids]

    def load(self, port, carrier_id):
        """A carrier with ``carrier_id`` is placed on ``port`` and mapped. An InputError when
        another port holds a carrier of that ID."""
        holder = self.ports.find(carrier_id)
        if holder is not None and holder.number != port:
            raise InputError("LOAD", None, f"carrier {carrier_id!r} is already at port "
                             f"{holder.number}")
        arrived = self.ports.arrive(port, carrier_id)
        self._tell(arrived)
        name = self.ports.port(port).carrier
        result = self.scan(name)
        self.results[port] = result
        read = self.ports.slot_map_read(port, tuple(int(c) for c in result.e87),
                                        result.warnings)
        self.log(f"port {port}: carrier {carrier_id} mapped {result.code} (E87 {result.e87})"
                 + "".join(f"\n  warning: {w}" for w in result.warnings))
        self._tell(read)
        return Arrival(port, carrier_id, result, (arrived, read))

    def acted(self, transitions):
        """Report the transitions a host's carrier action made."""
        for transition in transitions:
            self._tell(transition)

    def _tell(self, transition):
        self.log(f"port {transition.port}: carrier {transition.carrier_id} "
                 f"{transition.status_name}" + (f" ({transition.reason})"
                                                if transition.reason else ""))
        self.report(transition)
