"""SPEC §9 amended (issue 30): fab's scan_layout within 2x of its floor. The steps taken after the
fast paths of tests/core/test_fab_fast_paths.py give what their definitions give, bit for bit:

- the analytic engine's pass over the wafers does ``carrier_protrusions``' too
  (``analytic_stepped``): the same hits as ``analytic_engine`` and the same wafers and
  protrusions as ``carrier_protrusions``, or None where it leaves them to it (a tilted wafer,
  a scan that is not level);
- its runs, where the met wafers' intervals come in order and apart, are those intervals: the
  same as ``runs_from_intervals`` of its steps;
- ``stepped_records`` names a run by its one wafer where each run is one met wafer's steps in
  the layout's order and the spans are in order along Z: against ``run_wafers``, with spans
  that rounding brings together too (where it must not);
- ``slot_plan`` gives the recipe's fields in SlotPlan's order: the plan of ``recipe_fields``;
- a slot's runs are tuples from the start: ``map_slots`` against the judge, slot by slot;
- and scan_layout end to end against itself through the general paths (the engine given as a
  ``stepper``, its runs as a list: no shared pass, the names by bisection) on level layouts (no
  tilted wafer, a level beam), where these paths are taken; every field by its repr.

No timing here (the ratio is the bench's: waferscan/bench/fab_floor.py)."""

import math
import random
from dataclasses import fields, replace
from itertools import compress

from random_layouts import random_layout, shared_stacks
from scenarios import PAPER, fab_with

from waferscan.bench.workloads import fab_layout, paper_layout, stack_layout
from waferscan.core.mapping import EMPTY, SlotPlan, judge_run, map_slots
from waferscan.core.model import MappingTolerances, ScanParameters, Wafer
from waferscan.core.recipe import RECIPE_KEYS, recipe_fields
from waferscan.core.scan.engines import (
    StepHits,
    analytic_engine,
    analytic_stepped,
    runs_from_intervals,
)
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.scan.scan_result import (
    carrier_circle,
    carrier_protrusions,
    protruding_slots,
    run_wafers,
    slot_plan,
    stepped_intervals,
    stepped_records,
    wafer_records,
)

LEVEL = (0.0, 0.0, 1.0)
LEVEL_STATES = ("absent", "present", "present", "double", "thin", "misplaced", "protruding")


def level_only(layout):
    """The layout with its tilted wafers left out and its beam levelled, lifted along Z."""
    ex, ey, _ = layout.beam.direction
    norm = math.hypot(ex, ey)
    return replace(layout, lift_axis=LEVEL,
                   beam=replace(layout.beam, direction=(ex / norm, ey / norm, 0.0)),
                   wafers=tuple(w for w in layout.wafers if w.normal == LEVEL))


def layouts():
    paper = paper_layout(PAPER)
    fab = fab_layout(paper)
    yield "paper", paper  # tilted wafers: the protrusions are carrier_protrusions' own
    yield "fab", fab
    yield "fab-LP3", replace(fab, carrier="LP3")
    yield "fab-empty", replace(fab, wafers=())
    yield "stack", stack_layout(3)
    for seed in range(60):
        rng = random.Random(seed)
        load = [rng.choice(LEVEL_STATES) for _ in range(25)]
        layout = fab_with(load, foups=rng.choice([1, 2, 4]),
                          z_step=rng.choice([0.001, 0.05, 0.013, 0.5, 0.35]))
        if seed % 4 == 1:  # a bowed wafer: level, with the general edges
            wafers = list(layout.wafers)
            k = rng.randrange(len(wafers))
            wafers[k] = replace(wafers[k], bow=0.05)
            layout = replace(layout, wafers=tuple(wafers))
        yield f"fab{seed}", layout
    for seed in range(400):
        stacks = shared_stacks(random.Random(seed))
        yield f"stacks{seed}", stacks
        yield f"level-stacks{seed}", level_only(stacks)  # the shared pass taken
    for seed in range(300):
        layout = random_layout(random.Random(seed))
        yield f"random{seed}", layout
        yield f"level-random{seed}", level_only(layout)


