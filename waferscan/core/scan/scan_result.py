"""What a scan gives and the steps from an engine's hits to it: sensor runs as the MCS sees them
(latched), per-wafer intervals, the protrusion check, the warnings of SPEC §3 and the
``ScanResult``. ``core/scan/layout_scan.py`` (the ideal sensor) and ``core/scan/sensing.py`` (SPEC §10's real
sensor) both build their results from these, so neither imports the other's module."""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, fields
from itertools import compress, islice, repeat
from operator import attrgetter, gt, is_, itemgetter, le, lt

from ..geometry.beam import LEVEL, PRE_REJECT_SLACK, wafer_bounds
from ..geometry.ranges import translation_range
from ..mapping import LIMIT_SLACK, STATE_NAMES, UNSCANNED, SlotPlan
from ..model import DOWN, SLOW, UP, UPDOWN
from .engines import reachable_wafers


# The records a scan makes by the hundred (a run, a wafer's interval, mapping.SlotState) are
# logically immutable: nothing changes one after the scan. They are slotted dataclasses hashed
# by their fields (unsafe_hash) rather than frozen ones: a frozen dataclass sets each field
# through object.__setattr__ and keeps a dict per record, which made them a tenth of a fab's
# scan_layout.
@dataclass(slots=True, unsafe_hash=True)
class SensorRun:
    """A run of the sensor signal as latched: IN where the beam got blocked, OUT where it was
    last blocked, in the order of motion. ``wafers`` names the wafers that caused it (the
    simulator knows, a real sensor does not)."""

    z_in: float
    z_out: float
    wafers: tuple = ()
    # (bottom, top): the scan positions of its first and last blocked step before latching, in
    # ascending Z (what the geometry says; IN and OUT trail them by the latch lag).
    unlatched: tuple | None = None

    @property
    def diff(self):
        return abs(self.z_out - self.z_in)

    @property
    def bottom(self):
        return min(self.z_in, self.z_out)

    @property
    def top(self):
        return max(self.z_in, self.z_out)


@dataclass(slots=True, unsafe_hash=True)  # logically immutable (see SensorRun)
class WaferInterval:
    """First and last scan position (ascending Z, unlatched) at which the beam meets a wafer."""

    name: str
    z_in: float | None = None  # None, None: the scan never met the wafer
    z_out: float | None = None

    @property
    def diff(self):
        return None if self.z_in is None else self.z_out - self.z_in


@dataclass(frozen=True)
class ScanResult:
    layout: object
    engine: str
    plan: SlotPlan
    runs: tuple
    wafers: tuple
    slot_map: object
    protrusions: tuple  # (wafer name, protrusion in mm) for the scanned carrier's wafers
    warnings: tuple = ()  # why some of what is reported cannot be known (SPEC §3), as sentences
    # SPEC §10, a real sensor's scan only (core/scan/sensing.py): every latched ON/OFF edge in the
    # order latched, and the blocked fraction along the scan (a SignalTrace).
    edges: tuple = ()
    signal: object = None
    # SPEC §13, a slow scan with a jab or a sweep: each scanned pocket's PocketProbe
    # (core/scan/slow_scan.py), in slot order; empty otherwise.
    pockets: tuple = ()
    # The ScanParameters as asked, when the scan ran with others (``layout.scan``): latching in
    # motion has continuous edges, so it scans with z_step 0 whatever z_step asked (SPEC §10).
    # None: the scan used what was asked.
    asked_scan: object = None
    # SPEC §15: the ClearanceReport of the scan's motions (core/scan/clearance.py), when checked.
    clearance: object = None

    @property
    def durations(self):
        """Simulated seconds of a fast and of a slow scan of this layout (SPEC §13)."""
        from . import slow_scan

        # A fast scan's result says what a slow one with its jab and sweep would take.
        pockets = self.pockets or slow_scan.nominal_probes(
            self.layout.scan, self.plan, [s.slot for s in self.slot_map.slots
                                          if s.state != UNSCANNED])
        return {"fast": slow_scan.fast_duration(self.layout.scan),
                "slow": slow_scan.slow_duration(self.layout.scan, self.plan, pockets)}

    @property
    def code(self):
        return self.slot_map.code

    @property
    def e87(self):
        return self.slot_map.e87

    def table_rows(self):
        """Rows like the paper's Table 1: (slot, seat_z, wafers, z_in, z_out, diff, state).
        A run is listed at the lowest slot it speaks for; an empty slot gets one blank row."""
        listed = set()
        rows = []
        for slot in self.slot_map.slots:
            own = [i for i in slot.runs if i not in listed]
            listed.update(own)
            state = STATE_NAMES[slot.state]
            if not own:
                rows.append((slot.slot, slot.seat_z, (), None, None, None, state))
            for i in own:
                run = self.runs[i]
                rows.append((slot.slot, slot.seat_z, run.wafers, run.z_in, run.z_out, run.diff,
                             state))
        return rows


