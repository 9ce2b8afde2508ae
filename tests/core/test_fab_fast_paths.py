"""SPEC §9 amended (issue 30): fab's scan_layout within 2x of its floor. The paths written out
for it give what their plain definitions give, bit for bit:

- a level wafer's answers that depend on its centre's X and Y and its diameter alone (the
  accessibility check's XY test, whether the beam crosses its rim, whether it lies in the
  carrier's circle and how far it protrudes) are worked out once for the wafers that share
  those numbers' objects (a carrier's seated wafers): ``accessible_wafers``,
  ``carrier_protrusions`` and the analytic engine against their definitions on stacks that
  share them, a hair either side of every boundary;
- the analytic engine's level loop does the accessibility check, the level edges and the
  settled steps in one pass: against ``accessible``, ``level_edger``, ``settler`` and
  ``snap_to_grid`` one by one;
- ``missed_by_beam`` finds the unmet wafers with ``compress``: against the comprehension it had;
- and scan_layout end to end against a scan put together from the general functions (the
  engine's definition, ``stepped_intervals``, ``wafer_records``, ``run_wafers``, ``latcher``,
  ``protrusion``, ``_land_runs``' judge, ...), every field compared by its repr (so -0.0 is not
  0.0), on the paper, fab and its variations, stacks and 300 random layouts.

No timing here (the ratio is the bench's: waferscan/bench/fab_floor.py)."""

import math
import random
from dataclasses import replace

import pytest
from random_layouts import random_layout, shared_stacks
from scenarios import PAPER, fab_with

from waferscan.bench.workloads import fab_layout, paper_layout, stack_layout
from waferscan.core.geometry.beam import accessible, accessible_wafers, wafer_bounds
from waferscan.core.geometry.ranges import translation_range
from waferscan.core.mapping import (
    EMPTY,
    PROTRUDING,
    UNSCANNED,
    SlotMap,
    SlotState,
    _land_runs,
    two_run_warnings,
    unscanned_slots,
)
from waferscan.core.scan.engines import (
    StepHits,
    analytic_engine,
    level_edger,
    runs_from_intervals,
    settler,
    snap_to_grid,
    wafer_edges,
)
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.scan.scan_result import (
    BEAM_MISSES,
    SHOWN_NAMES,
    ScanResult,
    SensorRun,
    beam_miss,
    carrier_protrusions,
    latcher,
    missed_by_beam,
    protrusion,
    run_wafers,
    scan_warnings,
    scanned_range,
    slot_plan,
    stepped_intervals,
    wafer_records,
)

LEVEL = (0.0, 0.0, 1.0)


# --- the definitions, wafer by wafer ----------------------------------------------------------

def plain_reachable(layout):
    scan = layout.scan
    return [i for i, w in enumerate(layout.wafers)
            if accessible(layout, w, scan.start_z, scan.final_z)]


def plain_hits(layout):
    """analytic_engine's stepped hits by their definitions: the accessibility check wafer by
    wafer, then level_edger's edges and settler's steps for a level wafer of a level scan (the
    general edges for any other), snap_to_grid where not settled."""
    level_scan = layout.lift_axis == LEVEL and layout.beam.direction[2] == 0.0
    edges, settled = level_edger(layout), settler(layout)
    steps = [None] * len(layout.wafers)
    for i in plain_reachable(layout):
        wafer = layout.wafers[i]
        level = level_scan and wafer.normal == LEVEL
        edge = edges(wafer) if level and not wafer.bow else wafer_edges(layout, wafer)
        if edge is not None:
            steps[i] = (level and settled(edge)) or snap_to_grid(layout, wafer, edge)
    return StepHits(layout.scan.position_count, tuple(steps), runs_from_intervals(steps))


def plain_carrier_protrusions(carrier, wafers):
    r = 0.5 * carrier.wafer_diameter
    z_lo = carrier.seat_z(1) - carrier.pitch
    z_hi = carrier.seat_z(carrier.slot_count) + carrier.pitch
    return [(w, protrusion(carrier, w)) for w in wafers
            if math.hypot(w.mid_center[0] - carrier.center[0],
                          w.mid_center[1] - carrier.center[1]) < r
            and z_lo <= w.mid_center[2] <= z_hi]


