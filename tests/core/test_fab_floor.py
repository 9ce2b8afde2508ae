"""SPEC §9 amended (issue 30): the floor of fab's scan_layout (waferscan/bench/fab_floor.py) does
the same work as scan_layout, so the bench's ratio between them is honest: the same slot code,
runs and wafer intervals on fab and on variations of it. And the paths scan_layout took to get
nearer that floor give what their plain definitions give, bit for bit. No timing here."""

import math
import random
from dataclasses import replace

import pytest
from random_layouts import random_layout
from scenarios import PAPER, fab_with

from waferscan.bench.fab_floor import fab_floor_inputs, scan_plainly
from waferscan.bench.workloads import paper_layout
from waferscan.core.mapping import (
    BOUNDARY,
    EMPTY,
    SlotPlan,
    _land_by_bottom_edge,
    _land_runs,
    map_slots,
)
from waferscan.core.scan.engines import (
    analytic_engine,
    level_edger,
    reachable_wafers,
    settler,
    snap_to_grid,
    wafer_edges,
)
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.scan.scan_result import (
    run_wafers,
    stepped_intervals,
    stepped_records,
    wafer_records,
)

STATES = ("absent", "present", "double", "thin", "misplaced", "protruding")


def assert_floor_is_scan_layout(layout):
    code, runs, intervals = scan_plainly(**fab_floor_inputs(layout))
    result = scan_layout(layout)
    assert code == result.code
    assert runs == [(r.z_in, r.z_out, r.wafers) for r in result.runs]
    assert intervals == {w.name: (w.z_in, w.z_out) for w in result.wafers if w.z_in is not None}
    return result


def test_the_floor_is_scan_layout_on_fab():
    result = assert_floor_is_scan_layout(fab_with())
    assert result.code == "1" * 25 and len(result.runs) == 25
    assert result.runs[0].z_in == 293.94 and result.runs[0].z_out == 294.64


@pytest.mark.parametrize("step", [0.05, 0.013, 0.0007, 0.5])
def test_the_floor_is_scan_layout_at_other_steps(step):
    assert_floor_is_scan_layout(fab_with(z_step=step))


def test_the_floor_is_scan_layout_with_every_finding_of_a_level_load():
    states = ["present", "absent", "double", "thin", "misplaced", "protruding"] * 4 + ["present"]
    result = assert_floor_is_scan_layout(fab_with(states))
    assert set(result.code) == set("013456")  # every state a level wafer can give


@pytest.mark.parametrize("seed", range(12))
def test_the_floor_is_scan_layout_on_random_level_loads(seed):
    rng = random.Random(seed)
    states = [rng.choice(STATES) for _ in range(25)]
    layout = fab_with(states, foups=rng.choice([1, 2, 4]), z_step=rng.choice([0.001, 0.05]))
    assert_floor_is_scan_layout(layout)


def test_the_floor_is_scan_layout_where_the_scan_misses_slots():
    # from 300 mm up: slot 1's window (288.94 to 298.94) and part of its wafer are not scanned
    result = assert_floor_is_scan_layout(fab_with(start_z=300.0, final_z=500.0))
    assert result.code.startswith("??") and "?" in result.code[-5:]


def test_the_floor_refuses_what_it_does_not_cover():
    paper = paper_layout(PAPER)  # cross-slotted wafers are tilted
    with pytest.raises(ValueError, match="level wafers"):
        fab_floor_inputs(paper)
    with pytest.raises(ValueError, match="level wafers"):
        fab_floor_inputs(fab_with(direction="down", sensor_response=0.001))


# --- the paths toward the floor against their plain definitions ------------------------------

def test_stepped_records_are_the_intervals_records_and_names_one_by_one():
    compared = named = 0
    for seed in range(300):
        layout = random_layout(random.Random(seed))
        hits = analytic_engine(layout.with_scan(z_step=layout.scan.z_step))
        if seed % 7 == 0:  # runs not in ascending order (a stepper's), the general branch
            hits = replace(hits, runs=tuple(reversed(hits.runs)))
        runs, records, names = stepped_records(hits, layout.scan, layout.wafers)
        expected_runs, expected_spans = stepped_intervals(hits, layout.scan, None)
        assert runs == expected_runs
        # the spans it does not make: None where the steps are
        assert [s is None for s in expected_spans] == [s is None for s in hits.wafer_steps]
        assert records == wafer_records(layout.wafers, expected_spans)
        assert names == run_wafers(expected_runs, layout.wafers, expected_spans)
        compared += 1
        named += sum(len(n) for n in names)
    assert compared == 300 and named > 300