# SlotPlan's fields after its first seven (the carrier's and SPEC §4's tolerances) are the
# recipe's keys (SPEC §11, recipe.RECIPE_KEYS: tests/core/test_fab_shared_pass.py), read off the
# layout's mapping by these names at once and given in this order.
_recipe_values = attrgetter(*[f.name for f in fields(SlotPlan)][7:])


def slot_plan(carrier, mapping):
    """The nominal slots of a carrier with the layout's mapping tolerances and recipe (SPEC
    §11): the fields given in their order, the recipe's as ``recipe_fields(mapping)`` names
    them (its dict and a call by keywords cost nearly as much as the plan itself)."""
    return SlotPlan(carrier.slot_count, carrier.pitch, carrier.first_slot_z,
                    carrier.wafer_thickness,
                    mapping.thickness_tolerance_for(carrier.wafer_thickness),
                    mapping.position_tolerance, mapping.protrusion_limit,
                    *_recipe_values(mapping))


def pocket_window(plan):
    return (plan.seat_z(1) - 0.5 * plan.pitch, plan.seat_z(plan.slot_count) + 0.5 * plan.pitch)


def stepped_intervals(hits, scan, window):
    """Step intervals as (bottom, top) scan positions, clipped to the steps inside ``window``."""
    if window is None:
        k_lo, k_hi = 0, hits.count - 1
    else:
        k_lo = max(0, math.ceil((window[0] - scan.start_z) / scan.z_step))
        k_hi = min(hits.count - 1, math.floor((window[1] - scan.start_z) / scan.z_step))

    start, step = scan.start_z, scan.z_step
    if window is None:
        # Every step interval an engine gives lies in 0 .. count - 1 already: clipped to that,
        # each is itself (span's max and min choose its own ends), as scan positions.
        return ([(start + first * step, start + last * step) for first, last in hits.runs],
                [None if w is None else (start + w[0] * step, start + w[1] * step)
                 for w in hits.wafer_steps])

    def span(interval):
        """The interval clipped to [k_lo, k_hi], as scan positions (``scan.position``'s
        arithmetic, written out: this runs for every wafer); None when outside."""
        first, last = interval
        if last < k_lo or first > k_hi:
            return None
        return (start + (k_lo if k_lo > first else first) * step,  # max(first, k_lo)
                start + (k_hi if k_hi < last else last) * step)  # min(last, k_hi)

    runs = [span(r) for r in hits.runs]
    return ([r for r in runs if r is not None],
            [None if w is None else span(w) for w in hits.wafer_steps])


_name = attrgetter("name")


def stepped_records(hits, scan, wafers):
    """What a stepped scan without a window (fast mode) makes of an engine's ``StepHits``: the
    run spans as ``stepped_intervals(hits, scan, None)`` gives them, each wafer's
    ``WaferInterval`` (``wafer_records`` of its wafer spans) and each run's wafers as
    ``run_wafers`` names them. The records in one comprehension, then the names from the
    records of the wafers the scan met alone (``compress`` leaves out, without a step of Python
    each, the wafers whose steps are None: most of a fab's, in other carriers); three passes
    over a fab's 100 wafers were a sixth of its scan_layout. The same values
    (tests/core/test_fab_floor.py checks them against the three, tests/core/test_fab_fast_paths.py
    the whole scan). The wafer spans themselves are not made: a wafer's is None where its
    steps (``hits.wafer_steps``) are.

    Where each run is one met wafer's steps, in the layout's order (a fab's level wafers, each
    seated apart from the next), and the spans are in order along Z (each run's bottom <= its
    top < the next run's bottom: rounding keeps them so, unless a step is lost to it), each run
    names its own wafer alone, without the bisections: the wafer's span is the run's (the same
    steps, the same sums), which meets no other run (tests/core/test_fab_shared_pass.py)."""
    return _stepped_records(hits, scan, wafers)[:3]