def plain_missed_by_beam(layout, beam, wafer_spans):
    """missed_by_beam as it was written before its unmet wafers were found by compress."""
    carrier = layout.scanned_carrier.name
    unmet = [wafer for wafer, span in zip(layout.wafers, wafer_spans)
             if span is None and wafer.carrier in (None, carrier)]
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
    return (f"{BEAM_MISSES}{len(missed)} of the {mine} wafers at every height ({names}), "
            f"passing {by} beside {'it' if len(missed) == 1 else 'them'}: their slots read "
            "empty; check where the scanner's emitter and receiver are",)


def plain_scan(layout):
    """scan_layout of a fast stepped scan with the ideal sensor, put together from the general
    functions."""
    scan, carrier = layout.scan, layout.scanned_carrier
    plan = slot_plan(carrier, layout.mapping)
    hits = plain_hits(layout)
    run_spans, wafer_spans = stepped_intervals(hits, scan, None)
    records = wafer_records(layout.wafers, wafer_spans)
    names = run_wafers(run_spans, layout.wafers, wafer_spans)
    latch = latcher(scan)
    latched = [latch(bottom, top) for bottom, top in run_spans]
    runs = tuple(SensorRun(z_in, z_out, n, span)
                 for (z_in, z_out), span, n in zip(latched, run_spans, names))
    spans = [(min(z_in, z_out), max(z_in, z_out)) for z_in, z_out in latched]
    found = plain_carrier_protrusions(carrier, layout.wafers)
    flagged = set()
    for wafer, amount in found:
        if amount > plan.protrusion_limit:
            (_, _, z0), (_, _, z1) = wafer_bounds(wafer)
            flagged.add(plan.nearest_slot(z0))
            flagged.update(s for s in range(1, plan.slot_count + 1) if z0 <= plan.seat_z(s) <= z1)
    scanned = (scan.start_z, scan.final_z)
    unscanned = unscanned_slots(plan, scanned)
    states = [EMPTY] * (plan.slot_count + 1)
    members = [None] * (plan.slot_count + 1)
    _land_runs(plan, spans, states, members)
    for slot in unscanned:
        states[slot] = UNSCANNED
    for slot in flagged:
        states[slot] = PROTRUDING
    slot_map = SlotMap(tuple(SlotState(s, plan.seat_z(s), states[s], tuple(members[s] or ()))
                             for s in range(1, plan.slot_count + 1)))
    warnings = scan_warnings(layout, plan, run_spans, scanned, unscanned,
                             scanned_range(scan, None)) + \
        tuple(two_run_warnings(plan, slot_map, spans)) + \
        plain_missed_by_beam(layout, layout.beam, wafer_spans)
    return ScanResult(layout, "analytic", plan, runs, records, slot_map,
                      tuple((w.name, amount) for w, amount in found), warnings)


def canon(result):
    """Every field that a scan reports, by repr (-0.0 is not 0.0 there)."""
    return repr((result.engine, result.plan, [(r.z_in, r.z_out, r.wafers, r.unlatched)
                                              for r in result.runs],
                 [(w.name, w.z_in, w.z_out) for w in result.wafers],
                 [(s.slot, s.seat_z, s.state, s.runs) for s in result.slot_map.slots],
                 result.protrusions, result.warnings, result.edges, result.pockets,
                 result.asked_scan, result.code))


# --- stacks that share their numbers' objects, at every boundary -----------------------------

def test_shared_numbers_change_no_answer_of_the_accessibility_check():
    kept = dropped = 0
    for seed in range(1500):
        layout = shared_stacks(random.Random(seed))
        expected = plain_reachable(layout)
        scan = layout.scan
        assert accessible_wafers(layout, layout.wafers, scan.start_z, scan.final_z) == \
            expected, seed
        kept += len(expected)
        dropped += len(layout.wafers) - len(expected)
    assert kept > 10_000 and dropped > 10_000


def test_shared_numbers_change_no_carrier_wafer_nor_protrusion():
    inside = outside = 0
    for seed in range(1500):
        layout = shared_stacks(random.Random(seed))
        carrier = layout.carriers[0]
        expected = plain_carrier_protrusions(carrier, layout.wafers)
        assert carrier_protrusions(carrier, layout.wafers) == expected, seed
        assert repr(carrier_protrusions(carrier, layout.wafers)) == repr(expected), seed
        inside += len(expected)
        outside += len(layout.wafers) - len(expected)
    assert inside > 5_000 and outside > 10_000


