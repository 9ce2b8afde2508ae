"""Scan engines: which stepped positions the beam is blocked at, and by which wafer.

Every engine answers the same question on the same grid z_k = start_z + k*z_step, k = 0..K, and
returns a ``StepHits``: for each wafer the first and last step at which the beam meets it, and
the sensor runs (maximal sequences of blocked steps). ``loop``, ``vector`` and ``analytic`` use
the exact test and must agree exactly; ``paper`` uses the paper's mid-plane test.

The engines of the CAD layer (``document``, ``brep``) register themselves in ``ENGINES`` too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..geometry.beam import (
    LEVEL,
    TOUCH_TOLERANCE,
    accessible,
    accessible_wafers,
    beam_hits_wafer,
    beam_hits_wafers,
    level_near,
    paper_beam_hits_wafer,
    sweep_reach,
    wafer_columns,
)
from ..geometry.ranges import translation_range
from ..rules import check_stepped


@dataclass(frozen=True)
class StepHits:
    """Stepped outcome of a scan. Step indices k refer to ``ScanParameters.position(k)``."""

    count: int  # number of stepped positions, K + 1
    wafer_steps: tuple  # per wafer of the layout: (k_first, k_last) or None
    runs: tuple  # sensor runs: (k_first, k_last), ascending, disjoint, not adjacent


@dataclass(frozen=True)
class ExactHits:
    """Continuous outcome (z_step = 0): edges in scan position z, clipped to [start_z, final_z]."""

    wafer_edges: tuple  # per wafer: (z_first, z_last) or None
    runs: tuple  # (z_first, z_last), ascending, disjoint


def runs_from_blocked(blocked):
    """Maximal runs of True in a boolean sequence, as (first, last) index pairs."""
    import numpy as np  # numpy (~70 ms to import) only where arrays are used: see analytic_engine

    blocked = np.asarray(blocked, dtype=bool)
    if blocked.size == 0:
        return ()
    padded = np.concatenate(([False], blocked, [False]))
    change = np.flatnonzero(padded[1:] != padded[:-1])
    return tuple((int(a), int(b) - 1) for a, b in zip(change[::2], change[1::2]))


def runs_from_intervals(intervals):
    """Union of closed step intervals as runs; intervals that touch or are adjacent merge."""
    return _merged_runs([i for i in intervals if i is not None])


def _merged_runs(present):
    """``runs_from_intervals`` of a list of intervals none of which is None (sorted in place)."""
    if not present:
        return ()
    present.sort()
    runs = []
    run_first, run_last = present[0]
    for first, last in present:
        if first <= run_last + 1:  # (the first interval meets itself)
            if last > run_last:
                run_last = last
        else:
            runs.append((run_first, run_last))
            run_first, run_last = first, last
    runs.append((run_first, run_last))
    return tuple(runs)


def reachable_wafers(layout):
    """Indices of the wafers that pass the accessibility check over the whole scan."""
    scan = layout.scan
    return accessible_wafers(layout, layout.wafers, scan.start_z, scan.final_z)


def _stepped(layout):
    check_stepped(layout.scan)
    if layout.scan.final_z < layout.scan.start_z:
        raise ValueError("final_z is below start_z")


def _step_by_step(layout, test, progress=None):
    """The paper's procedure (its steps 4a and 4b): at each step, for each wafer of the layout,
    the accessibility check at that position, then, if it passed, the intersection test."""
    _stepped(layout)
    scan = layout.scan
    count = scan.position_count
    first = [None] * len(layout.wafers)
    last = [None] * len(layout.wafers)
    blocked = [False] * count
    for k in range(count):
        z = scan.position(k)
        emitter = layout.emitter_at(z)
        for i, wafer in enumerate(layout.wafers):
            if accessible(layout, wafer, z, z) and test(emitter, layout.beam, wafer):
                blocked[k] = True
                if first[i] is None:
                    first[i] = k
                last[i] = k
        if progress is not None and k % 1000 == 0:
            progress(k, count)
    steps = tuple(None if f is None else (f, l) for f, l in zip(first, last))
    return StepHits(count, steps, runs_from_blocked(blocked))


def loop_engine(layout, progress=None):
    """Reference engine: step by step, wafer by wafer, accessibility check first (the paper)."""
    return _step_by_step(layout, beam_hits_wafer, progress)


def paper_engine(layout, progress=None):
    """The paper's own mid-plane disc test (eqs. 1-5), stepped like ``loop``."""
    return _step_by_step(layout, paper_beam_hits_wafer, progress)