def _stepped_records(hits, scan, wafers):
    """``stepped_records``, and the runs' bottoms and tops as lists (each run's (z_in, z_out)
    in an up stroke without a latch lag: ``SensorRun``s made from them at once)."""
    start, step = scan.start_z, scan.z_step
    runs = hits.runs
    run_spans = [(start + first * step, start + last * step) for first, last in runs]
    bottoms = [bottom for bottom, _ in run_spans]
    tops = [top for _, top in run_spans]
    steps = hits.wafer_steps
    interval = WaferInterval
    records = tuple([interval(wafer.name) if k is None else
                     interval(wafer.name, start + k[0] * step, start + k[1] * step)
                     for wafer, k in zip(wafers, steps)])
    # (A stepper's runs as a tuple and its steps one per wafer, as StepHits says: else, as
    # before, the bisections; a second reader's catch.)
    if type(runs) is tuple and len(steps) == len(wafers) and \
            tuple(compress(steps, steps)) == runs and all(map(le, bottoms, tops)) and \
            all(map(lt, tops, islice(bottoms, 1, None))):  # tops[j] < bottoms[j + 1]
        # (zip of one iterable: each name in a tuple of its own)
        return run_spans, records, list(zip(map(_name, compress(wafers, steps)))), bottoms, tops
    if bottoms != sorted(bottoms):  # not as an engine gives them: run_wafers reorders them
        _, wafer_spans = stepped_intervals(hits, scan, None)
        return (run_spans, records, run_wafers(run_spans, wafers, wafer_spans), bottoms,
                tops)
    names = [[] for _ in run_spans]
    for record in compress(records, steps):  # the records whose steps are not None
        # run_wafers: the runs with top >= z_in and bottom <= z_out (bisect_right from the
        # first of them on: the same end where there is one, an empty range where none)
        first = bisect_left(tops, record.z_in)
        for j in range(first, bisect_right(bottoms, record.z_out, first)):
            names[j].append(record.name)
    return run_spans, records, [tuple(n) for n in names], bottoms, tops


def wafer_records(wafers, wafer_spans):
    """Each wafer's ``WaferInterval`` from its span (bottom, top), or None where the scan never
    met it."""
    return tuple([WaferInterval(w.name, None, None) if span is None else
                  WaferInterval(w.name, span[0], span[1])
                  for w, span in zip(wafers, wafer_spans)])


def exact_intervals(hits, window):
    def clip(interval):
        if interval is None:
            return None
        if window is None:
            return interval
        if interval[1] < window[0] or interval[0] > window[1]:
            return None
        return (max(interval[0], window[0]), min(interval[1], window[1]))

    runs = [clip(r) for r in hits.runs]
    return [r for r in runs if r is not None], [clip(w) for w in hits.wafer_edges]


def latch(bottom, top, scan):
    """(IN, OUT) of a run as the sensor latches it in the scan's direction of motion."""
    return latcher(scan)(bottom, top)


def latcher(scan):
    """``latch`` for one scan, as a function of (bottom, top): the lag and the direction read
    once for all of a scan's runs."""
    lag = scan.latch_lag
    if scan.mode == SLOW or scan.direction == UP:
        return lambda bottom, top: (bottom + lag, top + lag)
    if scan.direction == DOWN:
        return lambda bottom, top: (top - lag, bottom - lag)
    assert scan.direction == UPDOWN
    # Up stroke latches bottom + lag, down stroke bottom - lag: the mean cancels the lag.
    return lambda bottom, top: (0.5 * ((bottom + lag) + (bottom - lag)),
                                0.5 * ((top + lag) + (top - lag)))


