"""The array forms the sweep maps with, each against the scalar function beside it, layout by
layout and bit for bit: ``map_runs`` against ``map_slots`` (both rule sets), ``protruding_mask``
against ``protruding_slots`` and ``latch_runs`` against ``latcher``."""

import random
from dataclasses import replace

import numpy as np
import pytest

from waferscan.core import sweep
from waferscan.core.files.scenario import read_scenario
from waferscan.core.mapping import BOUNDARY, WAFERSCAN, map_runs, map_slots
from waferscan.core.model import DOWN, FAST, SLOW, UP, UPDOWN
from waferscan.core.scan.scan_result import (
    latch_runs,
    latcher,
    protruding_mask,
    protruding_slots,
    slot_plan,
)
from waferscan.core.sweep.distributions import parse_tolerances

PAPER = "resources/examples/paper.toml"

PROTRUDING = """
[seat_offset]
dist = "uniform"
lo = -0.7
hi = 0.7
[tilt]
dist = "uniform"
lo = 0.0
hi = 0.6
[bow]
dist = "uniform"
lo = -0.3
hi = 0.3
[protrusion]
dist = "uniform"
lo = 0.0
hi = 2.5
"""


def random_runs(rng, plan, count):
    """Up to ``count`` disjoint runs in ascending order around the plan's seats: single wafers
    seated high or low, thin, double, and runs across a boundary."""
    runs = []
    z = plan.first_slot_z - plan.pitch
    top_z = plan.first_slot_z + plan.slot_count * plan.pitch
    t = plan.wafer_thickness
    while len(runs) < count and z < top_z:
        z += rng.uniform(0.2, 1.6) * plan.pitch
        length = rng.choice([t, t, 0.4 * t, 2.0 * t, rng.uniform(0.1, 3.0) * plan.pitch])
        bottom = z + rng.uniform(-1.0, 1.0)
        runs.append((bottom, bottom + length))
        z = bottom + length
    return runs


@pytest.mark.parametrize("rules", [WAFERSCAN, BOUNDARY])
def test_map_runs_is_map_slots_layout_by_layout(rules):
    layout = read_scenario(PAPER)
    plan = slot_plan(layout.scanned_carrier, layout.mapping)
    plan = replace(plan, rules=rules)
    rng = random.Random(17)
    layouts = [random_runs(rng, plan, rng.randint(0, 30)) for _ in range(400)]
    width = max(len(r) for r in layouts)
    bottom = np.zeros((len(layouts), width))
    top = np.zeros((len(layouts), width))
    ok = np.zeros((len(layouts), width), dtype=bool)
    for i, runs in enumerate(layouts):
        for j, (b, t) in enumerate(runs):
            bottom[i, j], top[i, j], ok[i, j] = b, t, True
    states, first_run = map_runs(plan, bottom, top, ok)
    seen = set()
    for i, runs in enumerate(layouts):
        slot_map = map_slots(plan, runs)
        assert [s.state for s in slot_map.slots] == states[i].tolist(), i
        assert [s.runs[0] if s.runs else width for s in slot_map.slots] == first_run[i].tolist()
        seen.update(s.state for s in slot_map.slots)
    assert seen == {0, 1, 2, 3, 4, 5}  # every state a scan can report, protrusion aside


def test_protruding_mask_is_protruding_slots_layout_by_layout():
    base = sweep.sweep_base(read_scenario(PAPER))
    draws = sweep.draw_block(base, parse_tolerances(PROTRUDING), 5, 0, 300)
    m, S = draws.truth.shape
    W = 2 * S
    mask = protruding_mask(base.carrier, base.plan, draws.exists.reshape(m, W),
                           draws.center.reshape(m, W, 3), draws.normal.reshape(m, W, 3),
                           draws.thickness.reshape(m, W), draws.bow.reshape(m, W))
    for i in range(m):
        layout = sweep.sample_layout(base, draws, i)
        slots, _ = protruding_slots(base.carrier, base.plan, layout.wafers)
        assert sorted(np.flatnonzero(mask[i]) + 1) == slots, i
    assert 0.1 * mask.size < mask.sum() < 0.9 * mask.size  # some slots protrude, some do not


@pytest.mark.parametrize("mode,direction", [(FAST, UP), (FAST, DOWN), (FAST, UPDOWN),
                                            (SLOW, UP)])
def test_latch_runs_is_latcher(mode, direction):
    layout = read_scenario(PAPER)
    rng = np.random.default_rng(2)
    bottom = rng.uniform(290.0, 540.0, size=(50, 7))
    top = bottom + rng.uniform(0.0, 12.0, size=(50, 7))
    # the scan's own lag, then a lag per layout as a sweep draws the sensor's response
    responses = rng.uniform(0.0, 0.004, size=50)
    scan = replace(layout.scan, mode=mode, direction=direction, sensor_response=0.0023)
    lag = np.array([[replace(scan, sensor_response=float(r)).latch_lag] for r in responses])
    for lags, scans in ((None, [scan] * 50),
                        (lag, [replace(scan, sensor_response=float(r)) for r in responses])):
        got_bottom, got_top = latch_runs(bottom, top, scan, lags)
        for i in range(50):
            at = latcher(scans[i])
            for j in range(7):
                a, b = at(float(bottom[i, j]), float(top[i, j]))
                assert (min(a, b), max(a, b)) == (got_bottom[i, j], got_top[i, j])
        assert not np.array_equal(got_bottom, bottom) or mode == SLOW or direction == UPDOWN
