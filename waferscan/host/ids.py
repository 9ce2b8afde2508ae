"""The tool's SECS/GEM identifiers (SPEC §14's IDS.toml): every tool numbers its collection
events, variables and load ports its own way, so a host's configuration can be met as it is.

Every key is optional; the defaults are ``DEFAULTS`` below (docs/tutorials/host-link.md lists
them). A port's status variables are numbered from a base: the port's number is added to it.

>>> ids = parse_ids('[events]\\nwaiting_for_host = 4001\\n', "ids.toml")
>>> ids.events["waiting_for_host"], ids.events["verification_ok"]
(4001, 8703)
>>> ids.status_id("slot_map", 2)
8902
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..core.errors import InputError

MAX_TEXT = 20  # MDLN and SOFTREV: E5 allows 20 characters (a longer S1F14 is dropped by hosts)
MAX_U4 = 2**32 - 1
BUILT_IN_SVIDS = (1001, 1002, 1003, 1004, 1005)
BUILT_IN_CEIDS = (1, 2, 3, 20, 21)

DEFAULTS = {
    "equipment": {"mdln": "WSCAN", "softrev": "0.1.0", "device_id": 0},
    # CEIDs: one per slot-map transition (SPEC §14), and a carrier cancelled by the host.
    "events": {"slot_map_not_read": 8701, "waiting_for_host": 8702, "verification_ok": 8703,
               "verification_failed": 8704, "carrier_cancelled": 8705},
    # DVIDs: the data of the event being reported.
    "data": {"port_id": 8711, "carrier_id": 8712, "slot_map": 8713, "slot_map_status": 8714,
             "reason": 8715},
    # SVID bases: port n's variable is base + n.
    "status": {"carrier_id": 8800, "slot_map": 8900, "slot_map_status": 9000},
}
_PORT_KEYS = ("carrier", "number", "carrier_id")


@dataclass(frozen=True)
class PortIds:
    carrier: str  # the layout's carrier
    number: int | None  # PTN; None in a file's [[port]] without one: numbered in layout order
    carrier_id: str  # the CarrierID it is loaded with at start


@dataclass(frozen=True)
class ToolIds:
    mdln: str
    softrev: str
    device_id: int
    events: dict
    data: dict
    status: dict
    ports: tuple = ()  # PortIds given in the file; the rest follow the layout's order
    source: str = "<defaults>"
    lines: dict = field(default_factory=dict, compare=False)  # (table, key) -> line

    def status_id(self, name, port):
        return self.status[name] + port

    def assign_ports(self, carriers):
        """The ``PortIds`` of each of the layout's carriers (names, in order): those the file
        gives, the others numbered on from 1 in order, each loaded with a carrier named as the
        layout's. An InputError names a [[port]] whose carrier is not in the layout, a number
        used twice, or status variables that meet another ID."""
        given = {p.carrier: p for p in self.ports}
        for index, p in enumerate(self.ports):
            if p.carrier not in carriers:
                raise InputError(self.source, self.lines.get(("port", index, "carrier")),
                                 f"[[port]] carrier: no carrier named {p.carrier!r} in the "
                                 f"layout (carriers: {', '.join(carriers)})")
        used = {p.number for p in self.ports if p.number is not None}
        ports, number = [], 1
        for name in carriers:  # the rest numbered on from 1 in the layout's order
            if name in given and given[name].number is not None:
                ports.append(given[name])
                continue
            while number in used:
                number += 1
            used.add(number)
            carrier_id = given[name].carrier_id if name in given else name
            ports.append(PortIds(name, number, carrier_id))
        self._check_unique(ports)
        return tuple(ports)

    def _check_unique(self, ports):
        # secsgem's GEM handler answers these itself (Clock, ControlState, EventsEnabled,
        # AlarmsEnabled, AlarmsSet; its control-state events): a port's variable there would
        # never be read
        seen = {vid: [("secsgem", f"built-in SVID {vid}")] for vid in BUILT_IN_SVIDS}
        seen.update({ceid: [("secsgem", f"built-in CEID {ceid}")] for ceid in BUILT_IN_CEIDS})
        for table in ("events", "data"):
            for key, value in getattr(self, table).items():
                seen.setdefault(value, []).append((table, key))
        for name, base in self.status.items():
            for p in ports:
                seen.setdefault(base + p.number, []).append(("status", name, p.number))
        ids = {p.carrier_id: p for p in ports}
        if len(ids) < len(ports):
            twice = next(p for p in ports if ids[p.carrier_id] is not p)
            raise InputError(self.source, None, f"carrier_id {twice.carrier_id!r} is given to "
                             "two ports")
        for value, owners in seen.items():
            if len(owners) > 1:
                names = [self._name(owner) for owner in owners]
                # the line of whichever of the two the file sets (a default has none)
                line = next((self.lines[o[:2]] for o in reversed(owners[:2])
                             if o[:2] in self.lines), None)
                raise InputError(self.source, line,
                                 f"ID {value} is used twice: {names[0]} and {names[1]}")

    @staticmethod
    def _name(owner):
        if owner[0] == "secsgem":
            return f"secsgem's {owner[1]}"
        if owner[0] == "status":
            return f"[status] {owner[1]} of port {owner[2]}"
        return f"[{owner[0]}] {owner[1]}"


def default_ids():
    return parse_ids("", "<defaults>")


def read_ids(path):
    """Read and check an IDS.toml file (an InputError with the file and line when it is wrong)."""
    from ..core.files.text_files import read_text

    path = Path(path)
    return parse_ids(read_text(path, "the IDs file"), str(path))


def parse_ids(text, source="<ids>"):
    from ..core.files.scenario import key_line, parse_toml

    text = text.lstrip("\ufeff")
    data = parse_toml(text, source)
    lines = {}

    def line(table, key=None):
        return key_line(text, table, key)

    def error(message, table, key=None):
        return InputError(source, line(table, key), message)

    tables = {}
    for name, table in data.items():
        if name == "port":
            continue
        if name not in DEFAULTS:
            raise InputError(source, line(name) or line(None, name),
                             f"unknown table {name!r} (known: "
                             f"{', '.join(list(DEFAULTS) + ['port'])})")
        if not isinstance(table, dict):
            raise error(f"write it as a [{name}] table", None, name)
        for key, value in table.items():
            if key not in DEFAULTS[name]:
                raise error(f"[{name}] {key}: unknown key (known: "
                            f"{', '.join(DEFAULTS[name])})", name, key)
            lines[(name, key)] = line(name, key)
        tables[name] = {**DEFAULTS[name], **table}
    for name in DEFAULTS:
        tables.setdefault(name, dict(DEFAULTS[name]))

    equipment = tables["equipment"]
    for key in ("mdln", "softrev"):
        value = equipment[key]
        if not isinstance(value, str) or not value.isascii() or not 0 < len(value) <= MAX_TEXT:
            raise error(f"[equipment] {key}: expected ASCII text of 1 to {MAX_TEXT} characters "
                        f"(SEMI E5), got {value!r}", "equipment", key)
    device_id = equipment["device_id"]
    if isinstance(device_id, bool) or not isinstance(device_id, int) \
            or not 0 <= device_id <= 32767:
        raise error(f"[equipment] device_id: expected an integer 0-32767 (HSMS session ID), got "
                    f"{device_id!r}", "equipment", "device_id")
    for name in ("events", "data", "status"):
        for key, value in tables[name].items():
            if isinstance(value, bool) or not isinstance(value, int) \
                    or not 1 <= value <= MAX_U4:
                raise error(f"[{name}] {key}: expected a whole number 1-{MAX_U4} (U4), got "
                            f"{value!r}", name, key)
    ports = _ports(data.get("port", []), text, source, lines)
    return ToolIds(equipment["mdln"], equipment["softrev"], device_id, tables["events"],
                   tables["data"], tables["status"], ports, source, lines)


def _ports(entries, text, source, lines):
    from ..core.files.scenario import _Lines

    where = _Lines(text)
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise InputError(source, where.of(None, None, "port"), "write ports as [[port]] tables")
    ports, numbers, carriers = [], {}, {}
    for index, entry in enumerate(entries):
        def error(message, key=None):
            return InputError(source, where.of("port", index, key),
                              f"[[port]] #{index + 1} {key + ': ' if key else ''}{message}")

        for key in entry:
            if key not in _PORT_KEYS:
                raise error(f"unknown key (known: {', '.join(_PORT_KEYS)})", key)
            lines[("port", index, key)] = where.of("port", index, key)
        if "carrier" not in entry:
            raise error("missing key 'carrier' (the layout's carrier at this port)")
        carrier, number = entry["carrier"], entry.get("number")
        if not isinstance(carrier, str) or not carrier:
            raise error(f"expected a carrier's name, got {carrier!r}", "carrier")
        if number is not None and (isinstance(number, bool) or not isinstance(number, int)
                                   or not 1 <= number <= 255):
            raise error(f"expected a port number 1-255 (PTN is U1), got {number!r}", "number")
        carrier_id = entry.get("carrier_id", carrier)
        if not isinstance(carrier_id, str) or not carrier_id or not carrier_id.isascii():
            raise error(f"expected ASCII text, got {carrier_id!r}", "carrier_id")
        if number is not None and number in numbers:
            raise error(f"port {number} is already carrier {numbers[number]!r}'s", "number")
        if carrier in carriers:
            raise error(f"carrier {carrier!r} has a [[port]] already", "carrier")
        if number is not None:
            numbers[number] = carrier
        carriers[carrier] = number
        ports.append(PortIds(carrier, number, carrier_id))
    return tuple(ports)