def latch_runs(bottom, top, scan, lag=None):
    """``latcher`` over arrays (numpy): the (bottom, top) of runs as latched and then ordered,
    as ``SensorRun`` orders them. ``lag``: the scan's own (``latch_lag``) when None, else an
    array that broadcasts (a sweep's lag per layout, 0 in a slow scan)."""
    if lag is None:
        lag = scan.latch_lag
    if scan.mode == SLOW or scan.direction == UP:
        return bottom + lag, top + lag
    if scan.direction == DOWN:
        return bottom - lag, top - lag
    assert scan.direction == UPDOWN
    return 0.5 * ((bottom + lag) + (bottom - lag)), 0.5 * ((top + lag) + (top - lag))


def protrusion(carrier, wafer):
    """How far (mm) the wafer reaches out of the carrier's opening beyond a seated wafer: the
    solid's frontmost point along the carrier's ``front``, less a seated wafer's (its centre on
    the carrier's, D/2 out). A load port's protrusion sensor sees the solid, so a wafer tilted
    towards the front reaches t·sin(tilt) further at its top rim than at its bottom one, and
    (t/2)·sin(tilt) further than its mid-plane (issue 24)."""
    fx, fy = carrier.front
    nx, ny, _ = wafer.normal
    along = nx * fx + ny * fy
    reach = (wafer.center[0] - carrier.center[0]) * fx + (wafer.center[1] - carrier.center[1]) * fy
    reach += front_reach(wafer.radius, wafer.thickness, wafer.bow, along)
    return reach - 0.5 * carrier.wafer_diameter


def front_reach(radius, thickness, bow, along):
    """How far (mm) a wafer's solid reaches along a horizontal direction f beyond its frame's
    origin (the centre of its rim's bottom circle), ``along`` = n·f (the sine of its tilt towards
    f). A point of the solid is origin + r u + (w(r) + s) n, u a unit vector in its plane, r <= R,
    0 <= s <= t, w(r) = bow (1 − r²/R²) (0 for a flat wafer): along f it reaches
    r·sqrt(1 − along²) + (w(r) + s)·along, largest at s = t when along > 0 (else s = 0) and, over
    r, at the rim (w(R) = 0) unless bow·along > 0 puts the parabola's vertex inside it (a tilt
    beyond atan(R / (2 bow)): 89.96° for a 300 mm wafer bowed 0.1 mm)."""
    across = 1.0 - along * along
    c = math.sqrt(across) if across > 0.0 else 0.0  # NaN and -0.0 give 0.0 too
    reach = radius * c
    if bow * along > 0.0:
        curve = bow * along
        vertex = c * radius * radius / (2.0 * curve)
        if vertex < radius:
            reach = vertex * c + curve * (1.0 - vertex * vertex / (radius * radius))
    if along > 0.0:
        reach += thickness * along
    return reach


def front_reaches(radius, thickness, bow, along):
    """``front_reach`` over arrays (numpy) of wafers, the same floats."""
    import numpy as np

    across = np.sqrt(np.maximum(0.0, 1.0 - along * along))
    reach = radius * across
    curve = bow * along
    if (curve > 0.0).any():
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = across * radius * radius / (2.0 * curve)
            inner = vertex * across + curve * (1.0 - vertex * vertex / (radius * radius))
        reach = np.where((curve > 0.0) & (vertex < radius), inner, reach)
    return reach + np.maximum(0.0, thickness * along)


def carrier_wafers(carrier, wafers):
    """The wafers inside the carrier's footprint and slot range."""
    return (wafer for wafer, _ in carrier_protrusions(carrier, wafers))


