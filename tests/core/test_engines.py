"""The engines agree exactly with each other, the exact edges are exact, and the accessibility
check never drops a wafer the beam can hit."""

import random
from dataclasses import replace

import numpy as np
import pytest
from random_layouts import random_layout

from waferscan.core.geometry.beam import accessible, beam_hits_wafer
from waferscan.core.model import Beam, Carrier, Layout, ScanParameters, Wafer
from waferscan.core.scan.engines import (
    StepHits,
    analytic_engine,
    loop_engine,
    run_engine,
    runs_from_blocked,
    runs_from_intervals,
    vector_engine,
    wafer_edges,
)

SEEDS = range(400)


def test_engines_agree_on_random_layouts():
    """loop, vector (in small and large chunks) and analytic give identical stepped results
    (the loop's reference worked out once a layout: it is most of the time)."""
    blocked_steps = 0
    for seed in SEEDS:
        layout = random_layout(random.Random(seed))
        reference = loop_engine(layout)
        for chunk in (10, 2_000_000):
            assert vector_engine(layout, chunk_elements=chunk) == reference, \
                f"seed {seed}, chunks of {chunk}"
        assert analytic_engine(layout) == reference, f"seed {seed}"
        blocked_steps += sum(b - a + 1 for a, b in reference.runs)
    assert blocked_steps > 10_000  # the layouts do put wafers in the beam's way


def test_runs_are_the_union_of_wafer_intervals():
    for seed in range(100):
        hits = loop_engine(random_layout(random.Random(seed)))
        blocked = np.zeros(hits.count, dtype=bool)
        for steps in hits.wafer_steps:
            if steps is not None:
                blocked[steps[0]:steps[1] + 1] = True
        assert runs_from_blocked(blocked) == hits.runs


def _hit_at(layout, wafer, z):
    return beam_hits_wafer(layout.emitter_at(z), layout.beam, wafer)


def test_exact_edges_bracket_the_hits():
    """Just outside each closed-form edge the exact test misses, just inside it hits."""
    checked = 0
    for seed in range(200):
        layout = random_layout(random.Random(seed))
        for wafer in layout.wafers:
            edges = wafer_edges(layout, wafer)
            if edges is None:
                continue
            lo, hi = edges
            assert not _hit_at(layout, wafer, lo - 1e-7)
            assert not _hit_at(layout, wafer, hi + 1e-7)
            if hi - lo > 2e-7:
                assert _hit_at(layout, wafer, lo + 1e-7)
                assert _hit_at(layout, wafer, hi - 1e-7)
            checked += 1
    assert checked > 1000


def test_wafers_without_edges_are_never_hit():
    for seed in range(60):
        layout = random_layout(random.Random(seed))
        scan = layout.scan
        for wafer in layout.wafers:
            if wafer_edges(layout, wafer) is None:
                assert not any(_hit_at(layout, wafer, scan.position(k))
                               for k in range(scan.position_count))


def test_exact_mode_edges_match_the_stepped_limit():
    """With z_step = 0 the analytic engine gives the continuous runs; a fine step converges."""
    compared = 0
    for seed in range(20):
        layout = random_layout(random.Random(seed))
        exact = analytic_engine(layout.with_scan(z_step=0.0))
        fine = layout.with_scan(z_step=0.001)
        stepped = analytic_engine(fine)
        # Runs closer than a step merge on the grid; compare layouts where none do.
        if len(exact.runs) != len(stepped.runs):
            continue
        for (lo, hi), (k_lo, k_hi) in zip(exact.runs, stepped.runs):
            assert fine.scan.position(k_lo) - 0.001 <= lo <= fine.scan.position(k_lo) + 1e-9
            assert fine.scan.position(k_hi) - 1e-9 <= hi <= fine.scan.position(k_hi) + 0.001
            compared += 1
    assert compared > 20


def test_accessibility_never_drops_a_wafer_the_beam_can_hit():
    dropped = 0
    for seed in range(300):
        layout = random_layout(random.Random(seed))
        scan = layout.scan
        for wafer in layout.wafers:
            if accessible(layout, wafer, scan.start_z, scan.final_z):
                continue
            dropped += 1
            edges = wafer_edges(layout, wafer)
            assert edges is None or edges[1] < scan.start_z or edges[0] > scan.final_z
            assert not any(_hit_at(layout, wafer, scan.position(k))
                           for k in range(0, scan.position_count, 7))
    assert dropped > 100  # other carriers' wafers and far free wafers are dropped


def test_accessibility_keeps_a_wafer_grazed_at_the_end_of_the_travel():
    """A wafer touched only at the very last step, at the very tip of the beam, is kept."""
    wafer = Wafer("W", (100.0, 0.0, 50.0), (0.0, 0.0, 1.0), 200.0, 0.7)
    carrier = Carrier("C", 1, 10.0, 50.0, (100.0, 0.0), 200.0, 0.7)
    beam = Beam((-60.0, 0.0, 0.0), (1.0, 0.0, 0.0), 60.0)  # receiver at x = 0, the wafer's rim
    layout = Layout((carrier,), (wafer,), beam, ScanParameters(0.0, 50.0, 0.5))
    assert accessible(layout, wafer, 0.0, 50.0)
    assert loop_engine(layout).wafer_steps == ((100, 100),)
    far = replace(layout, beam=replace(beam, length=59.99))
    assert loop_engine(far).wafer_steps == (None,)


def test_touching_counts_as_blocked():
    """A wafer whose bottom face lies exactly at a stepped position is blocked there, and a beam
    whose end point touches the rim is blocked (tolerance 1e-9 mm)."""
    wafer = Wafer("W", (0.0, 0.0, 10.0), (0.0, 0.0, 1.0), 100.0, 1.0)
    carrier = Carrier("C", 1, 10.0, 10.0, (0.0, 0.0), 100.0, 1.0)
    beam = Beam((-100.0, 0.0, 0.0), (1.0, 0.0, 0.0), 50.0)  # ends exactly on the rim
    layout = Layout((carrier,), (wafer,), beam, ScanParameters(0.0, 20.0, 0.5))
    for name in ("loop", "vector", "analytic"):
        assert run_engine(name, layout).wafer_steps == ((20, 22),), name
    short = replace(layout, beam=replace(beam, length=50.0 - 1e-6))
    for name in ("loop", "vector", "analytic"):
        assert run_engine(name, short).wafer_steps == (None,), name


def test_grid_formula():
    scan = ScanParameters(280.0, 550.0, 0.05)
    assert scan.position_count == 5401
    assert scan.position(5400) == pytest.approx(550.0)
    assert ScanParameters(0.0, 1.0, 0.3).position_count == 4  # 0, .3, .6, .9
    assert ScanParameters(0.0, 0.9, 0.3).position_count == 4  # 0.9 kept despite rounding


def test_union_of_intervals_merges_adjacent_steps():
    assert runs_from_intervals([(5, 7), None, (8, 9), (1, 2), (12, 12)]) == ((1, 2), (5, 9),
                                                                            (12, 12))
    assert runs_from_blocked([True, True, False, True]) == ((0, 1), (3, 3))
    assert runs_from_blocked([]) == ()


def test_stepped_engines_refuse_exact_mode_and_unknown_names():
    layout = random_layout(random.Random(3)).with_scan(z_step=0.0)
    with pytest.raises(ValueError, match="analytic"):
        loop_engine(layout)
    with pytest.raises(ValueError, match="unknown engine"):
        run_engine("magic", layout)
    assert isinstance(analytic_engine(layout.with_scan(z_step=0.5)), StepHits)
