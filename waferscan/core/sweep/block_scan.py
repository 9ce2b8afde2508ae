"""Scanning a block of drawn layouts (layouts x wafers): over arrays where the closed forms
hold (the wafers' translation ranges, the step grid, the runs, the latching and the mapping, each
the array form of the scalar scan's own function), and layout by layout through the scalar scan,
the oracle, where they do not (a beam spot, latching in motion, exact edges, a slow scan's jab or
sweep, an edge on the grid). The same states either way: tests/core/test_sweep.py."""

from __future__ import annotations

import math
from dataclasses import replace

from .. import mapping
from ..geometry.beam import TOUCH_TOLERANCE
from ..geometry.ranges import translation_ranges
from ..mapping import PROTRUDING, map_runs, map_slots
from ..model import SLOW, Beam, Wafer
from ..scan.scan_result import latch_runs, protruding_rows
from .draws import sample_layout

# The wafers of a block whose beam ranges are computed at once (scan_block; the same results
# in any chunks: every operation there is element by element). 4,096 kept the temporaries in
# a core's cache while the general region's corners made dozens of them (100,000 layouts:
# 3.35-3.4 s against 3.5-3.65 s unchunked); since a tilted beam over level wafers takes
# _slanted_extremes, a whole block (~12,000 wafers) at once is 18-19 % faster in one process
# (median of 5 interleaved rounds of 50,000 layouts, against 4,096) and 3-9 % in each of two
# side by side: the per-call cost of the few tilted (cross-slotted) wafers' conic path is paid
# once a block instead of three times.
SWEEP_CHUNK = 16384
# A grid position nearer than this (mm) to a wafer's edge is settled by the scalar engine's own
# test, not by the array formulas (which agree with it to ~1e-12 mm).
GRID_MARGIN = 1e-7
# Reported state code of an unscanned slot in the sweep's arrays (mapping.UNSCANNED is "?").
UNSCANNED = 7


# --- the scalar path (the oracle, and the spot's path) ---------------------------------------

def scalar_layout_states(base, layout, peaks=None, ray_ranges=None):
    """Reported state codes, measured thickness and bottom per slot (lists; None where a slot
    has no run) of one layout by the scalar path: ``scan_layout`` and the recipe's mapping.
    ``peaks``: a list to which the largest blocked fraction of each group of wafers a beam spot
    saw is appended (SPEC §10; none for the ideal beam). ``ray_ranges``: the block's centre-ray
    ranges (``spot_scan.range_table``), for a beam spot."""
    from ..scan.layout_scan import scan_layout

    result = scan_layout(layout, ray_ranges=ray_ranges)
    if peaks is not None and result.signal is not None:
        peaks.extend(group.peak for group in result.signal.groups)
    return states_of_runs(base, layout, result.runs)


def scalar_block(base, draws, peaks=None):
    """``scan_block``'s answer layout by layout through the scalar path (``peaks`` as in
    ``scalar_layout_states``)."""
    import numpy as np

    m, S = draws.truth.shape
    states = np.zeros((m, S), dtype=np.int8)
    thickness = np.full((m, S), np.nan)
    bottom = np.full((m, S), np.nan)
    for i in range(m):
        st, th, bo = scalar_layout_states(base, sample_layout(base, draws, i), peaks)
        states[i] = st
        thickness[i] = [np.nan if v is None else v for v in th]
        bottom[i] = [np.nan if v is None else v for v in bo]
    return states, thickness, bottom


def spot_block(base, draws, peaks=None):
    """``scalar_block``'s answer (states, thickness, bottom; ``peaks`` as there) for a layout
    with a beam spot (core/sweep/spot_scan.py): the block's column ranges over arrays first
    (``range_table``); the layouts read per step in a fast scan through ``lean_block``, the
    others through the scalar path, which finds the ranges there. The same answers as
    ``scalar_block``, bit for bit (tests/core/test_sweep_spot.py)."""
    import numpy as np

    from .spot_scan import lean_block, lean_spot_path, range_table

    layout = base.layout
    spot = layout.spot
    m, S = draws.truth.shape
    layouts = [sample_layout(base, draws, i) for i in range(m)]
    table = range_table(layouts, spot) if spot is not None and not spot.ideal else {}
    states = np.zeros((m, S), dtype=np.int8)
    thickness = np.full((m, S), np.nan)
    bottom = np.full((m, S), np.nan)
    lean = [i for i, sample in enumerate(layouts) if lean_spot_path(sample)]
    answers = dict(zip(lean, lean_block([layouts[i] for i in lean], table)))
    for i, sample in enumerate(layouts):
        if i in answers:
            runs, group_peaks = answers[i]
            if peaks is not None:
                peaks.extend(group_peaks)
            st, th, bo = states_of_runs(base, sample, runs)
        else:
            st, th, bo = scalar_layout_states(base, sample, peaks, table)
        states[i] = st
        thickness[i] = [np.nan if v is None else v for v in th]
        bottom[i] = [np.nan if v is None else v for v in bo]
    return states, thickness, bottom


