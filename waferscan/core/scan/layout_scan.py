"""One scan, start to finish: engine, sensor runs as the MCS sees them, per-wafer intervals,
protrusion check and slot map.

Semantics of the modes (SPEC §3):
- ``fast``: one stroke over [start_z, final_z] (``up``, ``down``, or ``updown``: both, averaged).
  A latched edge trails the true one by scan_speed * sensor_response in the direction of motion.
- ``slow``: the end-effector stops at each step of each pocket's window [seat - p/2, seat + p/2]
  of the scanned carrier, so the sensor is read at rest (no latch lag) and only the carrier's
  windows are swept; the windows tile the carrier, so a run crossing two pockets stays whole.
"""

from __future__ import annotations

import gc
import threading
from contextlib import contextmanager

from ..mapping import POSITION_ERROR, map_slots, two_run_warnings, unscanned_slots
from ..model import SLOW, UP
from . import slow_scan
from .engines import ENGINES, ExactHits, analytic_engine, analytic_stepped, run_engine
from .scan_result import (
    ScanResult,
    SensorRun,
    _stepped_records,
    carrier_circle,
    exact_intervals,
    latcher,
    missed_by_beam,
    pocket_window,
    protruding_slots,
    protrusions_by_slot,
    run_wafers,
    scan_warnings,
    scanned_range,
    slot_plan,
    stepped_intervals,
    wafer_records,
)


def scan_layout(layout, engine="analytic", progress=None, stepper=None, measure=None,
                ray_ranges=None, turn_limits=None):
    """Scan the layout with the named engine and map the scanned carrier's slots.

    ``stepper(layout, progress)``, when given, computes the hits in place of the core engine of
    that name (the CAD layer's ``document`` and ``brep`` engines come in this way); ``measure``
    likewise measures a slow scan's jab and sweep (``slow_scan.probe_pocket``). ``ray_ranges``:
    a beam spot's centre-ray ranges worked out beforehand by a sweep (core/sensor/spot.py).
    ``turn_limits(slot, z, depth, amplitude)`` -> (low, high): how far a slow scan's sweep may
    turn at a pocket (the robot layer's clearance, SPEC §13 amended; default: all of it)."""
    # The core's scan makes a few objects a wafer and no reference cycles; Python's cyclic
    # collector, run meanwhile as objects pile up, made 10,000 wafers cost 12.6-21.5x 1,000
    # (~30 % of the larger scan in collection). It waits until the scan is done (SPEC §9:
    # <= 12x). Not for the CAD layer's engines (``stepper``): they step FreeCAD's objects for
    # seconds, and what they leave is collected as it comes.
    if stepper is not None:
        return _scan_layout(layout, engine, progress, stepper, measure, ray_ranges,
                            turn_limits)
    # collector_paused() written out: its generator's context manager cost more than the pause
    _pause_collector()
    try:
        return _scan_layout(layout, engine, progress, stepper, measure, ray_ranges,
                            turn_limits)
    finally:
        _resume_collector()


_PAUSE = threading.Lock()
_PAUSED = [0, False]  # [blocks inside a pause now, whether the collector ran before the first]


def _pause_collector():
    with _PAUSE:
        if _PAUSED[0] == 0:
            _PAUSED[1] = gc.isenabled()
            gc.disable()
        _PAUSED[0] += 1


def _resume_collector():
    with _PAUSE:
        _PAUSED[0] -= 1
        if _PAUSED[0] == 0 and _PAUSED[1]:
            gc.enable()


@contextmanager
def collector_paused():
    """Python's cyclic garbage collector held off within the block, and as it was after the
    last of the blocks that overlap (threads scanning at once: a Dask worker of several
    threads). The collector's state is the process's: one count for all threads, under a lock,
    so that no order of entries and exits leaves it off."""
    _pause_collector()
    try:
        yield
    finally:
        _resume_collector()


