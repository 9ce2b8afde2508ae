"""SEMI E87 carrier management as a virtual load port sees it (SPEC §14): each port's carrier,
its slot-map status, the host's carrier actions and the answers they get.

No SECS/GEM here: the HSMS side (``host.equipment``) turns messages into the calls below and the
``Transition`` values they return into collection events. Every call is safe from any thread.

>>> ports = LoadPorts([LoadPort(1, "LP1", 3)])
>>> ports.arrive(1, "FOUP7").status_name
'SLOT MAP NOT READ'
>>> ports.slot_map_read(1, (3, 1, 3)).status_name
'WAITING FOR HOST'
>>> reply, events = ports.carrier_action("ProceedWithCarrier", "FOUP7", 1, [("SlotMap", [3, 3, 3])])
>>> reply.caack, reply.errors[0].text
(3, 'SlotMap slot 2: the host expects 3 (correctly occupied), the equipment read 1 (empty)')
>>> events[0].status_name, ports.port(1).status
('VERIFICATION FAILED', 3)
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

# SlotMapStatus, numbered as E87 numbers it.
SLOT_MAP_NOT_READ, WAITING_FOR_HOST, VERIFICATION_OK, VERIFICATION_FAILED = 0, 1, 2, 3
STATUS_NAMES = {SLOT_MAP_NOT_READ: "SLOT MAP NOT READ", WAITING_FOR_HOST: "WAITING FOR HOST",
                VERIFICATION_OK: "VERIFICATION OK", VERIFICATION_FAILED: "VERIFICATION FAILED"}

# E87 SlotMap values (core.mapping.E87 gives them from slot states).
SLOT_VALUES = {0: "undefined", 1: "empty", 2: "not empty", 3: "correctly occupied",
               4: "double slotted", 5: "cross slotted"}
OCCUPIED = (2, 3, 4, 5)  # what SubstrateCount counts: every slot read as holding something

# CAACK, the carrier action's acknowledge code (SEMI E5).
ACKNOWLEDGED, INVALID_COMMAND, CANNOT_PERFORM_NOW, INVALID_DATA, REJECTED_INVALID_STATE = (
    0, 1, 2, 3, 5)
# ERRCODE values used in S3F18 (SEMI E5's table).
UNKNOWN_OBJECT_INSTANCE = 3
UNKNOWN_ATTRIBUTE = 4
INVALID_ATTRIBUTE_VALUE = 7
VERIFICATION_ERROR = 9
UNSUPPORTED_OPTION = 14
COMMAND_NOT_VALID_NOW = 17
LOAD_PORT_DOES_NOT_EXIST = 48

PROCEED, CANCEL = "ProceedWithCarrier", "CancelCarrier"
CARRIER_ACTIONS = (PROCEED, CANCEL)
# The attributes a host may send with ProceedWithCarrier (E87's settable carrier attributes).
PROCEED_ATTRIBUTES = ("Capacity", "SubstrateCount", "SlotMap", "Usage", "ContentMap")
# What S14F1 GetAttr answers for OBJTYPE "Carrier", in this order when no names are asked.
CARRIER_ATTRIBUTES = ("ObjID", "ObjType", "SlotMap", "SlotMapStatus", "Capacity",
                      "SubstrateCount", "Usage", "ContentMap", "PortID")


@dataclass(frozen=True)
class Transition:
    """One change of a carrier's state: what the collection event reports."""

    port: int
    carrier_id: str
    status: int | None  # the new SlotMapStatus; None when the carrier was cancelled
    slot_map: tuple  # E87 values, slot 1 first (all 0 until read)
    reason: str = ""

    @property
    def status_name(self):
        return "CARRIER CANCELLED" if self.status is None else STATUS_NAMES[self.status]


@dataclass(frozen=True)
class Error:
    code: int
    text: str


@dataclass(frozen=True)
class ActionReply:
    """S3F18: CAACK and the errors behind a refusal."""

    caack: int
    errors: tuple = ()


@dataclass
class LoadPort:
    """A load port (PTN) holding one of the layout's carriers (``carrier`` is the layout's name
    for it, ``capacity`` its slot count)."""

    number: int
    carrier: str
    capacity: int
    carrier_id: str | None = None  # None: no carrier on the port
    status: int = SLOT_MAP_NOT_READ
    slot_map: tuple = ()
    reason: str = ""
    warnings: tuple = ()
    host_attributes: dict = field(default_factory=dict)  # what ProceedWithCarrier sent

    def unread_map(self):
        return (0,) * self.capacity

    def transition(self):
        return Transition(self.number, self.carrier_id, self.status,
                          self.slot_map or self.unread_map(), self.reason)

    @property
    def substrate_count(self):
        return sum(1 for value in self.slot_map if value in OCCUPIED)