def states_of_runs(base, layout, runs):
    """``scalar_layout_states``'s answer from the scan's runs (``SensorRun``s): the
    recipe's mapping, the first run's thickness and bottom per slot."""
    from ..mapping import unscanned_slots
    from ..scan.scan_result import protruding_slots

    plan = base.plan
    flagged, _ = protruding_slots(base.carrier, plan, layout.wafers)
    unscanned = unscanned_slots(plan, (layout.scan.start_z, layout.scan.final_z))
    slot_map = map_slots(plan, [(r.bottom, r.top) for r in runs], flagged, unscanned)
    states, thickness, bottom = [], [], []
    for slot in slot_map.slots:
        states.append(UNSCANNED if slot.state == mapping.UNSCANNED else slot.state)
        if slot.runs:
            run = runs[slot.runs[0]]
            thickness.append(run.diff)
            bottom.append(run.bottom)
        else:
            thickness.append(None)
            bottom.append(None)
    return states, thickness, bottom


def needs_scalar_path(layout):
    """A beam spot, latching in motion, a slow scan's jab or sweep, or exact edges: the layout
    is scanned by the scalar path, one layout at a time."""
    from ..scan import slow_scan
    from ..scan.sensing import ideal_sensor

    return (not ideal_sensor(layout) or layout.scan.exact or slow_scan.probes_pockets(layout.scan))


# --- the vectorised scan ---------------------------------------------------------------------

def scalar_steps(base, draws, i, s, k):
    """One wafer's stepped interval by the scalar engine (engines.snap_to_grid et al.)."""
    from ..scan.engines import is_level, settled_steps, snap_to_grid, wafer_edges

    carrier = base.carrier
    wafer = Wafer(name=f"{carrier.name}_S{s + 1:02d}_{k}",
                  center=tuple(float(v) for v in draws.center[i, s, k]),
                  normal=tuple(float(v) for v in draws.normal[i, s, k]),
                  diameter=carrier.wafer_diameter, thickness=float(draws.thickness[i, s, k]),
                  carrier=carrier.name, slot=s + 1, bow=float(draws.bow[i, s, k]))
    beam = base.layout.beam
    layout = replace(base.layout, wafers=(wafer,), beam=Beam(
        beam.emitter, tuple(float(v) for v in draws.direction[i]), beam.length))
    edges = wafer_edges(layout, wafer)
    if edges is None:
        return None
    return (is_level(layout, wafer) and settled_steps(layout, edges)) or \
        snap_to_grid(layout, wafer, edges)