def carrier_circle(carrier):
    """``carrier_protrusions``' test of a level wafer in X and Y for one carrier, with the
    carrier's values read once: (amount, z_lo, z_hi), ``amount(cx, cy, diameter)`` the
    protrusion of a level wafer centred at (cx, cy) when it lies inside the carrier's circle,
    else None; such a wafer is the carrier's when its mid-plane's height lies in [z_lo, z_hi].
    (The analytic engine's pass over the wafers asks it too: ``engines.analytic_stepped``.)"""
    r = 0.5 * carrier.wafer_diameter
    ox, oy = carrier.center
    fx, fy = carrier.front
    hypot = math.hypot
    wide = r + PRE_REJECT_SLACK  # a level wafer further off in X or Y alone is outside

    def amount(cx, cy, diameter):
        # A level wafer of another carrier, left out by X or Y alone (most of a fab's)
        if cx - ox > wide or ox - cx > wide or cy - oy > wide or oy - cy > wide:
            return None
        dx, dy = cx - ox, cy - oy
        if not hypot(dx, dy) < r:
            return None
        # front_reach of a level wafer: R·sqrt(1 - 0²) = R, nothing from its thickness
        return dx * fx + dy * fy + diameter / 2.0 - r

    return (amount, carrier.seat_z(1) - carrier.pitch,
            carrier.seat_z(carrier.slot_count) + carrier.pitch)


def carrier_protrusions(carrier, wafers):
    """[(wafer, ``protrusion(carrier, wafer)``)] for each wafer inside the carrier's footprint and
    slot range: one pass with the carrier's values read once, as this runs for every wafer of a
    fab at every scan. Which wafers are the carrier's is judged by ``wafer.mid_center``; it and
    ``protrusion``'s sums are written out term for term (the same floats;
    tests/core/test_fixed_cost.py), without a level wafer's zero terms (``carrier_circle``);
    a level wafer further from the carrier's centre in X or Y alone than the circle is left out
    first (most of a fab's wafers lie in other carriers), and one that shares its X, Y and
    diameter with the level wafer before takes that one's answer in XY
    (tests/core/test_fab_fast_paths.py, on stacks that share them)."""
    r = 0.5 * carrier.wafer_diameter
    level_amount, z_lo, z_hi = carrier_circle(carrier)
    ox, oy = carrier.center
    fx, fy = carrier.front
    hypot = math.hypot
    found = []
    # The last level wafer's normal, centre X and Y and diameter (the objects) and what its XY
    # said (``amount``: its protrusion when inside the circle, else None), which depends on
    # these alone: the next wafer with the same objects (a carrier's seated wafers), so the
    # same numbers bit for bit, takes it without the arithmetic (as accessible_wafers does).
    same_normal = same_x = same_y = same_diameter = None
    amount = None
    for wafer in wafers:
        (cx, cy, cz), normal, diameter = wafer.center, wafer.normal, wafer.diameter
        if normal is same_normal and cx is same_x and cy is same_y and diameter is same_diameter:
            if amount is None:
                continue
        elif normal == LEVEL:
            same_normal, same_x, same_y, same_diameter = normal, cx, cy, diameter
            amount = level_amount(cx, cy, diameter)
            if amount is None:
                continue
        else:
            h = wafer.thickness / 2.0
            nx, ny, nz = normal
            mz = cz + h * nz
            if not z_lo <= mz <= z_hi:
                continue
            mx, my = cx + h * nx, cy + h * ny
            if hypot(mx - ox, my - oy) < r:
                # ``protrusion``'s sums: the solid's frontmost point, from the bottom centre
                reach = (cx - ox) * fx + (cy - oy) * fy
                reach += front_reach(diameter / 2.0, wafer.thickness, wafer.bow,
                                     nx * fx + ny * fy)
                found.append((wafer, reach - r))
            continue
        # A level wafer inside the circle: Z. n = (0, 0, 1): cz + h * 1 = cz + h, cx + h * 0
        # = cx (but for a -0.0, which no distance or sum above tells from 0.0)
        mz = cz + wafer.thickness / 2.0
        if z_lo <= mz <= z_hi:
            found.append((wafer, amount))
    return found


_second = itemgetter(1)


def protruding_slots(carrier, plan, wafers, inside=None):
    """Slots holding a wafer that sticks out beyond the protrusion limit, and every such wafer's
    protrusion. Models a load port's protrusion sensor across the carrier's opening: it sees the
    front edge alone, so a wafer is flagged however it is seated (SPEC §4). The slot it occupies
    is the one whose seat is nearest its bottom edge, and every slot whose seat its Z extent
    spans (a tilted, cross-slotted wafer occupies both of its slots). ``inside``: the
    carrier's ``carrier_protrusions(carrier, wafers)`` when found already (None: found here)."""
    by_slot, found = protrusions_by_slot(carrier, plan, wafers, inside)
    return sorted(by_slot), found


