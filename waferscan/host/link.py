"""The host link's load ports with their scans (SPEC §14): a carrier arrives, its map is scanned
by the engines of ``waferscan scan``, and every change of its E87 state is reported to the host.

The scans run on the caller's thread (the one that owns the FreeCAD document); the HSMS side
only reads and changes the ports' state through ``LoadPorts``, which is thread-safe.
"""

from __future__ import annotations

import threading
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
        # A change of a carrier's state and its event are one step: the events reach the host
        # in the order the states changed, whichever thread changed them (the scans' or
        # secsgem's). Taken before the ports' own lock, never while it is held.
        self._telling = threading.RLock()

    def port_of(self, name):
        """The port number given as text (``"2"``), or of the layout carrier so named; None if
        none."""
        for p in self.port_ids:
            if name == str(p.number):
                return p.number
        for p in self.port_ids:
            if name == p.carrier:
                return p.number
        return None

    def load_all(self):
        """Every port's carrier arrives, with the ID the IDs file gives it (SPEC §14: at the
        server's start)."""
        return [self.load(p.number, p.carrier_id) for p in self.port_ids]

    def load(self, port, carrier_id):
        """A carrier with ``carrier_id`` is placed on ``port`` and mapped. An InputError when
        another port holds a carrier of that ID, or this port one the host has not decided on
        yet. When the host cancels the carrier while it is being scanned, its map is not
        reported: the arrival's last transition is then the arrival itself."""
        with self._telling:
            holder = self.ports.find(carrier_id)
            if holder is not None and holder.number != port:
                raise InputError("LOAD", None, f"carrier {carrier_id!r} is already at port "
                                 f"{holder.number}")
            occupied = self.ports.occupant(port)
            if occupied:
                raise InputError("LOAD", None, occupied)
            arrived = self.ports.arrive(port, carrier_id)
            self._tell(arrived)
        name = self.ports.port(port).carrier
        result = self.scan(name)
        self.results[port] = result
        with self._telling:
            read = self.ports.slot_map_read(port, tuple(int(c) for c in result.e87),
                                            result.warnings, carrier_id)
            if read is not None:
                self.report(read)
        if read is None:
            self.log(f"port {port}: carrier {carrier_id} was cancelled while it was mapped: "
                     "its map is not reported")
            return Arrival(port, carrier_id, result, (arrived,))
        self.log(f"port {port}: carrier {carrier_id} mapped {result.code} (E87 {result.e87})"
                 + "".join(f"\n  warning: {w}" for w in result.warnings))
        self._said(read)
        return Arrival(port, carrier_id, result, (arrived, read))

    def carrier_action(self, action, carrier_id, port, attributes):
        """A host's S3F17 carried out (``LoadPorts.carrier_action``), the transitions it made
        reported before any other change of state can be: the reply."""
        with self._telling:
            reply, transitions = self.ports.carrier_action(action, carrier_id, port,
                                                           attributes)
            for transition in transitions:
                self.report(transition)
        for transition in transitions:
            self._said(transition)
        return reply

    def _tell(self, transition):
        self.report(transition)
        self._said(transition)

    def _said(self, transition):
        self.log(f"port {transition.port}: carrier {transition.carrier_id} "
                 f"{transition.status_name}" + (f" ({transition.reason})"
                                                if transition.reason else ""))