def test_the_engine_level_loop_is_the_check_the_edges_and_the_settled_steps():
    met = 0
    for seed in range(1500):
        layout = shared_stacks(random.Random(seed))
        expected = plain_hits(layout)
        assert analytic_engine(layout) == expected, seed
        met += sum(1 for s in expected.wafer_steps if s is not None)
    for seed in range(300):
        layout = random_layout(random.Random(seed))
        if seed % 2:  # a level beam lifted along Z: the loop written out
            ex, ey, _ = layout.beam.direction
            norm = math.hypot(ex, ey)
            layout = replace(layout, lift_axis=LEVEL,
                             beam=replace(layout.beam, direction=(ex / norm, ey / norm, 0.0)))
        assert analytic_engine(layout) == plain_hits(layout), seed
    assert met > 5_000


def test_missed_by_beam_finds_the_unmet_wafers_as_before():
    warned = 0
    for seed in range(400):
        rng = random.Random(seed)
        layout = random_layout(rng)
        if seed % 3 == 0:  # the beam set beside the wafers
            beam = layout.beam
            layout = replace(layout, beam=replace(beam, emitter=(beam.emitter[0],
                                                                 beam.emitter[1] - 80.0,
                                                                 beam.emitter[2])))
        spans = [None if rng.random() < 0.5 else (0, 1) for _ in layout.wafers]
        expected = plain_missed_by_beam(layout, layout.beam, spans)
        assert missed_by_beam(layout, layout.beam, spans) == expected, seed
        assert missed_by_beam(layout, layout.beam, tuple(spans)) == expected, seed
        warned += bool(expected)
    assert warned > 50


def layouts():
    paper = paper_layout(PAPER)
    fab = fab_layout(paper)
    yield "paper", paper
    yield "fab", fab
    yield "fab-LP2", replace(fab, carrier="LP2")
    yield "fab-empty", replace(fab, wafers=())
    yield "fab-short", fab.with_scan(start_z=300.0, final_z=400.0)
    yield "fab-below-0", fab.with_scan(start_z=-10.0, final_z=400.0, z_step=0.05)
    yield "stack", stack_layout(3)
    states = ("absent", "present", "double", "thin", "misplaced", "protruding", "cross")
    for seed in range(20):
        rng = random.Random(seed)
        load = [rng.choice(states) for _ in range(24)] + ["present"]
        yield f"fab{seed}", fab_with(load, foups=rng.choice([1, 2, 4]),
                                     z_step=rng.choice([0.001, 0.05, 0.013, 0.5]))
    for seed in range(300):
        yield f"random{seed}", random_layout(random.Random(seed))
    for seed in range(100):
        yield f"stacks{seed}", shared_stacks(random.Random(seed))


@pytest.mark.parametrize("direction, response", [("up", 0.0), ("up", 0.002), ("down", 0.003),
                                                 ("updown", 0.001)])
def test_scan_layout_is_the_scan_put_together_from_the_general_functions(direction, response):
    compared = 0
    for name, layout in layouts():
        layout = layout.with_scan(direction=direction, sensor_response=response)
        for rules in ("waferscan", "boundary"):
            if rules != "waferscan":
                if compared % 5:
                    continue
                layout = replace(layout, mapping=replace(layout.mapping, rules=rules))
            assert canon(scan_layout(layout, "analytic")) == canon(plain_scan(layout)), name
            compared += 1
    assert compared > 400


def test_a_zero_lag_keeps_the_runs_as_they_are():
    """An up stroke without a lag keeps each run's span as it is: z + 0.0 is z but for
    z = -0.0, which no grid position is (start_z + k z_step, k >= 0), not even at zero."""
    fab = fab_layout(paper_layout(PAPER))
    result = scan_layout(fab)
    assert all(r.unlatched == (r.z_in, r.z_out) for r in result.runs)
    for start in (-300.0, -0.0, 0.0):
        low = fab.with_scan(start_z=start, final_z=600.0, z_step=0.25)
        low = replace(low, wafers=low.wafers + (replace(low.wafers[0], name="Z",
                                                        center=(0.0, 400.0, -0.1)),))
        result = scan_layout(low)
        assert canon(result) == canon(plain_scan(low))
        assert any(r.unlatched[0] == 0.0 for r in result.runs)
        assert all(math.copysign(1.0, z) > 0.0 for r in result.runs for z in r.unlatched
                   if z == 0.0)