def test_the_engine_pass_is_the_engine_and_the_carrier_protrusions():
    shared = apart = merged = 0
    for name, layout in layouts():
        if layout.scan.final_z < layout.scan.start_z:
            continue
        carrier = layout.scanned_carrier
        hits, inside = analytic_stepped(layout, carrier_circle(carrier))
        assert hits == analytic_engine(layout), name
        assert hits.runs == runs_from_intervals(hits.wafer_steps), name
        met = tuple(compress(hits.wafer_steps, hits.wafer_steps))
        apart += bool(met) and hits.runs == met
        merged += hits.runs != met
        level_scan = layout.lift_axis == LEVEL and layout.beam.direction[2] == 0.0
        if not level_scan or any(w.normal != LEVEL for w in layout.wafers):
            assert inside is None, name
            continue
        expected = carrier_protrusions(carrier, layout.wafers)
        assert repr(inside) == repr(expected) and inside == expected, name
        plan = slot_plan(carrier, layout.mapping)
        assert repr(protruding_slots(carrier, plan, layout.wafers, inside)) == \
            repr(protruding_slots(carrier, plan, layout.wafers)), name
        shared += 1
    assert shared > 300 and apart > 50 and merged > 300


def _records_by_definition(hits, scan, wafers):
    runs, spans = stepped_intervals(hits, scan, None)
    return runs, wafer_records(wafers, spans), run_wafers(runs, wafers, spans)


def test_a_run_of_one_wafer_names_it_alone_as_the_bisections_do():
    by_itself = 0
    for name, layout in layouts():
        if layout.scan.final_z < layout.scan.start_z:
            continue
        hits = analytic_engine(layout)
        found = stepped_records(hits, layout.scan, layout.wafers)
        assert repr(found) == repr(_records_by_definition(hits, layout.scan, layout.wafers)), \
            name
        met = tuple(compress(hits.wafer_steps, hits.wafer_steps))
        by_itself += bool(met) and met == hits.runs
    assert by_itself > 50


def test_spans_that_rounding_brings_together_are_named_by_the_bisections():
    """Runs apart on the grid (k apart by 2 and more) whose positions round to one float, or
    out of order: the wafer's span then meets the other run too, or the runs are reordered,
    and the names are ``run_wafers``'."""
    wafers = tuple(Wafer(f"W{i}", (0.0, 0.0, 0.0), LEVEL, 300.0, 0.7) for i in range(4))
    cases = [
        # ulp(1e16) = 2: start + 0.5 k rounds k = 0, 2 (and 4, 6) onto the same floats
        (ScanParameters(1e16, 1e16 + 8.0, 0.5), ((0, 0), (2, 2), None, (4, 5))),
        (ScanParameters(1e16, 1e16 + 8.0, 0.5), ((0, 1), None, (3, 3), (6, 6))),
        (ScanParameters(0.0, 10.0, 1.0), ((0, 1), (3, 4), None, (6, 6))),  # apart, as a fab
        (ScanParameters(0.0, 10.0, 1.0), ((3, 4), (0, 1), None, None)),  # out of order
        (ScanParameters(0.0, 10.0, 1.0), ((0, 3), (2, 5), None, (7, 7))),  # overlapping
        (ScanParameters(0.0, 10.0, -1.0), ((0, 1), (3, 4), None, None)),  # a falling grid
        (ScanParameters(0.0, 10.0, 1.0), ((1, 0), (3, 4), None, None)),  # first > last
    ]
    fast = 0
    for scan, steps in cases:
        for runs in (tuple(s for s in steps if s is not None),
                     runs_from_intervals(steps)):
            hits = StepHits(11, steps, runs)
            found = stepped_records(hits, scan, wafers)
            assert repr(found) == repr(_records_by_definition(hits, scan, wafers)), (scan, steps)
            fast += all(len(n) == 1 for n in found[2])
    assert fast > 2