def scan_block(base, draws):
    """Reported state codes (m, S), measured thickness and bottom (m, S; nan without a run) of
    a block of sampled layouts, in numpy over layouts x wafers. Equal to ``scalar_block``."""
    import numpy as np

    layout = base.layout
    scan = layout.scan
    plan = base.plan
    if needs_scalar_path(layout):
        return scalar_block(base, draws)
    m, S = draws.truth.shape
    W = 2 * S
    # The wafers that exist, layout li, place wi, gathered by their flat index (np.take of
    # rows: cheaper than indexing by the pair (li, wi)).
    flat = np.flatnonzero(draws.exists)
    li, wi = np.divmod(flat, W)
    center = draws.center.reshape(-1, 3).take(flat, axis=0)
    normal = draws.normal.reshape(-1, 3).take(flat, axis=0)
    radius = np.full(len(li), 0.5 * base.carrier.wafer_diameter)
    thickness = draws.thickness.reshape(-1).take(flat)
    bow = draws.bow.reshape(-1).take(flat)
    # In chunks of wafers: translation_ranges makes dozens of temporaries the length of its
    # arrays, and a block's (~12,000 wafers) spill from the core's cache; a chunk's stay in it
    # (SWEEP_CHUNK).
    direction = draws.direction.take(li, axis=0)
    chunks = [slice(a, a + SWEEP_CHUNK) for a in range(0, len(li), SWEEP_CHUNK)] or [slice(0)]
    parts = [translation_ranges(layout.beam.emitter, direction[c], layout.lift_axis, center[c],
                                normal[c], radius[c], thickness[c], layout.beam.length,
                                TOUCH_TOLERANCE, bow[c])
             for c in chunks]
    lo, hi, hit, covered = (np.concatenate([p[k] for p in parts]) for k in range(4))
    scalar = ~covered
    z0 = layout.beam.emitter[2]
    az = layout.lift_axis[2]
    e0 = z0 + lo * az
    e1 = z0 + hi * az
    step = scan.z_step
    last = scan.last_step
    with np.errstate(invalid="ignore"):
        x0 = (e0 - scan.start_z) / step
        x1 = (e1 - scan.start_z) / step
        margin = GRID_MARGIN / step
        near = ((np.abs(x0 - np.rint(x0)) <= margin) | (np.abs(x1 - np.rint(x1)) <= margin))
        k_lo = np.maximum(0, np.ceil(x0))
        k_hi = np.minimum(last, np.floor(x1))
    near &= hit
    hit = hit & ~near
    scalar |= near
    k_lo = np.where(hit, k_lo, 0).astype(np.int64)
    k_hi = np.where(hit, k_hi, -1).astype(np.int64)
    for j in np.flatnonzero(scalar):
        steps = scalar_steps(base, draws, int(li[j]), int(wi[j]) // 2, int(wi[j]) % 2)
        if steps is not None:
            k_lo[j], k_hi[j] = steps
    # Each layout's intervals side by side from column 0, in the order of its wafers (li
    # ascends): as wide as the most a layout has, about half of W (a double's second place is
    # nearly always empty), so the runs' sort, merge, latching and mapping handle half the
    # columns; the same runs as at the wafers' own columns (_merge_runs sorts them stably).
    valid = k_lo <= k_hi
    rows = li[valid]
    counts = np.bincount(rows, minlength=m)
    cols = np.arange(len(rows)) - (np.cumsum(counts) - counts)[rows]
    width = max(1, int(counts.max(initial=0)))
    first = np.full((m, width), np.iinfo(np.int64).max)
    lastk = np.full((m, width), -1, dtype=np.int64)
    first[rows, cols] = k_lo[valid]
    lastk[rows, cols] = k_hi[valid]
    run_lo, run_hi, run_ok = _merge_runs(first, lastk)
    if scan.mode == SLOW:  # only the carrier's pockets are read (scan_result.pocket_window)
        w_lo = max(0, math.ceil((plan.seat_z(1) - 0.5 * plan.pitch - scan.start_z) / step))
        w_hi = min(last, math.floor((plan.seat_z(plan.slot_count) + 0.5 * plan.pitch
                                     - scan.start_z) / step))
        run_ok &= ~((run_hi < w_lo) | (run_lo > w_hi))
        run_lo = np.maximum(run_lo, w_lo)
        run_hi = np.minimum(run_hi, w_hi)
    bottom = scan.start_z + run_lo * step  # ScanParameters.position
    top = scan.start_z + run_hi * step
    if draws.sensor_response is None:
        bottom, top = latch_runs(bottom, top, scan)
    else:
        lag = (scan.scan_speed * draws.sensor_response)[:, None] if scan.mode != SLOW else 0.0
        bottom, top = latch_runs(bottom, top, scan, lag)
    # Compact each layout's valid runs to the left, in ascending order (they already are).
    # _merge_runs leaves them so; only a slow scan's window may have dropped some.
    if not np.all(run_ok[:, :-1] | ~run_ok[:, 1:]):
        order = np.argsort(~run_ok, axis=1, kind="stable")
        bottom = np.take_along_axis(bottom, order, axis=1)
        top = np.take_along_axis(top, order, axis=1)
        run_ok = np.take_along_axis(run_ok, order, axis=1)
    states, first_run = map_runs(plan, bottom, top, run_ok)
    flagged = protruding_rows(base.carrier, plan, m, li, center, normal, thickness, bow)
    states = np.where(flagged, PROTRUDING, states)
    unscanned = _unscanned(plan, scan)
    if unscanned:
        cols = np.array(unscanned) - 1
        states[:, cols] = np.where(flagged[:, cols], PROTRUDING, UNSCANNED)
    has = first_run < bottom.shape[1]
    pick = np.minimum(first_run, bottom.shape[1] - 1)
    b = np.take_along_axis(bottom, pick, axis=1)
    tp = np.take_along_axis(top, pick, axis=1)
    thick = np.where(has, tp - b, np.nan)
    return states.astype(np.int8), thick, np.where(has, b, np.nan)


def _unscanned(plan, scan):
    from ..mapping import unscanned_slots

    return unscanned_slots(plan, (scan.start_z, scan.final_z))


def _merge_runs(first, last):
    """Per layout (rows), the union of the step intervals (first, last) (first = int max where
    none) as runs: intervals that overlap or are adjacent merge (engines.runs_from_intervals).
    Returns (lo, hi, ok) arrays (m, W): run j of each layout, ok where it exists."""
    import numpy as np

    m, W = first.shape
    order = np.argsort(first, axis=1, kind="stable")
    f = np.take_along_axis(first, order, axis=1)
    la = np.take_along_axis(last, order, axis=1)
    # The intervals that exist sort first (the others' first is int max, their last -1), so
    # the running maximum of the last steps is, at each of them, the reach of those before it
    # and itself: a run starts where an interval begins past the reach before it plus one, and
    # ends (at its highest step, every interval's last >= its first) where the next one starts.
    present = la >= 0
    reach = np.maximum.accumulate(la, axis=1)
    new = present.copy()
    new[:, 0] &= f[:, 0] > -1
    new[:, 1:] &= f[:, 1:] > reach[:, :-1] + 1
    end = present.copy()
    end[:, :-1] &= new[:, 1:] | ~present[:, 1:]
    # Runs j = 0, 1, ... of each layout, in the order their starts and ends come (row-major).
    ok = np.arange(W) < np.count_nonzero(new, axis=1)[:, None]
    lo = np.zeros((m, W), dtype=np.int64)
    hi = np.full((m, W), -1, dtype=np.int64)
    lo[ok] = f[new]
    hi[ok] = reach[end]
    return lo, hi, ok
