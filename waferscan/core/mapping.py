"""Slot mapping: from sensor runs to one state per slot, the slot code and the SEMI E87 map.

A real controller sees only the sensor's runs; it knows the carrier's nominal slots (seat of slot
1, pitch, count) and the wafer's nominal thickness, and judges each run by its bottom edge and its
length (SPEC §4), or under the ``boundary`` rule set by its centre and length (SPEC §11).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

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
_RANK_OF_CODE = tuple(_RANK[code] for code in range(len(_SEVERITY)))  # by state code, for arrays

# Limits are inclusive up to this much (mm), so that a length or offset that equals a limit is
# not pushed across it by rounding (113.85 - 113.5 != 0.35 in binary floating point).
LIMIT_SLACK = 1e-9

# The rule sets a plan may judge by (SPEC §11, ``SlotPlan.rules``).
WAFERSCAN, BOUNDARY = "waferscan", "boundary"
RULE_SETS = (WAFERSCAN, BOUNDARY)
# Under "boundary" rules a run thicker than this many nominal thicknesses near a boundary is
# cross-slotted (DOMAIN-NOTES: the open load-port controller's 2.5 t).
BOUNDARY_CROSS_FACTOR = 2.5


@dataclass(frozen=True)
class SlotPlan:
    """The nominal slots and wafer the controller judges against (the MCS's taught values),
    and the recipe it judges by (SPEC §11).

    A judge of its own (a vectorised one over many layouts) takes the limits resolved from
    ``thickness_window()``, ``position_window()`` and ``double_limit()`` (not the fields, whose
    None stands for a rule), divides diffs by ``thickness_correction`` (``corrected``), compares
    with LIMIT_SLACK's inclusiveness, and follows ``judge_run``'s order for ``rules``:
    "waferscan" judges position before thickness, "boundary" thickness before position."""

    slot_count: int
    pitch: float
    first_slot_z: float
    wafer_thickness: float
    thickness_tolerance: float
    position_tolerance: float
    protrusion_limit: float = 1.0
    # The recipe (SPEC §11). None keeps the SPEC §4 rule built from t, Δt and Δp, so a plan
    # without a recipe judges exactly as before.
    thickness_min: float | None = None      # mm; None: t − Δt
    thickness_max: float | None = None      # mm; None: t + Δt
    double_threshold: float | None = None   # mm; None: 2t + Δt ("waferscan"), 2.5 t ("boundary")
    position_below: float | None = None     # mm below the seat; None: Δp
    position_above: float | None = None     # mm above the seat; None: Δp
    rules: str = "waferscan"                # "waferscan" (SPEC §4) or "boundary" (SPEC §11)
    # Measured diffs are divided by this before they are judged: a calibration's measured mean
    # thickness over the nominal one (a sensor that reads every wafer 2 % thick gives 1.02).
    thickness_correction: float = 1.0

    def __post_init__(self):
        if self.rules not in RULE_SETS:
            raise ValueError(f"rules must be one of {', '.join(RULE_SETS)}, not {self.rules!r}")

    def thickness_window(self):
        """(min, max) diff (mm, after the thickness correction) of a present wafer; both limits
        are inclusive up to LIMIT_SLACK. A shorter run is thin; a longer one double (or
        cross-slotted beyond ``double_limit()``)."""
        t, dt = self.wafer_thickness, self.thickness_tolerance
        low = t - dt if self.thickness_min is None else self.thickness_min
        high = t + dt if self.thickness_max is None else self.thickness_max
        return (low, high)

    def position_window(self):
        """(below, above): how far (mm, both >= 0) a run's bottom edge may lie below and above
        its slot's seat and still be seated (under ``"boundary"`` rules: its centre below and
        above the slot's reference, ``reference_z``); inclusive up to LIMIT_SLACK."""
        below = self.position_tolerance if self.position_below is None else self.position_below
        above = self.position_tolerance if self.position_above is None else self.position_above
        return (below, above)

    def double_limit(self):
        """The diff (mm, after the thickness correction) beyond which a run is cross-slotted.
        Under ``"waferscan"`` rules any run longer than this is cross-slotted; under
        ``"boundary"`` rules only one whose centre lies within a third of a pitch of a slot
        boundary (a run that crosses a boundary is cross-slotted at any length). The default
        depends on the rule set: 2t + Δt (SPEC §4) or 2.5 t (the open controller's rule)."""
        if self.double_threshold is not None:
            return self.double_threshold
        if self.rules == BOUNDARY:
            return BOUNDARY_CROSS_FACTOR * self.wafer_thickness
        return 2.0 * self.wafer_thickness + self.thickness_tolerance

    def corrected(self, diff):
        """A measured diff (mm) as the rules judge it: divided by the thickness correction."""
        if self.thickness_correction == 1.0:
            return diff
        return diff / self.thickness_correction

    def reference_z(self, slot):
        """Under ``"boundary"`` rules, the slot's **reference** (mm): where a seated wafer's
        centre is expected, its seat plus half the nominal thickness. A run belongs to the slot
        whose reference is nearest its centre and is placed by its centre against it."""
        return self.seat_z(slot) + 0.5 * self.wafer_thickness

    def boundary_z(self, slot):
        """The Z (mm) of the boundary between ``slot`` and ``slot + 1`` under ``"boundary"``
        rules: halfway between their references. There is none below slot 1 or above the top
        slot: only 1 <= slot < slot_count has one."""
        return self.reference_z(slot) + 0.5 * self.pitch

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


@dataclass(slots=True, unsafe_hash=True)  # logically immutable, as scan_result.SensorRun
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
    a list of (slot, state), by the plan's rule set. Slots outside 1..slot_count are left out."""
    return run_judge(plan)(bottom, top)


def run_judge(plan):
    """``judge_run`` for one plan, as a function of (bottom, top): what depends on the plan
    alone (its rule set and limits) worked out once for all of a scan's runs."""
    if plan.rules == BOUNDARY:  # its slots are always within 1..slot_count
        return partial(_judge_by_boundaries, plan)
    return _bottom_edge_judge(plan)


def _judge_by_bottom_edge(plan, bottom, top):
    return _bottom_edge_judge(plan)(bottom, top)


def _bottom_edge_limits(plan):
    """(double, below, above, low, high): the plan's limits as SPEC §4's judge compares with
    them, each with LIMIT_SLACK added as its comparison adds it (the same sums, so the same
    floats)."""
    eps = LIMIT_SLACK
    below, above = plan.position_window()
    low, high = plan.thickness_window()
    return (plan.double_limit() + eps, below + eps, above + eps, low - eps, high + eps)


def _bottom_edge_judge(plan):
    """SPEC §4 for one plan, as a function of (bottom, top) giving ``judge_run``'s list: a run
    longer than the double limit is cross-slotted (both slots around its midpoint); any other
    run belongs to the seat nearest its bottom edge and is judged first by position, then by
    thickness. The plan's limits are read once here, with LIMIT_SLACK added as each comparison
    adds it (the same sums, so the same floats); ``_nearest_slot`` and ``seat_z`` are written
    out, as this runs for every run of a scan."""
    double, below, above, low, high = _bottom_edge_limits(plan)
    first, pitch, count = plan.first_slot_z, plan.pitch, plan.slot_count
    correction = plan.thickness_correction
    floor = math.floor

    def judge(bottom, top):
        length = top - bottom if correction == 1.0 else (top - bottom) / correction
        if length > double:
            lower = int(floor((0.5 * (bottom + top) - first) / pitch)) + 1
            return [(slot, CROSS) for slot in (lower, lower + 1) if 1 <= slot <= count]
        slot = int(floor((bottom - first) / pitch + 0.5)) + 1
        if not 1 <= slot <= count:
            return []
        offset = bottom - (first + (slot - 1) * pitch)
        if offset > above or -offset > below:
            return [(slot, POSITION_ERROR)]
        if length < low:
            return [(slot, THIN)]
        return [(slot, PRESENT if length <= high else DOUBLE)]

    return judge


def _nearest_reference(plan, z):
    """The slot whose reference (``SlotPlan.reference_z``) is nearest to z, kept within
    1..slot_count: under ``"boundary"`` rules there is no boundary beyond the outer slots, so a
    run below slot 1's or above the top slot's is theirs."""
    first = plan.first_slot_z + 0.5 * plan.wafer_thickness
    slot = int(math.floor((z - first) / plan.pitch + 0.5)) + 1
    return min(plan.slot_count, max(1, slot))


def _judge_by_boundaries(plan, bottom, top):
    """SPEC §11 "boundary" rules (the open controller of DOMAIN-NOTES): a slot's reference is
    its seat + t/2 and the boundary between two slots lies halfway between their references
    (none beyond the outer slots). A run belongs to the slot whose reference is nearest its
    centre; it is cross-slotted when it crosses a boundary (every slot it spans gets 2) or when
    it is longer than the double limit with its centre within a third of a pitch of a boundary
    (both slots around that boundary get 2); otherwise it is judged first by thickness (thick,
    thin) and only then by the position of its centre against the reference, with the
    position window (below, above) of the plan."""
    length = plan.corrected(top - bottom)
    eps = LIMIT_SLACK
    count = plan.slot_count
    centre = 0.5 * (bottom + top)
    slot = _nearest_reference(plan, centre)
    # The boundaries between the slots nearest the run's ends: a run that reaches past one
    # crosses it; a run may span several slots.
    lowest = _nearest_reference(plan, bottom)
    highest = _nearest_reference(plan, top)
    crossed = [s for s in range(lowest, highest) if bottom < plan.boundary_z(s) - eps
               and top > plan.boundary_z(s) + eps]
    if crossed:
        spanned = sorted({s for b in crossed for s in (b, b + 1)})
        return [(s, CROSS) for s in spanned]
    if length > plan.double_limit() + eps:
        third = plan.pitch / 3.0 + eps
        if slot < count and plan.boundary_z(slot) - centre <= third:
            return [(slot, CROSS), (slot + 1, CROSS)]
        if slot > 1 and centre - plan.boundary_z(slot - 1) <= third:
            return [(slot - 1, CROSS), (slot, CROSS)]
    low, high = plan.thickness_window()
    offset = centre - plan.reference_z(slot)
    below, above = plan.position_window()
    if length > high + eps:
        state = DOUBLE
    elif length < low - eps:
        state = THIN
    elif offset > above + eps or -offset > below + eps:
        state = POSITION_ERROR
    else:
        state = PRESENT
    return [(slot, state)]


def two_run_warnings(plan, slot_map, runs):
    """Under ``"boundary"`` rules, one sentence for each slot that reads a position error
    because a second run landed in it (``map_slots``), naming its runs (``runs``: the (bottom,
    top) pairs given to ``map_slots``). The controller those rules come from keeps a slot's last
    run and says nothing; WaferScan keeps the finding, and says why it differs."""
    if plan.rules != BOUNDARY:
        return []
    judge = run_judge(plan)
    warnings = []
    for s in slot_map.slots:
        if s.state != POSITION_ERROR or len(s.runs) < 2:
            continue
        if not any(state != CROSS for i in s.runs[1:] for slot, state in judge(*runs[i])
                   if slot == s.slot):
            continue
        named = " and ".join(f"{runs[i][0]:.3f} to {runs[i][1]:.3f} mm" for i in s.runs)
        warnings.append(f"slot {s.slot} holds {len(s.runs)} sensor runs ({named}): reported "
                        f"as a position error (5); the controller of the boundary rules keeps "
                        f"only the last run, which would hide a wafer")
    return warnings


def unscanned_slots(plan, scanned):
    """The slots whose window is not wholly inside ``scanned`` (low, high scan Z, mm; None: the
    scan covered nothing)."""
    if scanned is None:
        return list(range(1, plan.slot_count + 1))
    low, high = scanned
    # The windows rise with the slot (seat_z is first + (slot - 1) * pitch, pitch > 0): when
    # the lowest starts and the highest ends inside, every window is inside, as most scans'.
    if plan.window(1)[0] >= low - LIMIT_SLACK and plan.window(plan.slot_count)[1] <= high + \
            LIMIT_SLACK:
        return []
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
    count = plan.slot_count
    # By slot number (index 0 unused): a scan maps every slot, once. A slot's tuple of runs is
    # made when its first run comes and grown by a second (most slots of a scan have one run
    # or none): the SlotState's own, without a list to copy.
    states = [EMPTY] * (count + 1)
    members = [None] * (count + 1)
    if plan.rules == BOUNDARY:
        _land_runs(plan, runs, states, members)
    else:
        _land_by_bottom_edge(plan, runs, states, members)
    for slot in unscanned:
        if 1 <= slot <= count:
            states[slot] = UNSCANNED
    for slot in protruding_slots:
        if 1 <= slot <= count:
            states[slot] = PROTRUDING
    first, pitch = plan.first_slot_z, plan.pitch  # seat_z(slot), written out
    return SlotMap(tuple([SlotState(slot, first + (slot - 1) * pitch, state,
                                    () if held is None else held)
                          for slot, state, held in zip(range(1, count + 1), states[1:],
                                                       members[1:])]))


def _land_runs(plan, runs, states, members):
    """``map_slots``' states and members (by slot number: a tuple of run indices, None for
    none yet) of the runs, by ``run_judge``'s findings: the worst finding a slot wins, and a
    second run in a slot that is not cross-slotted is a position error."""
    judge = run_judge(plan)
    rank = _RANK
    for index, (bottom, top) in enumerate(runs):
        two_runs_in_one_slot = None
        for slot, state in judge(bottom, top):
            held = members[slot]
            if held is None:
                members[slot] = (index,)
            else:
                if state != CROSS:
                    # A second run in a slot is not a normally inserted wafer.
                    two_runs_in_one_slot = (two_runs_in_one_slot or []) + [slot]
                members[slot] = held + (index,)
            if rank[state] > rank[states[slot]]:
                states[slot] = state
        for slot in two_runs_in_one_slot or ():
            if rank[POSITION_ERROR] > rank[states[slot]]:
                states[slot] = POSITION_ERROR


def _land_by_bottom_edge(plan, runs, states, members):
    """``_land_runs`` under the "waferscan" rules, with ``_bottom_edge_judge``'s body written
    out in the loop (the same limits and sums, so the same states; tests/core/test_fab_floor.py
    checks it against ``_land_runs``): its list of findings a run and the call were a third of
    the slot map of a fab's scan. A run lands in one slot, or (cross-slotted) in the two around
    its midpoint, which are CROSS and so never a second run's position error. A slot without
    members is EMPTY (as the caller makes them, and as landing keeps them: a state is set
    where a member is)."""
    double, below, above, low, high = _bottom_edge_limits(plan)
    first, pitch, count = plan.first_slot_z, plan.pitch, plan.slot_count
    correction = plan.thickness_correction
    floor = math.floor
    rank = _RANK_OF_CODE  # by state code: every state here is a number
    cross_rank, error_rank = rank[CROSS], rank[POSITION_ERROR]
    for index, (bottom, top) in enumerate(runs):
        length = top - bottom if correction == 1.0 else (top - bottom) / correction
        if length > double:
            # (math.floor of a float is an int: _bottom_edge_judge's int() of it, left out)
            lower = floor((0.5 * (bottom + top) - first) / pitch) + 1
            for slot in (lower, lower + 1):
                if 1 <= slot <= count:
                    held = members[slot]
                    members[slot] = (index,) if held is None else held + (index,)
                    if cross_rank > rank[states[slot]]:
                        states[slot] = CROSS
            continue
        slot = floor((bottom - first) / pitch + 0.5) + 1
        if not 1 <= slot <= count:
            continue
        offset = bottom - (first + (slot - 1) * pitch)
        if offset > above or -offset > below:
            state = POSITION_ERROR
        elif length < low:
            state = THIN
        else:
            state = PRESENT if length <= high else DOUBLE
        held = members[slot]
        if held is None:
            # The slot's first run: no run landed in it, so it is still EMPTY (as map_slots
            # makes it), which every state here outranks.
            members[slot] = (index,)
            states[slot] = state
        else:
            members[slot] = held + (index,)
            if rank[state] > rank[states[slot]]:
                states[slot] = state
            # A second run in a slot is not a normally inserted wafer.
            if error_rank > rank[states[slot]]:
                states[slot] = POSITION_ERROR


def map_runs(plan, bottom, top, ok):
    """``map_slots`` over arrays (numpy), for m layouts at once: runs (m, R) by bottom and top
    (latched, ascending per layout, ``ok`` where a run exists), by either rule set, the same
    floats and the same states as ``map_slots`` layout by layout (tests/core/test_mapping_arrays.py).
    Returns (states (m, S) codes, first_run (m, S): the index of the first run in each slot, R
    where none). Protruding and unscanned slots are the caller's (``map_slots``' last steps)."""
    import numpy as np

    m, R = bottom.shape
    S = plan.slot_count
    eps = LIMIT_SLACK
    length = top - bottom
    if plan.thickness_correction != 1.0:
        length = length / plan.thickness_correction
    low, high = plan.thickness_window()
    below, above = plan.position_window()
    limit = plan.double_limit()
    first = plan.first_slot_z
    pitch = plan.pitch

    def nearest(z):
        return np.floor((z - first) / pitch + 0.5).astype(np.int64) + 1

    def seat(slot):
        return first + (slot - 1) * pitch

    landings = []  # (slot, state, valid) arrays (m, R)
    if plan.rules == BOUNDARY:
        # _judge_by_boundaries over arrays, the same floats: references at seat + t/2,
        # boundaries halfway between them, none beyond the outer slots.
        first_reference = first + 0.5 * plan.wafer_thickness

        def nearest_reference(z):
            slot = np.floor((z - first_reference) / pitch + 0.5).astype(np.int64) + 1
            return np.minimum(S, np.maximum(1, slot))

        def reference(slot):
            return seat(slot) + 0.5 * plan.wafer_thickness

        def boundary(slot):
            return reference(slot) + 0.5 * pitch

        centre = 0.5 * (bottom + top)
        slot = nearest_reference(centre)
        lowest = nearest_reference(bottom)
        highest = nearest_reference(top)
        span = int(np.max(np.where(ok, highest - lowest, 0), initial=0))

        def crossed(b):
            bz = boundary(b)
            return (b >= lowest) & (b < highest) & (bottom < bz - eps) & (top > bz + eps)

        any_crossed = np.zeros((m, R), dtype=bool)
        for j in range(span):
            any_crossed |= crossed(lowest + j)
        for j in range(span + 1):
            s = lowest + j
            spanned = crossed(s - 1) | crossed(s)
            landings.append((s, np.full((m, R), CROSS), ok & any_crossed & spanned))
        long_run = ~any_crossed & (length > limit + eps)
        third = pitch / 3.0 + eps
        up = long_run & (slot < S) & (boundary(slot) - centre <= third)
        down = long_run & ~up & (slot > 1) & (centre - boundary(slot - 1) <= third)
        landings.append((slot, np.full((m, R), CROSS), ok & (up | down)))
        landings.append((np.where(up, slot + 1, slot - 1), np.full((m, R), CROSS),
                         ok & (up | down)))
        single = ok & ~any_crossed & ~up & ~down
        offset = centre - reference(slot)
        state = np.where(length > high + eps, DOUBLE,
                         np.where(length < low - eps, THIN,
                                  np.where((offset > above + eps) | (-offset > below + eps),
                                           POSITION_ERROR, PRESENT)))
        landings.append((slot, state, single))
    else:
        cross = length > limit + eps
        middle = 0.5 * (bottom + top)
        lower = np.floor((middle - first) / pitch).astype(np.int64) + 1
        slot = nearest(bottom)
        offset = bottom - seat(slot)
        state = np.where((offset > above + eps) | (-offset > below + eps), POSITION_ERROR,
                         np.where(length < low - eps, THIN,
                                  np.where(length <= high + eps, PRESENT, DOUBLE)))
        landings.append((np.where(cross, lower, slot), np.where(cross, CROSS, state), ok))
        landings.append((lower + 1, np.full((m, R), CROSS), ok & cross))
    rank = np.zeros(m * (S + 2), dtype=np.int64)
    first_run = np.full(m * (S + 2), R, dtype=np.int64)
    rows = np.broadcast_to(np.arange(m)[:, None], (m, R))
    index = np.broadcast_to(np.arange(R)[None, :], (m, R))
    ranks = np.array(_RANK_OF_CODE)
    flat_landings = []
    for slot, state, valid in landings:
        v = valid & (slot >= 1) & (slot <= S)
        cell = (rows * (S + 2) + np.where(v, slot, 0))[v]
        np.maximum.at(rank, cell, ranks[np.asarray(state)[v]])
        np.minimum.at(first_run, cell, index[v])
        flat_landings.append((cell, np.asarray(state)[v], index[v]))
    # A second run in a slot (not a cross-slotted one) is not a normally inserted wafer.
    for cell, state, idx in flat_landings:
        late = (state != CROSS) & (idx > first_run[cell])
        np.maximum.at(rank, cell[late], _RANK_OF_CODE[POSITION_ERROR])
    rank = rank.reshape(m, S + 2)[:, 1:S + 1]
    first_run = first_run.reshape(m, S + 2)[:, 1:S + 1]
    return np.array(_SEVERITY)[rank], first_run