def _scan_layout(layout, engine, progress, stepper, measure, ray_ranges, turn_limits):
    if layout.spot is not None or layout.scan.latch != "step":
        from .sensing import ideal_sensor, sensed_scan

        if not ideal_sensor(layout):  # SPEC §10: a beam spot, latching in motion
            return sensed_scan(layout, engine, progress, ray_ranges)
    scan = layout.scan
    carrier = layout.scanned_carrier
    plan = slot_plan(carrier, layout.mapping)
    stepping = slow_scan.stepping_layout(layout)  # with a jab, the fork in (SPEC §13)
    inside = None  # the carrier's wafers and protrusions, when the engine's pass found them
    if stepper is not None:
        hits = stepper(stepping, progress)
    elif not scan.exact and ENGINES.get(engine) is analytic_engine:
        # its pass over the wafers does carrier_protrusions' too (the same wafers: stepping is
        # the layout, or it with another beam)
        hits, inside = analytic_stepped(stepping, carrier_circle(carrier))
    else:
        hits = run_engine(engine, stepping, progress)
    window = pocket_window(plan) if scan.mode == SLOW else None
    # Whether the runs' ends are grid positions start_z + k z_step (k >= 0, z_step > 0): never
    # -0.0, since a sum is -0.0 only where both its terms are, and k z_step is not
    on_grid = False
    if window is None and not isinstance(hits, ExactHits):
        run_spans, wafers, run_names, bottoms, tops = _stepped_records(hits, scan,
                                                                       layout.wafers)
        wafer_spans = hits.wafer_steps  # None where the scan never met a wafer, as its span
        on_grid = True
    else:
        if isinstance(hits, ExactHits):
            run_spans, wafer_spans = exact_intervals(hits, window)
        else:
            run_spans, wafer_spans = stepped_intervals(hits, scan, window)
        wafers = wafer_records(layout.wafers, wafer_spans)
        run_names = run_wafers(run_spans, layout.wafers, wafer_spans)
    lag = scan.latch_lag
    runs = None
    if scan.mode == SLOW or scan.direction == UP:
        # latcher's (bottom + lag, top + lag), without its call a run; bottom <= top stays so
        # (rounding is monotonic), so these are also the runs' (bottom, top) below. Without a
        # lag they are the spans themselves: z + 0.0 is z, bit for bit, but for z = -0.0.
        if lag == 0.0 and on_grid:
            latched = spans = run_spans
            # each run's (z_in, z_out) is its span's (bottom, top): the runs made at once
            runs = tuple(map(SensorRun, bottoms, tops, run_names, run_spans))
        else:
            latched = spans = [(bottom + lag, top + lag) for bottom, top in run_spans]
    else:
        latch_run = latcher(scan)
        latched = [latch_run(bottom, top) for bottom, top in run_spans]
        # (run.bottom, run.top) of each run, from its latched pair without the properties' calls
        spans = [(z_in, z_out) if z_in <= z_out else (z_out, z_in)  # min, max
                 for z_in, z_out in latched]
    if runs is None:
        runs = tuple([SensorRun(z_in, z_out, names, span)
                      for (z_in, z_out), span, names in zip(latched, run_spans, run_names)])
    flagged, protrusions = protruding_slots(carrier, plan, layout.wafers, inside)
    # The range the scan was set to cover; between its stepped positions, as everywhere on the
    # grid, the beam is sampled a step apart.
    scanned = (scan.start_z, scan.final_z)
    unscanned = unscanned_slots(plan, scanned)
    # SPEC §13: a slow scan's jab and sweep at each scanned pocket (core/scan/slow_scan.py).
    pockets, swept_off, probe_warnings = (), (), []
    if slow_scan.probes_pockets(scan):
        pockets = slow_scan.probe_pockets(
            layout, plan, [s for s in range(1, plan.slot_count + 1) if s not in unscanned],
            measure, turn_limits)
        jabbed, swept_off, probe_warnings = slow_scan.judge(layout, plan, pockets)
        if scan.jab > 0.0:
            # SPEC §13: the robot's own sensor measures protrusion as well as the load port's
            # (§4: 6 however the wafer is seated): the jab adds evidence, never removes any. A
            # wafer below or above the jab's height, or a jab that starts inside the wafers,
            # misses what the load port sees: said, slot by slot.
            missed = sorted(set(flagged) - set(jabbed))
            if missed:
                by_slot, _ = protrusions_by_slot(carrier, plan, layout.wafers)
                probe_warnings += slow_scan.missed_protrusion_warnings(
                    plan, [p for p in pockets if p.slot in missed], by_slot)
            flagged = sorted(set(flagged) | set(jabbed))
    slot_map = map_slots(plan, spans, flagged, unscanned)
    probe_warnings += two_run_warnings(plan, slot_map, spans)  # "boundary" rules only
    if swept_off:
        slot_map = slow_scan.with_position_errors(slot_map, swept_off)
        # Why a slot reads 5 by its sweep; a slot worse by its runs (cross-slotted) keeps its
        # code.
        probe_warnings += [why for slot, why in sorted(dict(swept_off).items())
                           if slot_map.slots[slot - 1].state == POSITION_ERROR]
    notice = slow_scan.slow_fast_notice(scan)  # SPEC §13: a jab or sweep a fast scan ignores
    probe_warnings += [notice] if notice else []
    warnings = scan_warnings(layout, plan, run_spans, scanned, unscanned,
                             scanned_range(scan, window)) + tuple(probe_warnings) + \
        missed_by_beam(layout, stepping.beam, wafer_spans)
    return ScanResult(layout, engine, plan, runs, wafers, slot_map, protrusions, warnings,
                      pockets=pockets)