def protruding_mask(carrier, plan, exists, center, normal, thickness, bow):
    """``protruding_slots`` over arrays (numpy), for m layouts of W wafers each: ``exists``
    (m, W), ``center`` and ``normal`` (m, W, 3), ``thickness`` and ``bow`` (m, W). Returns an
    (m, S) mask, True where the load port's protrusion check flags the slot; the same slots as
    ``protruding_slots`` layout by layout (``protruding_rows`` over the wafers that exist)."""
    import numpy as np

    li, wi = np.nonzero(exists)
    return protruding_rows(carrier, plan, exists.shape[0], li, center[li, wi], normal[li, wi],
                           thickness[li, wi], bow[li, wi])


def protruding_rows(carrier, plan, m, owner, center, normal, thickness, bow):
    """``protruding_mask`` of m layouts from their wafers alone (a sweep's scan has them
    gathered already): ``owner`` (n,) the index of each one's layout, ``center`` and ``normal``
    (n, 3), ``thickness`` and ``bow`` (n,). Each wafer's sums are its own, so the same floats as
    over every place of every layout; the places that hold no wafer are not worked out at all."""
    import numpy as np

    S = plan.slot_count
    out = np.zeros((m, S), dtype=bool)
    c, n, t = center, normal, thickness
    h = t / 2.0
    mx, my, mz = c[:, 0] + h * n[:, 0], c[:, 1] + h * n[:, 1], c[:, 2] + h * n[:, 2]
    r = 0.5 * carrier.wafer_diameter
    z_lo = carrier.seat_z(1) - carrier.pitch
    z_hi = carrier.seat_z(carrier.slot_count) + carrier.pitch
    inside = (np.hypot(mx - carrier.center[0], my - carrier.center[1]) < r) \
        & (z_lo <= mz) & (mz <= z_hi)
    fx, fy = carrier.front
    along = n[:, 0] * fx + n[:, 1] * fy
    # protrusion's sums: the solid's frontmost point, from the bottom centre
    reach = (c[:, 0] - carrier.center[0]) * fx + (c[:, 1] - carrier.center[1]) * fy
    reach = reach + front_reaches(r, t, bow, along)
    flagged = inside & (reach - r > plan.protrusion_limit)
    for j in np.flatnonzero(flagged):
        # protrusions_by_slot: the nearest slot to its bottom and every seat its Z extent spans
        i = owner[j]
        nz = float(n[j, 2])
        half = r * math.sqrt(max(0.0, 1.0 - nz * nz)) + (0.5 * float(t[j])
                                                          + abs(float(bow[j]))) * abs(nz)
        z0, z1 = float(mz[j]) - half, float(mz[j]) + half
        out[i, plan.nearest_slot(z0) - 1] = True
        for slot in range(1, S + 1):
            if z0 <= plan.seat_z(slot) <= z1:
                out[i, slot - 1] = True
    return out


def protrusions_by_slot(carrier, plan, wafers, inside=None):
    """({slot: [(wafer name, protrusion mm), …]} for the slots ``protruding_slots`` flags, and
    every carrier wafer's (name, protrusion)): which wafers make a slot protrude, and by how
    much, for the words of a finding. ``inside``: as ``protruding_slots`` takes it."""
    by_slot = {}
    limit = plan.protrusion_limit
    if inside is None:
        inside = carrier_protrusions(carrier, wafers)
    found = tuple([(wafer.name, amount) for wafer, amount in inside])
    # those with amount > limit (compress: the others without a step of Python each)
    for wafer, amount in compress(inside, map(gt, map(_second, inside), repeat(limit))):
        (_, _, z0), (_, _, z1) = wafer_bounds(wafer)
        slots = {plan.nearest_slot(z0)}
        for slot in range(1, plan.slot_count + 1):
            if z0 <= plan.seat_z(slot) <= z1:
                slots.add(slot)
        for slot in slots:
            by_slot.setdefault(slot, []).append((wafer.name, amount))
    return by_slot, found


