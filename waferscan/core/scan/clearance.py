"""Clearance along every motion of a scan (SPEC §15): the motions, the least distance along each,
and what the results say of them. numpy-free and geometry-free: the distances come from a
*body* (``waferscan/robot/clearance.py`` measures them with coal, from the robot's collision
geometry or, without a robot, the scanner's heads), so the GUI, ``crosscheck`` and sweeps can ask
the same questions of another body.

A body answers, for a ``Motion`` and a parameter s along it (a scan position in mm, an advance in
mm or a wrist angle in degrees):

- ``nearest(motion, s)`` -> (distance mm, part, obstacle, slot): the least distance between the
  moving geometry at s and every obstacle (negative: they overlap by that much);
- ``path(motion, s0, s1)`` -> mm: a bound on how far any point of the moving geometry travels
  between s0 and s1;
- ``swept(motion)`` -> a ``Closest`` or None: the exact least distance over the whole motion when
  the body can give it in one piece (a translation of boxes, cylinders and spheres along their
  own axes sweeps them into longer ones), else None.

**Continuity.** Where ``swept`` gives no answer, ``least_along`` samples the motion and refines it
with a Lipschitz bound: between samples a and b, no point moves further than ``path(a, b)``, so
the distance there is at least ``(d(a) + d(b) - path(a, b)) / 2``. Intervals are split (lowest
bound first) until every bound is at least the least sampled distance minus ``TOLERANCE`` and,
when no sample is a contact, at least ``clearance_min``: a contact closer than ``clearance_min``
cannot be missed, and the least distance reported d is within max(``TOLERANCE``, ``RELATIVE``
|d - clearance_min|) of the true one (it is the distance at the reported position exactly): a
motion that stays far from everything needs no micrometres, one near the limit gets them. A
contact's (d < clearance_min) within ``CONTACT_RELATIVE`` |d - clearance_min|.

**Spans.** A long translation that touches something somewhere (a stocker's stroke through a
roof: 120,000 first samples) is swept span by span first; a span swept clear by more than the
refinement can reach is left unsampled, which changes nothing in the answer (``least_along``).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field, replace

from ..errors import InputError

DEFAULT_CLEARANCE_MIN = 1.0  # mm (SPEC §15)
TOLERANCE = 1e-3  # mm: how far the least distance reported may lie above the true least …
RELATIVE = 0.05  # … or this fraction of its margin to clearance_min, whichever is more
CONTACT_RELATIVE = 0.5  # the same fraction for a contact: where and what matter, not the depth
SAMPLES_PER_MM = 1.0  # first samples of a translation (per mm) and of a turn (per degree)
MAX_EVALUATIONS = 200_000  # per motion; beyond, the least lower bound is reported instead
CARRIER_NOT_CHECKED = "not checked: the layout has no carrier solids"

STROKE, STEPS, JAB, SWEEP = "stroke", "steps", "jab", "sweep"
UNITS = {STROKE: "z", STEPS: "z", JAB: "advance", SWEEP: "angle"}


@dataclass(frozen=True)
class Motion:
    """One motion of a scan: ``kind`` (stroke, steps, jab, sweep), ``phase`` in words, the
    pocket's ``slot`` (None for a stroke), the parameter from ``start`` to ``end`` (scan position
    mm for a stroke and steps, advance mm for a jab, wrist angle deg for a sweep), and where it is
    made: the scan position ``z`` of a jab or a sweep and the fork's ``advance`` during steps and
    a sweep."""

    kind: str
    phase: str
    slot: int | None
    start: float
    end: float
    z: float | None = None
    advance: float = 0.0

    @property
    def unit(self):
        return UNITS[self.kind]


@dataclass(frozen=True)
class Closest:
    """The least distance along one motion: ``distance`` mm (negative: overlapping by that
    much) at parameter ``position``, between the robot's ``part`` and the ``obstacle`` (a wafer's
    name), in ``slot`` (the obstacle's slot when known, else the motion's pocket)."""

    motion: Motion
    distance: float
    position: float
    part: str
    obstacle: str
    slot: int | None
    exact: bool = True  # False: the evaluation budget ran out; distance is a lower bound


@dataclass(frozen=True)
class ClearanceReport:
    """Every motion's least distance, against ``clearance_min``. ``body``: what moved ("robot"
    or "scanner"); ``carrier``: how the carrier was checked; ``measured_by``: the body object
    that measured it (the GUI asks it the distance at every frame; not compared)."""

    clearance_min: float
    closest: tuple
    body: str
    carrier: str = CARRIER_NOT_CHECKED
    measured_by: object = field(default=None, compare=False, repr=False)

    @property
    def least(self):
        """The Closest with the least distance over all motions, or None without motions."""
        return min(self.closest, key=lambda c: c.distance, default=None)

    @property
    def contacts(self):
        """The motions that come closer than clearance_min, in scan order."""
        return tuple(c for c in self.closest if c.distance < self.clearance_min)

    def warnings(self):
        """One sentence per contact (SPEC §3's channels: JSON, results.txt, stderr, GUI)."""
        return tuple(f"contact: {describe(c)}, under clearance_min {self.clearance_min:g} mm: "
                     "the robot must not run this scan" for c in self.contacts)

    def collision_lines(self):
        """results.txt's ``collision = …`` values, one per contact."""
        return tuple(describe(c) for c in self.contacts)

    def as_dict(self):
        """JSON's ``clearance``."""
        least = self.least
        return {"clearance_min": self.clearance_min, "body": self.body,
                "carrier": self.carrier,
                "least": None if least is None else least.distance,
                "contacts": len(self.contacts),
                "motions": [closest_dict(c) for c in self.closest]}


def closest_dict(c):
    m = c.motion
    return {"motion": m.kind, "phase": m.phase, "slot": c.slot, "pocket": m.slot,
            "distance": c.distance, "exact": c.exact, "unit": m.unit, "position": c.position,
            "z": m.z, "part": c.part, "obstacle": c.obstacle}


_WHERE = {"z": "at scan position {:.3f} mm", "advance": "advanced {:.3f} mm",
          "angle": "at wrist angle {:+.3f} deg"}


def describe(c):
    """'0.650 mm between tine_right and wafer_3 (slot 4), fast stroke up at scan position …'."""
    slot = "" if c.slot is None else f" (slot {c.slot})"
    where = _WHERE[c.motion.unit].format(c.position)
    if c.motion.z is not None and c.motion.unit != "z":
        where += f" at scan position {c.motion.z:.3f} mm"
    bound = "" if c.exact else " at least"
    return (f"{bound.strip() + ' ' if bound else ''}{c.distance:.3f} mm between {c.part} and "
            f"{c.obstacle}{slot}, {c.motion.phase} {where}")


# --- the motions of a scan ---------------------------------------------------------------------

def scan_motions(layout, pockets=None):
    """The motions a scan of the layout makes, in order. A fast scan: its stroke(s). A slow scan:
    at each pocket (``pockets``: the scanned slots; default every slot of the scanned carrier)
    its jab (advance 0 .. jab at the pocket's height), its Z steps over the pocket's window
    (the fork advanced by the jab) and its sweep (-sweep .. +sweep at the jab's depth). A
    pocket may be given as a slot number or as its ``PocketProbe``, whose ``reached`` angles
    (where the sweep stopped short of clearance_min, SPEC §13) are then the sweep's."""
    scan = layout.scan
    if scan.mode != "slow":
        up = Motion(STROKE, "fast stroke up", None, scan.start_z, scan.final_z)
        down = Motion(STROKE, "fast stroke down", None, scan.final_z, scan.start_z)
        return {"up": [up], "down": [down], "updown": [up, down]}[scan.direction]
    from .scan_result import slot_plan

    carrier = layout.scanned_carrier
    plan = slot_plan(carrier, layout.mapping)
    slots = range(1, plan.slot_count + 1) if pockets is None else pockets
    motions = []
    for pocket in slots:
        slot = getattr(pocket, "slot", pocket)
        reached = getattr(pocket, "reached", None) or (-scan.sweep, scan.sweep)
        seat = plan.seat_z(slot)
        z = seat + 0.5 * plan.wafer_thickness
        if scan.jab > 0.0:
            motions.append(Motion(JAB, f"slot {slot} jab", slot, 0.0, scan.jab, z))
        low = max(scan.start_z, seat - 0.5 * plan.pitch)
        high = min(scan.final_z, seat + 0.5 * plan.pitch)
        if high > low:
            motions.append(Motion(STEPS, f"slot {slot} steps", slot, low, high, None, scan.jab))
        if scan.sweep > 0.0:
            motions.append(Motion(SWEEP, f"slot {slot} sweep", slot, reached[0], reached[1], z,
                                  scan.jab))
    return motions


# --- the least distance along a motion ---------------------------------------------------------

def least_along(body, motion, clearance_min, tolerance=TOLERANCE, per_unit=SAMPLES_PER_MM,
                budget=MAX_EVALUATIONS):
    """The Closest of one motion, exact (``swept``) or by Lipschitz refinement (module doc).

    A long translation that ``swept`` cannot answer whole (it overlaps something somewhere) is
    cut into spans of SPAN first samples; a span the body sweeps clear of everything by a
    margin the refinement can never reach (``_clear_spans``) is not sampled: its samples could
    not be the least, nor its intervals split, so the answer is the one sampling it gives, to
    the last bit (and, should the refinement reach a span's bound after all, every sample is
    taken and the search made again)."""
    swept = body.swept(motion)
    if swept is not None:
        return swept
    a, b = motion.start, motion.end
    count = max(1, int(math.ceil(abs(b - a) * per_unit)))
    grid = [a + (b - a) * i / count for i in range(count + 1)]
    values = {}
    spans = _clear_spans(body, motion, grid, clearance_min, values)
    found = _refined(body, motion, clearance_min, tolerance, budget, grid, values, spans)
    if found is None:  # the refinement reached a span's bound: every sample, as without spans
        found = _refined(body, motion, clearance_min, tolerance, budget, grid, values, [])
    return found


# First samples of a translation a span holds (``_clear_spans``), and how far below the swept
# parts' distance to everything a span's samples are taken to lie at the least (coal's
# distances of the swept shapes and of one position agree far closer than this).
SPAN = 64
SPAN_SLACK = 0.01  # mm


def _clear_spans(body, motion, grid, clearance_min, values):
    """The spans of ``grid`` (a translation's first samples) that need no sampling: (i, j,
    low) for grid[i] .. grid[j] (its inner samples left out), swept by the body clear of
    everything, ``low`` a bound below every Lipschitz bound of an interval inside it. Kept
    only where ``low`` is at least clearance_min and the least of the samples taken (filled in
    ``values``, index -> nearest), which the refinement never passes (``_refined``): it splits
    an interval only while its bound is below the least sample found less the tolerance, or
    below clearance_min when nothing is closer than that."""
    if motion.kind not in (STROKE, STEPS) or len(grid) <= 2 * SPAN:
        return []
    spans = []
    for i in range(0, len(grid) - 1 - SPAN, SPAN):
        j = i + SPAN
        closest = body.swept(replace(motion, start=grid[i], end=grid[j]))
        if closest is None:
            continue  # overlapping something somewhere in the span: sampled
        # An interval's bound is half its ends' distances (each at least the swept one, less
        # SPAN_SLACK) less half its path; SPAN_SLACK again for the bound's rounding.
        longest = max(body.path(motion, grid[k], grid[k + 1]) for k in range(i, j))
        low = closest.distance - SPAN_SLACK - 0.5 * longest - SPAN_SLACK
        if low >= clearance_min:
            spans.append((i, j, low))
    while True:
        inner = {k for i, j, _ in spans for k in range(i + 1, j)}
        for k, s in enumerate(grid):
            if k not in inner and k not in values:
                values[k] = body.nearest(motion, s)
        least = min(v[0] for v in values.values())
        kept = [span for span in spans if span[2] >= least]
        if len(kept) == len(spans):
            return spans
        spans = kept  # a span dropped is sampled, which may lower the least


def _refined(body, motion, clearance_min, tolerance, budget, grid, values, spans):
    """The Lipschitz refinement of ``least_along`` from the first samples ``grid`` (``values``:
    those taken, by index; each one missing is taken), the inner samples of ``spans`` left out.
    None when the least bound left to split would be a span's."""
    inner = {}
    for i, j, low in spans:
        for k in range(i, j):
            inner[k] = low  # the interval grid[k] .. grid[k + 1] lies in a span
    floor = min(inner.values(), default=math.inf)
    for k, s in enumerate(grid):
        if k not in values and (k not in inner or k - 1 not in inner):
            values[k] = body.nearest(motion, s)
    taken = [k for k in range(len(grid)) if k in values]
    best_k = min(taken, key=lambda k: values[k][0])
    best_s, best = grid[best_k], values[best_k]
    heap = []

    def push(s0, v0, s1, v1):
        bound = 0.5 * (v0[0] + v1[0] - body.path(motion, s0, s1))
        heapq.heappush(heap, (bound, s0, s1, v0, v1))

    for k in range(len(grid) - 1):
        if k not in inner:
            push(grid[k], values[k], grid[k + 1], values[k + 1])
    evaluations = len(grid)
    exact = True
    while heap or spans:
        if spans and (not heap or heap[0][0] >= floor):
            return None  # the next interval to weigh could be one inside a span
        bound, s0, s1, v0, v1 = heap[0]
        fraction = CONTACT_RELATIVE if best[0] < clearance_min else RELATIVE
        slack = max(tolerance, fraction * abs(best[0] - clearance_min))
        done = bound >= best[0] - slack and (bound >= clearance_min or best[0] < clearance_min)
        if done or abs(s1 - s0) < 1e-12:
            break
        if evaluations >= budget:
            exact = False
            break
        heapq.heappop(heap)
        mid = 0.5 * (s0 + s1)
        vm = body.nearest(motion, mid)
        evaluations += 1
        if vm[0] < best[0]:
            best_s, best = mid, vm
        push(s0, v0, mid, vm)
        push(mid, vm, s1, v1)
    distance, part, obstacle, slot = best
    if not exact:
        distance = min(distance, heap[0][0])
    return Closest(motion, float(distance), float(best_s), part, obstacle,
                   motion.slot if slot is None else slot, exact)


# --- how far a sweep may turn (SPEC §13 amended) ------------------------------------------------

MAX_ADVANCES = 5_000  # conservative-advancement steps per side; beyond, the sweep stops there


class SweepBlocked(InputError):
    """A requested sweep that cannot turn at all at a pocket (bad input, SPEC §13 amended): the
    fork is already closer than ``clearance_min`` to an obstacle before it turns. ``slot``: the
    pocket; ``meets``: per side, the wrist angle (deg) at which a part would touch the obstacle
    turning that way, or None when it would not within the sweep; ``closest``: the nearest
    (distance, part, obstacle, slot) before the turn. Named by the key only ("sweep: …"): the
    callers that know the file and line the sweep came from name them
    (``cad.layout_files.setting_error``)."""

    def __init__(self, slot, clearance_min, closest, meets):
        self.slot = slot
        self.clearance_min = clearance_min
        self.closest = closest
        self.meets = meets
        distance, part, obstacle, _ = closest
        if distance < 0.0:  # already in it: the jab or the steps are contacts too
            near = f"{part} is inside {obstacle} by {-distance:.3f} mm"
        else:
            near = (f"{part} is {distance:.3f} mm from {obstacle}, under clearance_min "
                    f"{clearance_min:g} mm")
        touching = [f"{a:+.3f} deg" for a in meets if a]
        where = (f"; turning, the fork would touch at {' or '.join(touching)}" if touching
                 else "")
        super().__init__("sweep", None,
                         f"cannot turn at slot {slot}: before it turns, {near}{where}")


def reach_along(body, motion, clearance_min, tolerance=TOLERANCE, budget=MAX_ADVANCES):
    """How far the body can move along ``motion`` (from ``start`` towards ``end``) without
    coming closer than ``clearance_min`` to any obstacle: (the parameter reached, the body's
    ``nearest`` there), or (None, nearest at the start) when the start itself is closer.

    Conservative advancement: at s, with least distance d, no point moves further than
    ``path(s, s')`` before s', so every position in [s, s'] keeps at least d - path(s, s'); the
    step is the longest that keeps that at ``clearance_min`` + tolerance/2. Every position up to
    the one reached is therefore at least ``clearance_min`` away (nothing is sampled), and the
    motion stops within ``tolerance`` of the distance limit, at the end of the motion, or after
    ``budget`` steps (a tangential approach: the sweep then stops early, never late)."""
    s, end = motion.start, motion.end
    near = body.nearest(motion, s)
    if near[0] < clearance_min:
        return None, near
    wall = clearance_min + 0.5 * tolerance
    sign = 1.0 if end >= s else -1.0
    for _ in range(budget):
        margin = near[0] - wall
        if s == end or margin < 0.5 * tolerance:
            break
        step = abs(end - s)
        for _ in range(60):
            travel = body.path(motion, s, s + sign * step)
            if travel <= margin:
                break
            step *= min(0.5, margin / travel) if travel > 0.0 else 0.5
        else:
            break
        s = end if step >= abs(end - s) else s + sign * step
        near = body.nearest(motion, s)
    return s, near


def sweep_reach(body, slot, z, advance, amplitude, clearance_min, tolerance=TOLERANCE):
    """(low, high): the wrist angles (deg) a sweep at a pocket reaches turning each way from
    0 towards -amplitude and +amplitude, each stopped where the fork would come closer than
    ``clearance_min`` (``reach_along``). SweepBlocked when it cannot turn at all."""
    sides = [Motion(SWEEP, f"slot {slot} sweep", slot, 0.0, end, z, advance)
             for end in (-amplitude, amplitude)]
    reached = [reach_along(body, m, clearance_min, tolerance) for m in sides]
    if all(r is None for r, _ in reached):
        # Where a part would touch (distance 0) turning each way: 0 when it already does,
        # None when it would not within the sweep.
        meets = tuple(reach_along(body, m, 0.0, tolerance)[0] for m in sides)
        meets = tuple(0.0 if a is None else None if abs(a) >= amplitude else a for a in meets)
        raise SweepBlocked(slot, clearance_min, reached[0][1], meets)
    return tuple(0.0 if r is None else r for r, _ in reached)


def turn_limits(body, clearance_min, tolerance=TOLERANCE, seated=None):
    """``turn_limits(slot, z, depth, amplitude)`` for ``scan_layout``: each pocket's sweep
    stopped by ``body``'s clearance (``sweep_reach``). A pocket where it cannot turn at all is
    bad input (SweepBlocked) when the recipe is to blame: when the sweep could not turn with a
    wafer seated in the pocket either (``seated()``: the body with the carrier's slots holding
    seated wafers, made when first needed). Otherwise what is in the pocket stops it (a wafer
    pushed out or shifted: the jab's and the steps' contact says so): it turns (0, 0)."""
    nominal = []

    def limits(slot, z, depth, amplitude):
        try:
            return sweep_reach(body, slot, z, depth, amplitude, clearance_min, tolerance)
        except SweepBlocked as blocked:
            if seated is None:
                raise
            if not nominal:
                nominal.append(seated())
            try:
                sweep_reach(nominal[0], slot, z, depth, amplitude, clearance_min, tolerance)
            except SweepBlocked:
                raise blocked from None
            return (0.0, 0.0)

    return limits


def check_clearance(layout, body, pockets=None, clearance_min=None, body_name="robot",
                    carrier=CARRIER_NOT_CHECKED):
    """The ClearanceReport of a scan of ``layout`` made by ``body``: the least distance along
    each of its motions (``scan_motions``). ``clearance_min`` defaults to the layout's."""
    if clearance_min is None:
        clearance_min = layout.mapping.clearance_min
    closest = tuple(least_along(body, m, clearance_min) for m in scan_motions(layout, pockets))
    return ClearanceReport(clearance_min, closest, body_name, carrier, body)
