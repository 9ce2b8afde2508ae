"""Slot mapping: from sensor runs to one state per slot, the slot code and the SEMI E87 map.

A real controller sees only the sensor's runs; it knows the carrier's nominal slots (seat of slot
1, pitch, count) and the wafer's nominal thickness, and judges each run by its bottom edge and its
length (SPEC §4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

EMPTY, PRESENT, CROSS, DOUBLE, THIN, POSITION_ERROR, PROTRUDING = 0, 1, 2, 3, 4, 5, 6
# A slot whose window the scan did not wholly cover (SPEC §3, §4): its state is not known, and
# its code character is "?" itself, so that ``str(state)`` spells the slot code for every state.
UNSCANNED = "?"

STATE_NAMES = {
    EMPTY: "empty",
    PRESENT: "present",
    CROSS: "cross-slotted",
    DOUBLE: "double",
    THIN: "thin",
    POSITION_ERROR: "position error",
    PROTRUDING: "protruding",
    UNSCANNED: "unscanned",
}

# SEMI E87 SlotMap: 1 empty, 3 correctly occupied, 4 double slotted, 5 cross slotted,
# 2 not empty for the other abnormal states, 0 undefined for a slot the scan did not cover.
E87 = {EMPTY: 1, PRESENT: 3, CROSS: 5, DOUBLE: 4, THIN: 2, POSITION_ERROR: 2, PROTRUDING: 2,
       UNSCANNED: 0}

# When several findings land on one slot the worst one is reported.
_SEVERITY = (EMPTY, PRESENT, THIN, POSITION_ERROR, DOUBLE, CROSS, PROTRUDING)
_RANK = {state: rank for rank, state in enumerate(_SEVERITY)}  # _SEVERITY.index, looked up

# Limits are inclusive up to this much (mm), so that a length or offset that equals a limit is
# not pushed across it by rounding (113.85 - 113.5 != 0.35 in binary floating point).
LIMIT_SLACK = 1e-9


@dataclass(frozen=True)
class SlotPlan:
    """The nominal slots and wafer the controller judges against (the MCS's taught values)."""

    slot_count: int
    pitch: float
    first_slot_z: float
    wafer_thickness: float
    thickness_tolerance: float
    position_tolerance: float
    protrusion_limit: float = 1.0

    def seat_z(self, slot):
        return self.first_slot_z + (slot - 1) * self.pitch

    def window(self, slot):
        """The Z range (mm) a scan must cover to judge the slot: half a pitch either side of
        its seat (the windows tile the carrier)."""
        seat = self.seat_z(slot)
        return (seat - 0.5 * self.pitch, seat + 0.5 * self.pitch)

    def nearest_slot(self, z):
        """The slot whose seat is nearest to z, kept within 1..slot_count."""
        return min(self.slot_count, max(1, _nearest_slot(self, z)))


@dataclass(frozen=True)
class SlotState:
    slot: int
    seat_z: float
    state: int
    runs: tuple  # indices into the run list given to ``map_slots``


@dataclass(frozen=True)
class SlotMap:
    slots: tuple

    @property
    def code(self):
        """One character per slot, slot 1 first."""
        return "".join(str(s.state) for s in self.slots)

    @property
    def e87(self):
        return "".join(str(E87[s.state]) for s in self.slots)


def _nearest_slot(plan, z):
    return int(math.floor((z - plan.first_slot_z) / plan.pitch + 0.5)) + 1


def judge_run(plan, bottom, top):
    """Which slots a run (bottom, top in scan Z, bottom <= top) speaks for and what it says:
    a list of (slot, state). Slots outside 1..slot_count are left out."""
    t = plan.wafer_thickness
    dt = plan.thickness_tolerance
    length = top - bottom
    eps = LIMIT_SLACK
    if length > 2.0 * t + dt + eps:
        middle = 0.5 * (bottom + top)
        lower = int(math.floor((middle - plan.first_slot_z) / plan.pitch)) + 1
        found = [(lower, CROSS), (lower + 1, CROSS)]
    else:
        slot = _nearest_slot(plan, bottom)
        if abs(bottom - plan.seat_z(slot)) > plan.position_tolerance + eps:
            state = POSITION_ERROR
        elif length < t - dt - eps:
            state = THIN
        elif length <= t + dt + eps:
            state = PRESENT
        else:
            state = DOUBLE
        found = [(slot, state)]
    return [(slot, state) for slot, state in found if 1 <= slot <= plan.slot_count]


def unscanned_slots(plan, scanned):
    """The slots whose window is not wholly inside ``scanned`` (low, high scan Z, mm; None: the
    scan covered nothing)."""
    if scanned is None:
        return list(range(1, plan.slot_count + 1))
    low, high = scanned
    outside = []
    for slot in range(1, plan.slot_count + 1):
        bottom, top = plan.window(slot)
        if bottom < low - LIMIT_SLACK or top > high + LIMIT_SLACK:
            outside.append(slot)
    return outside


def map_slots(plan, runs, protruding_slots=(), unscanned=()):
    """Slot states from sensor runs given as (bottom, top) pairs; ``protruding_slots`` are the
    slots a protrusion check flagged (state 6); ``unscanned`` the slots whose window the scan did
    not wholly cover: whatever their runs say is not known, so they are ``?`` (SPEC §3). The
    load port's protrusion check does not depend on the scan: 6 outranks ``?`` too."""
    states = {slot: EMPTY for slot in range(1, plan.slot_count + 1)}
    members = {slot: [] for slot in states}
    for index, (bottom, top) in enumerate(runs):
        two_runs_in_one_slot = set()
        for slot, state in judge_run(plan, bottom, top):
            if members[slot] and state != CROSS:
                # A second run in a slot is not a normally inserted wafer.
                two_runs_in_one_slot.add(slot)
            members[slot].append(index)
            if _RANK[state] > _RANK[states[slot]]:
                states[slot] = state
        for slot in two_runs_in_one_slot:
            if _RANK[POSITION_ERROR] > _RANK[states[slot]]:
                states[slot] = POSITION_ERROR
    for slot in unscanned:
        if slot in states:
            states[slot] = UNSCANNED
    for slot in protruding_slots:
        if slot in states:
            states[slot] = PROTRUDING
    # states' keys are 1..slot_count in order already: sorted(states) is that range
    return SlotMap(tuple([SlotState(slot, plan.seat_z(slot), states[slot], tuple(members[slot]))
                          for slot in range(1, plan.slot_count + 1)]))