def scanned_range(scan, window=None):
    """(low, high) scan Z (mm) the beam was read over: the stepped positions from start_z to the
    last one on the grid (z_step = 0: start_z to final_z), within ``window`` when the scan keeps
    to one (slow mode); None when no position lies in it."""
    if scan.exact:
        low, high = scan.start_z, scan.final_z
        if window is not None:
            low, high = max(low, window[0]), min(high, window[1])
        return (low, high) if low <= high else None
    k_lo, k_hi = 0, scan.last_step
    if window is not None:
        k_lo = max(k_lo, math.ceil((window[0] - scan.start_z) / scan.z_step))
        k_hi = min(k_hi, math.floor((window[1] - scan.start_z) / scan.z_step))
    return (scan.position(k_lo), scan.position(k_hi)) if k_lo <= k_hi else None


_thickness = attrgetter("thickness")
_carrier = attrgetter("carrier")


def scan_warnings(layout, plan, run_spans, scanned, unscanned, visited):
    """Why parts of a scan's result cannot be known (SPEC §3 "Honest results"), one sentence
    each: a step coarser than half the thinnest wafer, slots whose window the scan did not
    wholly cover (``scanned``: start_z to final_z), runs cut off by an end of the range the beam
    was read over (``visited``: the first and last stepped positions; in slow mode, within the
    carrier's pockets)."""
    scan = layout.scan
    warnings = []
    coarse = not scan.exact and scan.z_step > 0.5 * min(
        plan.wafer_thickness, min(map(_thickness, layout.wafers), default=math.inf)) + LIMIT_SLACK
    if coarse:
        # Only the wafers the beam can reach count (the accessibility check, run only here).
        reachable = reachable_wafers(layout)
        thinnest = min([plan.wafer_thickness] + [layout.wafers[i].thickness for i in reachable])
        if scan.z_step > 0.5 * thinnest + LIMIT_SLACK:
            warnings.append(f"z_step {scan.z_step:g} mm is coarser than half the thinnest wafer "
                            f"({thinnest:g} mm): a wafer can be missed, or measured thin, thick "
                            f"or off its seat")
    if unscanned:
        where = "nothing" if scanned is None else f"{scanned[0]:.3f} to {scanned[1]:.3f} mm"
        slots = ", ".join(str(s) for s in unscanned)
        warnings.append(f"slot{'s' if len(unscanned) > 1 else ''} {slots} of {plan.slot_count} "
                        f"not wholly inside the scanned range ({where}): reported unscanned (?)")
    if visited is not None:
        first, last = visited[0] + LIMIT_SLACK, visited[1] - LIMIT_SLACK
        for bottom, top in run_spans:
            if first < bottom and top < last:
                continue  # inside the range, as most runs are: nothing to say
            ends = [name for name, cut in (("start", bottom <= first), ("end", top >= last))
                    if cut]
            if ends:
                warnings.append(f"the sensor run from {bottom:.3f} to {top:.3f} mm is cut off by "
                                f"the {' and the '.join(ends)} of the scanned range: its length "
                                f"and position are not known")
    return tuple(warnings)


def beam_miss(beam, axis, wafer):
    """How far (mm) the beam passes beside ``wafer`` at every lift: seen along the lift ``axis``
    (a unit vector), the distance from the beam's segment to the wafer's outline, 0 when they
    overlap. Exact for a level wafer (its disc seen from above); for a tilted one, its outline
    towards the beam (the cylinder's reach in that direction)."""
    ax, ay, az = axis

    def flat(point):  # the point seen along the axis: its part across it
        d = point[0] * ax + point[1] * ay + point[2] * az
        return (point[0] - d * ax, point[1] - d * ay, point[2] - d * az)

    start = flat(beam.emitter)
    end = flat(tuple(e + beam.length * v for e, v in zip(beam.emitter, beam.direction)))
    centre = flat(wafer.mid_center)
    along = tuple(b - a for a, b in zip(start, end))
    length2 = sum(v * v for v in along)
    share = 0.0 if length2 == 0.0 else max(0.0, min(1.0, sum(
        (c - a) * v for c, a, v in zip(centre, start, along)) / length2))
    gap = tuple(c - a - share * v for c, a, v in zip(centre, start, along))
    distance = math.sqrt(sum(v * v for v in gap))
    if distance == 0.0:
        return 0.0
    tilt = abs(sum(g * n for g, n in zip(gap, wafer.normal))) / distance
    reach = wafer.radius * math.sqrt(max(0.0, 1.0 - tilt * tilt)) + 0.5 * wafer.thickness * tilt
    return max(0.0, distance - reach)