def slot_map_difference(expected, read):
    """Why a host's expected SlotMap is not the one read, naming the first differing slot;
    None when they agree."""
    if len(expected) != len(read):
        return f"SlotMap has {len(expected)} slots, the carrier {len(read)}"
    for slot, (want, have) in enumerate(zip(expected, read), start=1):
        if want != have:
            return (f"SlotMap slot {slot}: the host expects {want} ({SLOT_VALUES.get(want, '?')})"
                    f", the equipment read {have} ({SLOT_VALUES[have]})"
                    + (" - the slot was not wholly scanned" if have == 0 else ""))
    return None


def _integer(value):
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError
    return value


def _slot_values(value):
    values = tuple(_integer(v) for v in value)
    if any(v not in SLOT_VALUES for v in values):
        raise ValueError
    return values


def _text(value):
    if not isinstance(value, str):
        raise ValueError
    return value


def _content_map(value):
    pairs = tuple(tuple(pair) for pair in value)
    if any(len(pair) != 2 or not all(isinstance(s, str) for s in pair) for pair in pairs):
        raise ValueError
    return pairs


_CHECKS = {"Capacity": _integer, "SubstrateCount": _integer, "SlotMap": _slot_values,
           "Usage": _text, "ContentMap": _content_map}
_SHAPES = {"Capacity": "an integer", "SubstrateCount": "an integer",
           "SlotMap": "a list of E87 slot values 0-5", "Usage": "a text",
           "ContentMap": "a list of (LotID, SubstID) pairs"}