def test_the_plan_takes_the_recipe_in_its_fields_order():
    assert tuple(f.name for f in fields(SlotPlan))[7:] == RECIPE_KEYS
    carrier = fab_layout(paper_layout(PAPER)).scanned_carrier
    for seed in range(200):
        rng = random.Random(seed)
        mapping = MappingTolerances(
            thickness_tolerance=rng.choice([None, 0.1]),
            position_tolerance=rng.uniform(0.1, 1.0), protrusion_limit=rng.uniform(0.1, 2.0),
            thickness_min=rng.choice([None, 0.5]), thickness_max=rng.choice([None, 0.9]),
            double_threshold=rng.choice([None, 1.6]), position_below=rng.choice([None, 0.3]),
            position_above=rng.choice([None, 0.7]), rules=rng.choice(["waferscan", "boundary"]),
            thickness_correction=rng.choice([1.0, 1.02]))
        expected = SlotPlan(
            slot_count=carrier.slot_count, pitch=carrier.pitch,
            first_slot_z=carrier.first_slot_z, wafer_thickness=carrier.wafer_thickness,
            thickness_tolerance=mapping.thickness_tolerance_for(carrier.wafer_thickness),
            position_tolerance=mapping.position_tolerance,
            protrusion_limit=mapping.protrusion_limit, **recipe_fields(mapping))
        assert repr(slot_plan(carrier, mapping)) == repr(expected)


def test_a_slots_runs_are_the_judges_findings_in_order():
    """map_slots' members as tuples from the first run on: each slot's runs, in order, are the
    runs whose findings name it (judge_run), and a slot without runs is empty."""
    for seed in range(1500):
        rng = random.Random(seed)
        t = rng.uniform(0.3, 1.2)
        plan = SlotPlan(rng.randint(1, 25), rng.choice([4.76, 10.0]), rng.uniform(0.0, 300.0),
                        t, 0.5 * t, rng.uniform(0.2, 1.0),
                        rules=rng.choice(["waferscan", "boundary"]))
        runs, z = [], plan.first_slot_z - plan.pitch
        for _ in range(rng.randint(0, 30)):
            z += rng.choice([0.0, rng.uniform(0.0, plan.pitch)])
            length = rng.choice([t, rng.uniform(0.0, 3.0 * plan.pitch)])
            runs.append((z, z + length))
            z += length
        slot_map = map_slots(plan, runs)
        for s in slot_map.slots:
            named = tuple(i for i, (bottom, top) in enumerate(runs)
                          if any(slot == s.slot for slot, _ in judge_run(plan, bottom, top)))
            assert type(s.runs) is tuple and s.runs == named, seed
            assert (s.state == EMPTY) == (not named), seed


def _general(layout, progress=None):
    """The analytic engine as a stepper, its runs as a list: scan_layout then takes no shared
    pass (the carrier's protrusions by ``carrier_protrusions``) and names the runs by
    bisection (a list is never the tuple of the met wafers' steps)."""
    hits = analytic_engine(layout)
    return replace(hits, runs=list(hits.runs))


def _fields(result):
    return repr((result.engine, result.plan, result.runs, result.wafers, result.slot_map,
                 result.protrusions, result.warnings, result.pockets, result.code))


def test_scan_layout_on_level_layouts_is_itself_through_the_general_paths():
    compared = 0
    for name, layout in layouts():
        if layout.scan.final_z < layout.scan.start_z:
            continue
        for direction, response in (("up", 0.0), ("down", 0.002)):
            scanned = layout.with_scan(direction=direction, sensor_response=response)
            assert _fields(scan_layout(scanned, "analytic")) == \
                _fields(scan_layout(scanned, "analytic", stepper=_general)), name
            compared += 1
    assert compared > 1500


def test_a_stepper_off_the_contract_is_named_by_the_bisections():
    # A second reader's cases: a stepper whose runs are an array, or whose steps have an entry
    # past the layout's wafers, takes the bisections as before (every run kept, the last one
    # naming no wafer; no array's ambiguous truth).
    import numpy as np

    fab = fab_layout(paper_layout(PAPER), foups=2, z_step=0.05)
    hits = analytic_engine(fab)
    extra = hits.wafer_steps + ((hits.count - 3, hits.count - 1),)
    longer = scan_layout(fab, "analytic", stepper=lambda layout, progress=None: replace(
        hits, wafer_steps=extra, runs=runs_from_intervals(extra)))
    assert len(longer.runs) == len(hits.runs) + 1 and longer.runs[-1].wafers == ()
    assert [r.wafers for r in longer.runs[:-1]] == \
        [r.wafers for r in scan_layout(fab, "analytic").runs]
    as_array = scan_layout(fab, "analytic", stepper=lambda layout, progress=None: replace(
        hits, runs=np.array(hits.runs)))
    assert as_array.code == scan_layout(fab, "analytic").code