# Elements (steps x reachable wafers) per chunk of the vector engine. Each element takes about
# twenty float64 temporaries, so a chunk peaks near 16 MB: 2 million took 310 MB, and smaller
# chunks, kept in the processor's caches, are also faster (fab workload: 0.53 s against 1.3 s).
VECTOR_CHUNK_ELEMENTS = 100_000


def vector_engine(layout, progress=None, chunk_elements=VECTOR_CHUNK_ELEMENTS):
    """numpy over steps x wafers, in chunks of steps to bound memory (``chunk_elements``)."""
    import numpy as np

    _stepped(layout)
    scan = layout.scan
    reachable = reachable_wafers(layout)
    count = scan.position_count
    columns = [c[None, :] for c in wafer_columns([layout.wafers[i] for i in reachable])]
    bowed = [j for j, i in enumerate(reachable) if layout.wafers[i].bow]
    first = np.full(len(reachable), -1)
    last = np.full(len(reachable), -1)
    blocked = np.zeros(count, dtype=bool)
    chunk = max(1, chunk_elements // max(1, len(reachable)))
    for start in range(0, count if reachable else 0, chunk):
        ks = np.arange(start, min(count, start + chunk), dtype=float)
        z = scan.position(ks)
        ox, oy, oz = layout.emitter_at(z)
        hits = beam_hits_wafers(ox[:, None], oy[:, None], oz[:, None], layout.beam, *columns)
        for j in bowed:  # SPEC §10: a bowed wafer is no disc; the exact test, step by step
            wafer = layout.wafers[reachable[j]]
            hits[:, j] = [beam_hits_wafer((float(x), float(y), float(w)), layout.beam, wafer)
                          for x, y, w in zip(ox, oy, oz)]
        blocked[start:start + len(ks)] = hits.any(axis=1)
        any_hit = hits.any(axis=0)
        lo = start + np.argmax(hits, axis=0)
        hi = start + len(ks) - 1 - np.argmax(hits[::-1], axis=0)
        first = np.where(any_hit & (first < 0), lo, first)
        last = np.where(any_hit, hi, last)
        if progress is not None:
            progress(start + len(ks), count)
    steps = [None] * len(layout.wafers)
    for j, i in enumerate(reachable):
        if first[j] >= 0:
            steps[i] = (int(first[j]), int(last[j]))
    return StepHits(count, tuple(steps), runs_from_blocked(blocked))


def wafer_edges(layout, wafer, tol=TOUCH_TOLERANCE):
    """Exact first and last scan position z at which the beam meets the wafer (unclipped), or
    None. The set of such z is an interval: the wafer and the beam are convex. ``tol`` (mm)
    grows the wafer as the touching tolerance does; 0 gives the geometric edges."""
    ax, ay, az = layout.lift_axis
    span = translation_range(layout.beam.emitter, layout.beam, layout.lift_axis, wafer, tol)
    if span is None:
        return None
    z0 = layout.beam.emitter[2]
    return (z0 + span[0] * az, z0 + span[1] * az)


def level_edger(layout, tol=TOUCH_TOLERANCE):
    """``wafer_edges(layout, wafer, tol)`` for a level scan (lift along Z, beam level) and a flat
    level wafer (normal (0, 0, 1), no bow), as a function of the wafer: ``translation_range``'s
    level case (``_level_wafer_range``, ``rim_span``, ``rim_roots`` with floats) in one body,
    with the beam's values read once a scan. The same numbers bit for bit
    (tests/core/test_fixed_cost.py), without the five calls per wafer that were a third of an
    analytic scan of a fab's FOUP.

    With n = a = (0, 0, 1) and the beam's e_z = 0, the general sums reduce exactly (x * 0 = ±0,
    x ± 0 = x, x * 1 = x, x / 1 = x): w.n = w_z, e.n = 0, a.n = 1, p = (w_x, w_y, 0),
    q = (e_x, e_y, 0), so q.q depends on the beam alone; p.q keeps its trailing + 0.0 (p_z q_z),
    which turns a -0.0 into the 0.0 whose sign the root's copysign reads."""
    ox, oy, oz = layout.beam.emitter
    ex, ey, _ = layout.beam.direction
    length = layout.beam.length
    sqrt, copysign, inf = math.sqrt, math.copysign, math.inf
    qq = ex * ex + ey * ey  # (+ q_z q_z = + 0.0, which changes no sum of squares)
    past_end = length + tol

    def edges(wafer):
        cx, cy, cz = wafer.center
        wx, wy, wz = ox - cx, oy - cy, oz - cz
        r = wafer.diameter / 2.0 + tol
        c = wx * wx + wy * wy - r * r
        # _level_wafer_range, and rim_span in it
        if qq == 0.0:
            if c > 0.0:
                return None
            low, high = -inf, inf
        else:
            pq = wx * ex + wy * ey + 0.0
            disc = pq * pq - qq * c
            if disc < 0.0:
                return None
            root = -pq - copysign(sqrt(disc), pq)  # rim_roots
            r1 = root / qq
            r2 = c / root if root != 0.0 else 0.0
            low, high = (r1, r2) if r1 <= r2 else (r2, r1)  # min, max (finite: roots)
        if high < -tol or low > past_end:
            return None
        low, high = -tol - wz, wafer.thickness + tol - wz
        # min, max: a (validated, finite) thickness > -2 tol puts them in this order already
        return (oz + low, oz + high) if low <= high else (oz + high, oz + low)

    return edges


def geometric_edges(layout, wafer, touching):
    """The edges to report for a wafer the beam meets (``touching``: its edges with the touching
    tolerance): the solid's own, so that the tolerance does not leak into reported positions
    (an edge at 300.0 is 300.0, not 299.999999999). A beam that only grazes the wafer, where the
    geometric range is lost to rounding, touches it at the middle of the touching range."""
    exact = wafer_edges(layout, wafer, tol=0.0)
    if exact is None:
        middle = 0.5 * (touching[0] + touching[1])
        return (middle, middle)
    return exact


# How far a grid position must be from a level wafer's edge for ``settled_steps`` to place it
# without a test, relative to the size of the coordinates: the edges and the loop engine's test
# are exact to a few units of the last place (~1e-16 relative), this is a thousand times more,
# and below the touch tolerance (1e-9 mm) at the coordinates of a fab (< 1 m), so that a seat
# on the grid is settled too.
SETTLED_MARGIN = 1e-12


def is_level(layout, wafer):
    """The common case of ``translation_range``: a wafer lying flat, lifted along its axis (Z),
    the beam along its faces. Its edges are its faces' heights (widened by the touch tolerance)
    to rounding, and the beam meets it at every position between them."""
    return (wafer.normal == (0.0, 0.0, 1.0) and layout.lift_axis == (0.0, 0.0, 1.0)
            and layout.beam.direction[2] == 0.0)


def settled_steps(layout, edges):
    """The stepped interval of a level wafer when no grid position lies near either edge (within
    SETTLED_MARGIN of the coordinates' size): then every position is on the side of the edges
    that it is by more than any rounding, and the ``loop`` engine's test would find just that.
    None when not so (the positions next to the edges are then tested)."""
    return settler(layout)(edges)


def settler(layout):
    """``settled_steps`` for one layout, as a function of the edges: what depends on the scan
    alone (its size, its last step) worked out once a scan instead of once a wafer. The same
    values: max over floats and the comparisons are exact, whatever their grouping."""
    return _settler(_settling(layout))


def _settler(settling):
    """``settler`` from ``_settling``'s values."""
    start, step, last_k, scan_size, scan_margin = settling
    ceil, floor = math.ceil, math.floor

    def settled(edges):
        e0, e1 = edges
        # max(scan_size, |e0|, |e1|) as comparisons (max's own: a later value replaces the
        # largest so far only when greater), and the margin of that size
        a, b = abs(e0), abs(e1)
        if a > scan_size or b > scan_size:
            size = a if a > scan_size else scan_size
            if b > size:
                size = b
            margin = SETTLED_MARGIN * size / step
        else:
            margin = scan_margin
        x0 = (e0 - start) / step
        x1 = (e1 - start) / step
        lo, hi = ceil(x0), floor(x1)
        # min(lo - x0, x0 - lo + 1, x1 - hi, hi + 1 - x1) <= margin, term by term
        if lo - x0 <= margin or x0 - lo + 1 <= margin or x1 - hi <= margin or hi + 1 - x1 <= margin:
            return None
        if lo < 0:  # max(0, lo), min(last_k, hi) of ints
            lo = 0
        if hi > last_k:
            hi = last_k
        return (lo, hi) if lo <= hi else None

    return settled


def _settling(layout):
    """What ``settler`` reads of the scan once: (start_z, z_step, last step, the scan's size,
    the margin of edges inside that size)."""
    scan = layout.scan
    scan_size = max(1.0, abs(scan.start_z), abs(scan.final_z), abs(layout.beam.emitter[2]))
    return (scan.start_z, scan.z_step, scan.last_step, scan_size,
            SETTLED_MARGIN * scan_size / scan.z_step)


def snap_to_grid(layout, wafer, edges):
    """The stepped interval of one wafer from its exact edges. The closed-form edges are exact
    to rounding; the grid steps next to each edge are then settled with the very test the
    ``loop`` engine uses, so that both engines agree bit for bit."""
    scan = layout.scan
    last_k = scan.last_step

    def hit(k):
        return beam_hits_wafer(layout.emitter_at(scan.position(k)), layout.beam, wafer)

    lo = max(0, math.ceil((edges[0] - scan.start_z) / scan.z_step))
    hi = min(last_k, math.floor((edges[1] - scan.start_z) / scan.z_step))
    if lo > hi:
        # Thinner than a step or off the grid: at most the steps around the edges can hit.
        near = [k for k in range(max(0, hi - 1), min(last_k, lo + 1) + 1) if hit(k)]
        return (near[0], near[-1]) if near else None
    while lo > 0 and hit(lo - 1):
        lo -= 1
    while lo <= hi and not hit(lo):
        lo += 1
    if lo > hi:
        return None
    while hi < last_k and hit(hi + 1):
        hi += 1
    while hi > lo and not hit(hi):
        hi -= 1
    return (lo, hi)


def analytic_engine(layout, progress=None):
    """Exact edges per wafer in closed form, then quantized onto the step grid: the cost does not
    depend on the number of steps. With z_step = 0 it returns the continuous ``ExactHits``.
    Plain Python throughout: a headless scan need not pay for importing numpy."""
    scan = layout.scan
    if scan.final_z < scan.start_z:
        raise ValueError("final_z is below start_z")
    if not scan.exact:
        steps, runs, _ = _stepped_steps(layout)
        return StepHits(scan.position_count, steps, runs)
    wafers = layout.wafers
    edges = [None] * len(wafers)
    level_scan = layout.lift_axis == (0.0, 0.0, 1.0) and layout.beam.direction[2] == 0.0
    level_edges = level_edger(layout) if level_scan else None
    # A level wafer's stepped interval straight from its edges when no grid position lies near
    # them (is_level, settled_steps, with the layout's part of each worked out once); else
    # the steps next to the edges are tested (snap_to_grid).
    settled = None if scan.exact else settler(layout)
    steps = [None] * len(wafers)
    for i in reachable_wafers(layout):  # only these: most of a fab's wafers are out of reach
        wafer = wafers[i]
        level = level_scan and wafer.normal == (0.0, 0.0, 1.0)
        edge = level_edges(wafer) if level and not wafer.bow else wafer_edges(layout, wafer)
        edges[i] = edge
        if settled is not None and edge is not None:
            steps[i] = (level and settled(edge)) or snap_to_grid(layout, wafer, edge)
    if scan.exact:
        edges = [None if e is None else geometric_edges(layout, w, e)
                 for w, e in zip(wafers, edges)]
        clipped = []
        for e in edges:
            if e is None or e[1] < scan.start_z or e[0] > scan.final_z:
                clipped.append(None)
            else:
                clipped.append((max(e[0], scan.start_z), min(e[1], scan.final_z)))
        runs = []
        for first, last in sorted(c for c in clipped if c is not None):
            if runs and first <= runs[-1][1]:
                runs[-1] = (runs[-1][0], max(runs[-1][1], last))
            else:
                runs.append((first, last))
        return ExactHits(tuple(clipped), tuple(runs))
    steps = tuple(steps)
    return StepHits(scan.position_count, steps, runs_from_intervals(steps))


def analytic_stepped(layout, circle):
    """``analytic_engine(layout)`` of a stepped scan (z_step > 0), and from the same pass over
    the wafers the carrier's wafers with their protrusions, as
    ``scan_result.carrier_protrusions`` gives them (``circle``: its ``carrier_circle``), or
    None where the pass cannot tell them (a tilted wafer, a scan that is not level: the caller
    asks ``carrier_protrusions`` then). Returns (StepHits, the carrier's wafers or None).

    A scan walks the layout's wafers for the beam and again for the carrier's protrusion check
    (SPEC §4); a fab's 75 wafers of the other carriers cost each pass its own steps of Python.
    The hits are ``analytic_engine``'s: the same function of the same values
    (tests/core/test_fab_shared_pass.py checks both answers against their definitions)."""
    scan = layout.scan
    if scan.final_z < scan.start_z:
        raise ValueError("final_z is below start_z")
    steps, runs, inside = _stepped_steps(layout, circle)
    return StepHits(scan.position_count, steps, runs), inside


def _stepped_steps(layout, circle=None, tol=TOUCH_TOLERANCE):
    """``analytic_engine``'s stepped intervals (z_step > 0), one per wafer of the layout, None
    where the beam misses it or ``reachable_wafers`` leaves it out, and the runs they make
    (``runs_from_intervals`` of them: only the wafers with steps make runs). Where the level
    loop met the wafers in ascending order and apart (each one's first step beyond the last
    one's last step + 1: a fab's seated wafers), the merge would sort nothing and join nothing:
    the runs are those intervals themselves, the same pairs.

    In a level scan (lift along Z, the beam level) one loop over the wafers does, for a level
    wafer, what ``reachable_wafers`` (``accessible_wafers``' level branch, over the scan's
    range), ``level_edger`` and ``settler`` do, written out term for term: the same floats
    (tests/core/test_fab_fast_paths.py checks the loop against the three, and so does
    tests/core/test_fab_floor.py; each against its definition in tests/core/test_fixed_cost.py,
    the engine against ``loop`` in tests/core/test_engines.py). A tilted wafer takes
    ``accessible_wafers`` itself, a bowed one the general edges, edges near a grid position
    ``snap_to_grid``, as before.

    ``circle``, when given (``scan_result.carrier_circle`` of a carrier), the loop also does
    ``carrier_protrusions``' pass: a level wafer's answer in X and Y (inside the carrier's
    circle, and its protrusion) is the circle's, taken once for the wafers that share their
    objects as the beam's answers are (the two passes made the same groups), and its Z test
    reads the mid-plane height ``mid_z`` that the beam's Z test computes, the same sum
    (cz + thickness / 2.0). Returns (steps, runs, the carrier's [(wafer, protrusion)] in the
    layout's order), the last None without a circle, in a scan that is not level, or when a
    tilted wafer (whose protrusion is the general one's) was met."""
    wafers = layout.wafers
    steps = [None] * len(wafers)
    present = []
    if not (layout.lift_axis == (0.0, 0.0, 1.0) and layout.beam.direction[2] == 0.0):
        _snapped(layout, reachable_wafers(layout), steps, present)
        return tuple(steps), _merged_runs(present), None
    scan = layout.scan
    # reachable_wafers: accessible_wafers' values of the beam swept over the scan
    reach = sweep_reach(layout, scan.start_z, scan.final_z)
    margin, z_top, z_bottom = reach[:3]
    settling = _settling(layout)
    settled = _settler(settling)
    start, step, last_k, scan_size, scan_margin = settling
    ceil, floor = math.ceil, math.floor
    # level_edger's values of the beam, read once a scan
    ox, oy, oz = layout.beam.emitter
    ex, ey, _ = layout.beam.direction
    sqrt, copysign, inf = math.sqrt, math.copysign, math.inf
    qq = ex * ex + ey * ey
    past_end = layout.beam.length + tol
    tilted = []  # the wafers that are not level, for accessible_wafers after the loop
    # carrier_protrusions' values of the carrier (unused without a circle: amount stays None)
    amount_of, z_lo, z_hi = (None, None, None) if circle is None else circle
    inside = []
    # The last level wafer's normal, centre X and Y and diameter (the objects), whether it
    # passed accessible_wafers' XY test (``near``), whether the beam's line crosses its rim
    # within the beam (``crossed``) and its protrusion when inside the carrier's circle
    # (``amount``, else None), which depend on these alone: the next wafer with the same
    # objects (a carrier's seated wafers, made from the carrier's numbers), so the same numbers
    # bit for bit, takes the answers without their arithmetic. ``keep``: near or inside.
    same_normal = same_x = same_y = same_diameter = None
    near = crossed = keep = False
    amount = None
    apart, last = True, -2  # whether the intervals so far ascend apart; the last one's end
    for i, wafer in enumerate(wafers):
        (cx, cy, cz), normal, diameter = wafer.center, wafer.normal, wafer.diameter
        if normal is same_normal and cx is same_x and cy is same_y and diameter is same_diameter:
            if not keep:
                continue
        elif normal == LEVEL:
            same_normal, same_x, same_y, same_diameter = normal, cx, cy, diameter
            # accessible_wafers' XY test of a level wafer, and carrier_protrusions'
            near = level_near(reach, cx, cy, diameter)
            amount = None if amount_of is None else amount_of(cx, cy, diameter)
            keep = near or amount is not None
            if not keep:
                continue
            if near:
                # level_edger's rim: where the beam's line is within it (rim_span), and
                # whether that meets the beam
                wx, wy = ox - cx, oy - cy
                r = diameter / 2.0 + tol
                c = wx * wx + wy * wy - r * r
                if qq == 0.0:
                    crossed = not c > 0.0
                    low, high = -inf, inf
                else:
                    pq = wx * ex + wy * ey + 0.0
                    disc = pq * pq - qq * c
                    crossed = not disc < 0.0
                    if crossed:
                        root = -pq - copysign(sqrt(disc), pq)  # rim_roots
                        r1 = root / qq
                        r2 = c / root if root != 0.0 else 0.0
                        low, high = (r1, r2) if r1 <= r2 else (r2, r1)
                crossed = crossed and not (high < -tol or low > past_end)
        else:
            tilted.append(i)
            continue
        thickness = wafer.thickness
        mid_z = cz + thickness / 2.0
        # carrier_protrusions' Z test of a level wafer inside the circle: n = (0, 0, 1), its
        # mid-plane at cz + thickness / 2.0 * 1 = mid_z
        if amount is not None and z_lo <= mid_z <= z_hi:
            inside.append((wafer, amount))
        if not near:
            continue
        # accessible_wafers' Z test of a level wafer. Its mid-plane within the scan's range
        # passes it: subtracting (adding) half_z >= 0 and margin >= 0 gives no more (no less)
        # than mid_z, rounding being monotonic.
        bow = wafer.bow
        if not (z_bottom <= mid_z <= z_top and thickness >= 0.0):
            half_z = 0.5 * thickness + abs(bow)
            if z_top < (mid_z - half_z) - margin or z_bottom > (mid_z + half_z) + margin:
                continue
        if bow:  # level but bowed: the general edges, then settled (or snapped)
            edge = wafer_edges(layout, wafer)
            if edge is None:
                continue
            found = settled(edge) or snap_to_grid(layout, wafer, edge)
        else:
            if not crossed:
                continue
            # level_edger's edges: the faces' heights, widened by the touch tolerance
            wz = oz - cz
            low, high = -tol - wz, thickness + tol - wz
            if low <= high:
                e0, e1 = oz + low, oz + high
            else:
                e0, e1 = oz + high, oz + low
            # max(|e0|, |e1|) > the scan's size, e0 <= e1 (a NaN, which no comparison
            # passes, raises in ceil either way)
            if e1 > scan_size or -e0 > scan_size:
                found = settled((e0, e1))  # an edge beyond the scan's size widens the margin
            else:
                # settled((e0, e1)) with |e0|, |e1| <= the scan's size: its margin is the scan's
                x0 = (e0 - start) / step
                x1 = (e1 - start) / step
                lo, hi = ceil(x0), floor(x1)
                if lo - x0 <= scan_margin or x0 - lo + 1 <= scan_margin or \
                        x1 - hi <= scan_margin or hi + 1 - x1 <= scan_margin:
                    found = None
                else:
                    if lo < 0:
                        lo = 0
                    if hi > last_k:
                        hi = last_k
                    if lo <= hi:  # settled, as most are: taken as below, without its tests
                        steps[i] = found = (lo, hi)
                        present.append(found)
                        if lo > last + 1:
                            last = hi
                        else:
                            apart = False
                        continue
                    found = None
            found = found or snap_to_grid(layout, wafer, (e0, e1))
        if found is not None:
            steps[i] = found
            present.append(found)
            if found[0] > last + 1:
                last = found[1]
            else:
                apart = False
    if tilted:
        # reachable_wafers' answer for them: accessible_wafers' general test (one wafer's
        # answer does not depend on the others)
        reached = accessible_wafers(layout, [wafers[i] for i in tilted], scan.start_z,
                                    scan.final_z)
        _snapped(layout, [tilted[j] for j in reached], steps, present)
        apart = False  # (they come last, in any order)
        inside = None  # its protrusion, in its place among the others: carrier_protrusions'
    return (tuple(steps), tuple(present) if apart else _merged_runs(present),
            None if circle is None else inside)


def _snapped(layout, indices, steps, present):
    """The general edges of the wafers ``indices`` snapped to the grid: each one's steps into
    ``steps`` (None where the beam misses it), those not None appended to ``present``."""
    wafers = layout.wafers
    for i in indices:
        wafer = wafers[i]
        edge = wafer_edges(layout, wafer)
        if edge is not None:
            steps[i] = found = snap_to_grid(layout, wafer, edge)
            if found is not None:
                present.append(found)


# Engines of the CAD layer (waferscan.cad, which needs FreeCAD): named here so that a command
# line can offer them without importing FreeCAD.
CAD_ENGINES = ("document", "brep")

ENGINES = {
    "loop": loop_engine,
    "vector": vector_engine,
    "analytic": analytic_engine,
    "paper": paper_engine,
}


def run_engine(name, layout, progress=None):
    """Run the named engine on the layout."""
    try:
        engine = ENGINES[name]
    except KeyError:
        raise ValueError(f"unknown engine {name!r}; choose one of {', '.join(sorted(ENGINES))}")
    return engine(layout, progress=progress)