class LoadPorts:
    """The equipment's load ports and their carriers' E87 state, behind one lock."""

    def __init__(self, ports):
        self._ports = {p.number: p for p in ports}
        self._lock = threading.Lock()

    @property
    def numbers(self):
        return tuple(self._ports)

    def port(self, number):
        """A copy of the port's state, for showing it."""
        with self._lock:
            p = self._ports[number]
            return LoadPort(p.number, p.carrier, p.capacity, p.carrier_id, p.status,
                            p.slot_map, p.reason, p.warnings, dict(p.host_attributes))

    def port_of_layout_carrier(self, name):
        for p in self._ports.values():
            if p.carrier == name:
                return p.number
        return None

    def arrive(self, number, carrier_id):
        """A carrier is placed on the port: its slot map is not read yet."""
        with self._lock:
            p = self._ports[number]
            p.carrier_id, p.status, p.slot_map, p.reason, p.warnings = (
                carrier_id, SLOT_MAP_NOT_READ, (), "", ())
            p.host_attributes = {}
            return p.transition()

    def occupant(self, number):
        """Why a new carrier cannot be placed on the port now, or None: a carrier whose map is
        not read yet or waits for the host's verification is still the host's to decide on
        (ProceedWithCarrier or CancelCarrier). A verified carrier (OK or FAILED) leaves when the
        next one arrives."""
        with self._lock:
            p = self._ports[number]
            if p.carrier_id is not None and p.status in (SLOT_MAP_NOT_READ, WAITING_FOR_HOST):
                return (f"port {number} holds carrier {p.carrier_id!r} "
                        f"({STATUS_NAMES[p.status]}): the host proceeds with it or cancels it "
                        "first")
            return None

    def slot_map_read(self, number, slot_map, warnings=(), carrier_id=None):
        """The port's carrier was scanned: its E87 SlotMap, the host's turn to verify it.
        None when the carrier is no longer there to be read (``carrier_id`` given: the host
        cancelled it while it was being scanned)."""
        with self._lock:
            p = self._ports[number]
            if carrier_id is not None and (p.carrier_id != carrier_id
                                           or p.status != SLOT_MAP_NOT_READ):
                return None
            if p.carrier_id is None or p.status != SLOT_MAP_NOT_READ:
                raise ValueError(f"port {number} has no carrier waiting for its slot map")
            if len(slot_map) != p.capacity:
                raise ValueError(f"port {number}: {len(slot_map)} slots read, capacity "
                                 f"{p.capacity}")
            p.slot_map, p.status, p.warnings = tuple(slot_map), WAITING_FOR_HOST, tuple(warnings)
            return p.transition()

    def find(self, carrier_id):
        """The port holding the carrier, or None."""
        with self._lock:
            return self._find(carrier_id)

    def _find(self, carrier_id):
        for p in self._ports.values():
            if p.carrier_id is not None and p.carrier_id == carrier_id:
                return p
        return None

    def carrier_action(self, action, carrier_id, port_number, attributes):
        """S3F17: ``action`` on ``carrier_id`` at ``port_number`` (0: wherever it is) with the
        host's (name, value) attributes. Returns the ``ActionReply`` and the transitions it made
        (to be reported as events after the reply)."""
        with self._lock:
            if action not in CARRIER_ACTIONS:
                return ActionReply(INVALID_COMMAND, (Error(
                    UNSUPPORTED_OPTION, f"unknown carrier action {action!r} (this load port "
                    f"carries out {' and '.join(CARRIER_ACTIONS)})"),)), []
            p = self._find(carrier_id)
            if p is None:
                return ActionReply(INVALID_DATA, (Error(
                    UNKNOWN_OBJECT_INSTANCE, f"no carrier {carrier_id!r} at any load port"),)), []
            if port_number and port_number != p.number:
                known = port_number in self._ports
                return ActionReply(INVALID_DATA, (Error(
                    INVALID_ATTRIBUTE_VALUE if known else LOAD_PORT_DOES_NOT_EXIST,
                    f"carrier {carrier_id!r} is at port {p.number}, not port {port_number}"
                    + ("" if known else f" (no port {port_number})")),)), []
            if action == CANCEL:
                return self._cancel(p)
            return self._proceed(p, attributes)

    def _cancel(self, p):
        gone = Transition(p.number, p.carrier_id, None, p.slot_map or p.unread_map(),
                          "cancelled by the host")
        p.carrier_id, p.status, p.slot_map, p.reason, p.warnings = (
            None, SLOT_MAP_NOT_READ, (), "", ())
        p.host_attributes = {}
        return ActionReply(ACKNOWLEDGED), [gone]

    def _proceed(self, p, attributes):
        if p.status == SLOT_MAP_NOT_READ:
            return ActionReply(CANNOT_PERFORM_NOW, (Error(
                COMMAND_NOT_VALID_NOW, f"carrier {p.carrier_id!r}: the slot map is not read "
                "yet"),)), []
        if p.status != WAITING_FOR_HOST:
            return ActionReply(REJECTED_INVALID_STATE, (Error(
                COMMAND_NOT_VALID_NOW, f"carrier {p.carrier_id!r} is in "
                f"{STATUS_NAMES[p.status]}, not WAITING FOR HOST"),)), []
        given, errors = {}, []
        for name, value in attributes:
            if name not in _CHECKS:
                errors.append(Error(UNKNOWN_ATTRIBUTE, f"unknown attribute {name!r} for "
                                    f"{PROCEED} (known: {', '.join(PROCEED_ATTRIBUTES)})"))
                continue
            try:
                given[name] = _CHECKS[name](value)
            except (TypeError, ValueError):
                errors.append(Error(INVALID_ATTRIBUTE_VALUE,
                                    f"{name}: expected {_SHAPES[name]}, got {value!r:.80}"))
        if errors:  # a malformed request changes nothing: the host may send it again
            return ActionReply(INVALID_DATA, tuple(errors)), []
        if "ContentMap" in given and len(given["ContentMap"]) != p.capacity:
            return ActionReply(INVALID_DATA, (Error(
                INVALID_ATTRIBUTE_VALUE, f"ContentMap has {len(given['ContentMap'])} entries, "
                f"the carrier {p.capacity} slots"),)), []
        reason = self._verification_failure(p, given)
        p.host_attributes = given
        if reason:
            p.status, p.reason = VERIFICATION_FAILED, reason
            return ActionReply(INVALID_DATA, (Error(VERIFICATION_ERROR, reason),)), [
                p.transition()]
        p.status, p.reason = VERIFICATION_OK, ""
        return ActionReply(ACKNOWLEDGED), [p.transition()]

    @staticmethod
    def _verification_failure(p, given):
        if "Capacity" in given and given["Capacity"] != p.capacity:
            return f"Capacity {given['Capacity']}: the carrier has {p.capacity} slots"
        if "SlotMap" in given:
            differs = slot_map_difference(given["SlotMap"], p.slot_map)
            if differs:
                return differs
        if "SubstrateCount" in given and given["SubstrateCount"] != p.substrate_count:
            return (f"SubstrateCount {given['SubstrateCount']}: the equipment read "
                    f"{p.substrate_count} slots holding a substrate")
        return None

    def attributes(self, carrier_id, names=()):
        """S14F1 GetAttr of a carrier: [(name, value)] for ``names`` (all when empty) and the
        errors for names it does not have; None when no port holds the carrier."""
        with self._lock:
            p = self._find(carrier_id)
            if p is None:
                return None
            values = {"ObjID": p.carrier_id, "ObjType": "Carrier",
                      "SlotMap": list(p.slot_map or p.unread_map()), "SlotMapStatus": p.status,
                      "Capacity": p.capacity, "SubstrateCount": p.substrate_count,
                      "Usage": p.host_attributes.get("Usage", ""),
                      "ContentMap": [list(pair) for pair in p.host_attributes.get(
                          "ContentMap", ())],
                      "PortID": p.number}
            found, errors = [], []
            for name in names or CARRIER_ATTRIBUTES:
                if name in values:
                    found.append((name, values[name]))
                else:
                    errors.append(Error(UNKNOWN_ATTRIBUTE, f"unknown attribute {name!r} of a "
                                        f"Carrier (known: {', '.join(CARRIER_ATTRIBUTES)})"))
            return found, errors