def _plan(rng, rules):
    t = rng.uniform(0.3, 1.2)
    recipe = {}
    if rng.random() < 0.5:
        recipe = {"thickness_min": t * rng.uniform(0.3, 0.9),
                  "thickness_max": t * rng.uniform(1.1, 1.8),
                  "double_threshold": t * rng.uniform(1.9, 3.0),
                  "position_below": rng.uniform(0.1, 1.0),
                  "position_above": rng.uniform(0.1, 1.0)}
    return SlotPlan(slot_count=rng.randint(1, 25), pitch=rng.choice([4.76, 6.35, 10.0]),
                    first_slot_z=rng.uniform(0.0, 300.0), wafer_thickness=t,
                    thickness_tolerance=0.5 * t, position_tolerance=rng.uniform(0.2, 1.0),
                    rules=rules, thickness_correction=rng.choice([1.0, 1.0, 1.03]), **recipe)


def test_landing_by_the_bottom_edge_is_the_judge_run_by_run():
    landed = 0
    for seed in range(2000):
        rng = random.Random(seed)
        plan = _plan(rng, "waferscan")
        runs, z = [], plan.first_slot_z - 2.0 * plan.pitch
        for _ in range(rng.randint(0, 30)):
            z += rng.choice([0.0, rng.uniform(0.0, plan.pitch)])
            if rng.random() < 0.3:  # a seat to the last place, or a length at a limit
                z = plan.seat_z(rng.randint(0, plan.slot_count + 1))
            length = rng.choice([plan.wafer_thickness, rng.uniform(0.0, 3.5 * plan.pitch),
                                 plan.double_limit(), plan.thickness_window()[1]])
            runs.append((z, z + length))
            z += length + rng.uniform(0.0, plan.pitch)
        fast = ([EMPTY] * (plan.slot_count + 1), [None] * (plan.slot_count + 1))
        plain = ([EMPTY] * (plan.slot_count + 1), [None] * (plan.slot_count + 1))
        _land_by_bottom_edge(plan, runs, *fast)
        _land_runs(plan, runs, *plain)
        assert fast == plain, seed
        landed += sum(1 for m in plain[1] if m)
    assert landed > 5000


def test_the_slot_map_under_boundary_rules_takes_the_judge():
    rng = random.Random(5)
    plan = _plan(rng, BOUNDARY)
    runs = [(plan.seat_z(1), plan.seat_z(1) + plan.wafer_thickness)]
    assert map_slots(plan, runs).slots[0].runs == (0,)


def test_the_stepped_engine_is_the_level_edges_then_settled_or_snapped():
    """analytic_engine's stepped loop against what it writes out: level_edger's edges (the
    general ones for a tilted or bowed wafer), then settler's steps, else snap_to_grid."""
    met = 0
    for seed in range(400):
        layout = random_layout(random.Random(seed))
        if seed % 2:  # a level beam lifted along Z: the written-out path
            ex, ey, _ = layout.beam.direction
            norm = math.hypot(ex, ey)
            layout = replace(layout, lift_axis=(0.0, 0.0, 1.0),
                             beam=replace(layout.beam, direction=(ex / norm, ey / norm, 0.0)))
        level_scan = layout.lift_axis == (0.0, 0.0, 1.0) and layout.beam.direction[2] == 0.0
        edges, settled = level_edger(layout), settler(layout)
        expected = [None] * len(layout.wafers)
        for i in reachable_wafers(layout):
            wafer = layout.wafers[i]
            level = level_scan and wafer.normal == (0.0, 0.0, 1.0)
            edge = edges(wafer) if level and not wafer.bow else wafer_edges(layout, wafer)
            if edge is not None:
                expected[i] = (level and settled(edge)) or snap_to_grid(layout, wafer, edge)
        assert analytic_engine(layout).wafer_steps == tuple(expected), seed
        met += sum(1 for e in expected if e is not None)
    assert met > 1000
