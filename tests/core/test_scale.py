"""Fab-scale paths give the answers of their plain definitions: the accessibility check over
many wafers, the naming of each sensor run by the wafers that caused it, and the vector
engine's memory bound. (How fast they are is `waferscan bench`'s business, not a test's.)"""

import random
import tracemalloc
from dataclasses import replace

import pytest
from random_layouts import random_layout

from waferscan.addon import paper_scenario
from waferscan.bench import fab_layout, stack_layout
from waferscan.core.files.scenario import read_scenario
from waferscan.core.geometry.beam import accessible, accessible_wafers
from waferscan.core.model import Wafer
from waferscan.core.scan.engines import StepHits, loop_engine, run_engine, vector_engine
from waferscan.core.scan.layout_scan import scan_layout


def test_accessible_wafers_is_the_accessibility_check_wafer_by_wafer():
    kept = dropped = 0
    for seed in range(300):
        rng = random.Random(seed)
        layout = random_layout(rng)
        scan = layout.scan
        for z_from, z_to in ((scan.start_z, scan.final_z),
                             (rng.uniform(scan.start_z, scan.final_z),) * 2,
                             (scan.final_z, rng.uniform(scan.start_z - 20, scan.final_z))):
            expected = [i for i, w in enumerate(layout.wafers)
                        if accessible(layout, w, z_from, z_to)]
            assert accessible_wafers(layout, layout.wafers, z_from, z_to) == expected, seed
            kept += len(expected)
            dropped += len(layout.wafers) - len(expected)
    assert kept > 500 and dropped > 500  # both answers were exercised


def _named_by_definition(layout, hits):
    """Each run's wafers as SPEC §3 defines them: every wafer whose steps overlap the run's."""
    names = []
    for first, last in hits.runs:
        names.append(tuple(w.name for w, span in zip(layout.wafers, hits.wafer_steps)
                           if span is not None and span[0] <= last and span[1] >= first))
    return names


def test_each_run_is_named_by_the_wafers_that_overlap_it():
    """Random runs and wafer intervals, overlapping anyhow (a wafer across two runs, runs with
    no wafer, wafers in no run): the names are the definition's, in the layout's order."""
    layout = read_scenario(paper_scenario())
    count = layout.scan.position_count
    checked = 0
    for seed in range(300):
        rng = random.Random(seed)
        cuts = sorted(rng.sample(range(count), 2 * rng.randint(0, 8)))
        runs = tuple((a, b) for a, b in zip(cuts[::2], cuts[1::2]) if b > a + 1)
        steps = []
        for _ in layout.wafers:
            if rng.random() < 0.2:
                steps.append(None)
            else:
                a = rng.randrange(count)
                steps.append((a, min(count - 1, a + rng.choice([0, 3, 50, 900]))))
        hits = StepHits(count, tuple(steps), runs)
        result = scan_layout(layout, "bench", stepper=lambda lay, progress: hits)
        assert [r.wafers for r in result.runs] == _named_by_definition(layout, hits), seed
        checked += sum(len(r.wafers) for r in result.runs)
    assert checked > 300


def test_a_stack_of_foups_names_every_run_by_its_own_wafer():
    layout = stack_layout(40)  # 1,000 wafers, every one in the beam's way
    result = scan_layout(layout)
    assert len(result.runs) == 1_000
    assert [r.wafers for r in result.runs] == [(w.name,) for w in layout.wafers]
    assert result.code == "1" * 25


def test_the_vector_engine_bounds_its_memory():
    """270,001 positions x 25 reachable wafers: numpy's peak stays near the chunk's ~16 MB
    (chunks of 2 million elements peaked at 310 MB), and the result is analytic's."""
    fab = fab_layout(read_scenario(paper_scenario()))
    tracemalloc.start()
    try:
        hits = vector_engine(fab)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 40e6
    assert hits == run_engine("analytic", fab)


@pytest.mark.parametrize("z_step", [0.05, 0.002])
def test_level_wafers_settled_without_a_test_agree_with_loop(z_step):
    """The analytic engine places a level wafer's steps without testing the positions next to
    its edges when none is near them. Seats on the grid, and off it by a touch tolerance or a
    few rounding units either way: the same steps as loop, position for position."""
    base = read_scenario(paper_scenario())
    offsets = [0.0, 1e-9, -1e-9, 2e-9, -2e-9, 1e-12, -1e-12, 5e-10, 1e-7, -1e-7, 0.3 * z_step]
    carrier = base.scanned_carrier
    wafers = []
    for slot, offset in enumerate(offsets, start=1):
        seat = base.scan.start_z + round((carrier.seat_z(slot) - base.scan.start_z) / z_step) \
            * z_step + offset
        wafers.append(Wafer(name=f"W{slot}", center=(carrier.center[0], carrier.center[1], seat),
                            normal=(0.0, 0.0, 1.0), diameter=carrier.wafer_diameter,
                            thickness=round(0.7 / z_step) * z_step))
    layout = replace(base, wafers=tuple(wafers), robot=None,
                     scan=replace(base.scan, z_step=z_step, final_z=carrier.seat_z(13)))
    assert run_engine("analytic", layout) == loop_engine(layout)