SHOWN_NAMES = 3  # wafers named in a warning; the others counted
BEAM_MISSES = "the beam misses "  # how missed_by_beam's warning starts (the GUI shows it at once)


def missed_by_beam(layout, beam, wafer_spans):
    """SPEC §3, a fast scan: the scanned carrier's wafers (and the free ones) that ``beam``,
    lifted along the layout's lift axis, crosses at no height at all: one warning naming how many
    and by how much the beam passes beside them (a beam set beside the wafers maps every slot
    empty, silently else). ``wafer_spans``: each wafer's scanned span, None where the scan never met it (the
    only ones looked at again, with the closed form). Returns a tuple of at most one sentence."""
    if layout.scan.mode == SLOW:
        # A slow scan's arm may wait in front of the pockets and reach in pocket by pocket
        # (SPEC §13): its beam at rest beside the wafers is how it is meant.
        return ()
    carrier = layout.scanned_carrier.name
    mine = (None, carrier)
    # The wafers the scan never met (compress: those whose span is None), and whether any is
    # the scanned carrier's or a free one: by their carriers' names, without a step of Python
    # a wafer (in a fab, the other carriers' wafers are most and all unmet)
    unmet = compress(layout.wafers, map(is_, wafer_spans, repeat(None)))
    unmet_carriers = set(map(_carrier, unmet))
    if carrier not in unmet_carriers and None not in unmet_carriers:
        return ()
    # those, in the layout's order
    unmet = [wafer for wafer, span in zip(layout.wafers, wafer_spans)
             if span is None and wafer.carrier in mine]
    missed = [(wafer.name, beam_miss(beam, layout.lift_axis, wafer)) for wafer in unmet
              if translation_range(beam.emitter, beam, layout.lift_axis, wafer) is None]
    if not missed:
        return ()
    names = ", ".join(name for name, _ in missed[:SHOWN_NAMES])
    if len(missed) > SHOWN_NAMES:
        names += f" and {len(missed) - SHOWN_NAMES} more"
    low, high = min(m for _, m in missed), max(m for _, m in missed)
    by = f"{low:.3f} mm" if high - low < 5e-4 else f"{low:.3f} to {high:.3f} mm"
    mine = sum(1 for w in layout.wafers if w.carrier in (None, carrier))
    count = f"{len(missed)} of the {mine} wafers"
    return (f"{BEAM_MISSES}{count} at every height ({names}), passing {by} beside "
            f"{'it' if len(missed) == 1 else 'them'}: their slots read empty; check where the "
            "scanner's emitter and receiver are",)


def run_wafers(run_spans, wafers, wafer_spans):
    """For each run (bottom, top), the names of the wafers whose span overlaps it, in the
    layout's order. The runs are disjoint, so sorted by bottom their tops ascend too: each
    wafer finds its runs by bisection, O((runs + wafers) log runs) where a search of every
    wafer for every run was O(runs x wafers) (10,000 wafers: seconds)."""
    bottoms = [bottom for bottom, _ in run_spans]
    if bottoms == sorted(bottoms):  # as an engine gives them: no reordering
        order = range(len(run_spans))
        tops = [top for _, top in run_spans]
    else:
        order = sorted(range(len(run_spans)), key=lambda i: run_spans[i][0])
        bottoms = [run_spans[i][0] for i in order]
        tops = [run_spans[i][1] for i in order]
    names = [[] for _ in run_spans]
    for wafer, span in zip(wafers, wafer_spans):
        if span is None:
            continue
        # Runs with top >= span's low end and bottom <= its high end.
        for j in range(bisect_left(tops, span[0]), bisect_right(bottoms, span[1])):
            names[order[j]].append(wafer.name)
    return [tuple(n) for n in names]


