"""Sweeps with a beam spot (core/sweep/spot_scan.py): the array translation ranges
(core/geometry/ranges.py) are the scalar ``translation_range``'s floats bit for bit, and a block
of sampled layouts with a tilted beam, tilted wafers and a 1 mm spot maps exactly as the scalar
path maps each layout."""

from dataclasses import replace

import numpy as np
import pytest
from scenarios import SWEEP_TOLERANCES, beams_and_wafers

from waferscan.core.files.scenario import read_scenario
from waferscan.core.geometry.beam import TOUCH_TOLERANCE
from waferscan.core.geometry.ranges import translation_range, translation_ranges
from waferscan.core.mapping import BOUNDARY, WAFERSCAN
from waferscan.core.sensor import spot as spot_module
from waferscan.core.sensor.spot import Amplifier, BeamSpot
from waferscan.core import sweep
from waferscan.core.sweep import spot_scan as sweep_spot
from waferscan.core.sweep.distributions import parse_tolerances

PAPER = "resources/examples/paper.toml"

TILTED = SWEEP_TOLERANCES  # every quantity varied, every state placed


def spot_paper(**changes):
    return replace(read_scenario(PAPER), spot=BeamSpot(diameter=1.0), **changes)


@pytest.mark.parametrize("tol", [0.0, TOUCH_TOLERANCE])
def test_array_ranges_are_the_scalar_functions_bit_for_bit(tol):
    rng = np.random.default_rng(7)
    axis = (0.0, 0.0, 1.0)
    covered_count = 0
    every = beams_and_wafers(rng, 1200)
    for length in (400.0, 250.0, 120.0):
        cases = [c for c in every if c[1].length == length]
        emitter = np.array([c[0] for c in cases])
        direction = np.array([c[1].direction for c in cases])
        center = np.array([c[2].center for c in cases])
        normal = np.array([c[2].normal for c in cases])
        radius = np.array([c[2].radius for c in cases])
        thickness = np.array([c[2].thickness for c in cases])
        lo, hi, hit, covered = translation_ranges(
            emitter, direction, axis, center, normal, radius, thickness, length, tol)
        hits = 0
        for j, (e, beam, wafer) in enumerate(cases):
            expected = translation_range(e, beam, axis, wafer, tol=tol)
            if not covered[j]:
                continue
            covered_count += 1
            if expected is None:
                assert not hit[j]
            else:
                hits += 1
                assert hit[j] and (lo[j], hi[j]) == expected  # exact, not approximate
        assert hits > len(cases) // 3
    # Only the level beam over a level wafer (a quarter) takes the scalar closed form.
    assert covered_count >= 0.7 * len(every)


def test_range_table_holds_the_spot_engines_own_column_ranges():
    base = sweep.sweep_base(spot_paper())
    draws = sweep.draw_block(base, parse_tolerances(TILTED), 3, 0, 20)
    layouts = [sweep.sample_layout(base, draws, i) for i in range(20)]
    spot = base.layout.spot
    table = sweep_spot.range_table(layouts, spot)
    offsets = sweep_spot.column_offsets(spot)
    assert len(offsets) == 2 * spot_module.COLUMNS + 1
    found = 0
    for layout in layouts:
        ranges = [spot_module.column_ranges(layout, w, spot) for w in layout.wafers]
        u = spot_module.spot_frame(layout.beam.direction, layout.lift_axis)[0]
        ox, oy, oz = layout.beam.emitter
        for wafer, columns in zip(layout.wafers, ranges):
            index, in_order = table[(id(wafer), id(layout.beam))]
            for j, (s, listed) in enumerate(zip(offsets, in_order)):
                expected = translation_range((ox + s * u[0], oy + s * u[1], oz + s * u[2]),
                                             layout.beam, layout.lift_axis, wafer, tol=0.0)
                assert index[s] == j and listed == expected
                found += expected is not None
            assert columns == in_order[:spot_module.COLUMNS + 1]
    assert found > 1000


def block_pair(layout, tolerances, seed, count, rules=None):
    base = sweep.sweep_base(layout, rules=rules)
    draws = sweep.draw_block(base, tolerances, seed, 0, count)
    fast_peaks, slow_peaks = [], []
    fast = sweep.spot_block(base, draws, fast_peaks)
    slow = sweep.scalar_block(base, draws, slow_peaks)
    return base, draws, (fast, fast_peaks), (slow, slow_peaks)


def assert_same(fast, slow):
    (f, f_peaks), (s, s_peaks) = fast, slow
    for a, b in zip(f, s):
        assert np.array_equal(a, b, equal_nan=True)
    assert f_peaks == s_peaks  # every group's peak blocked fraction, bit for bit


@pytest.mark.parametrize("rules", [WAFERSCAN, BOUNDARY])
def test_spot_block_equals_the_scalar_path_with_a_tilted_beam(rules, monkeypatch):
    calls = []
    scalar_range = spot_module.translation_range

    def counted(*args, **kwargs):
        calls.append(args)
        return scalar_range(*args, **kwargs)

    monkeypatch.setattr(spot_module, "translation_range", counted)
    base, draws, fast, slow = block_pair(spot_paper(), parse_tolerances(TILTED), 11, 150,
                                         rules)
    scalar_calls = len(calls)
    calls.clear()
    sweep.spot_block(base, draws)
    # The table answered (nearly) every column: the array path is what ran.
    assert len(calls) < 0.01 * scalar_calls
    assert_same(fast, slow)
    states = fast[0][0]
    # Every kind of finding occurred: the comparison is not of empty carriers.
    assert {int(c) for c in np.unique(states)} >= {0, 1, 2, 3, 4}


@pytest.mark.parametrize("on, off", [(0.5, None), (0.6, 0.3), (0.3, 0.1)])
def test_spot_block_equals_the_scalar_path_for_thresholds_and_hysteresis(on, off):
    layout = spot_paper(amplifier=Amplifier(on, off))
    tolerances = parse_tolerances(TILTED + """
[threshold_on]
dist = "uniform"
lo = 0.15
hi = 0.85
""")
    _, _, fast, slow = block_pair(layout, tolerances, 5, 100)
    assert_same(fast, slow)
    # Without drawn thresholds too (the layout's amplifier, hysteresis kept).
    _, _, fast, slow = block_pair(layout, parse_tolerances(TILTED), 6, 60)
    assert_same(fast, slow)


def test_spot_block_equals_the_scalar_path_for_a_slit_and_updown_strokes():
    layout = replace(read_scenario(PAPER), spot=BeamSpot(width=2.0, height=0.6))
    layout = layout.with_scan(direction="updown")
    _, _, fast, slow = block_pair(layout, parse_tolerances(TILTED), 8, 60)
    assert_same(fast, slow)


def test_spot_sweep_summary_equals_the_scalar_paths():
    layout = spot_paper()
    tolerances = parse_tolerances(TILTED)
    base = sweep.sweep_base(layout)
    fast = sweep.sweep_block(base, tolerances, 2, 0, 40)
    slow = sweep.sweep_block(base, tolerances, 2, 0, 40, scalar=True)
    assert fast.keys() == slow.keys()
    for key in fast:
        if key == "weakest_peak":
            assert fast[key] == slow[key] < 1.0
        else:
            assert np.array_equal(fast[key], slow[key], equal_nan=True)


def test_round_spot_fraction_is_grouped_fraction_bit_for_bit():
    """The sort-free area of a round spot against spot.GroupedFraction, at translations across
    every group's reach and beyond, groups of one wafer and of several (doubles, cross)."""
    base = sweep.sweep_base(spot_paper())
    draws = sweep.draw_block(base, parse_tolerances(TILTED), 9, 0, 30)
    rng = np.random.default_rng(3)
    compared = 0
    for i in range(30):
        layout = sweep.sample_layout(base, draws, i)
        groups = spot_module.wafer_groups(layout, layout.wafers, layout.spot)
        fractions = [spot_module.BlockedFraction(layout, [layout.wafers[j] for j in members],
                                                 layout.spot, ranges)
                     for members, ranges, _ in groups]
        scalar = spot_module.GroupedFraction(fractions)
        fast = sweep_spot.RoundSpotFraction(fractions)
        owner = np.repeat(np.arange(len(groups)), 60)
        tau = np.concatenate([rng.uniform(lo - 0.3, hi + 0.3, 60) for _, _, (lo, hi) in groups])
        expected = scalar(tau, owner)
        assert np.array_equal(fast(tau, owner), expected)
        compared += int(((expected > 0.0) & (expected < 1.0)).sum())
    assert compared > 10000


def test_the_lean_path_runs_and_builds_most_groups_from_the_table(monkeypatch):
    built = []
    blocked = spot_module.BlockedFraction

    def counted(*args, **kwargs):
        built.append(len(args[1]))
        return blocked(*args, **kwargs)

    monkeypatch.setattr(spot_module, "BlockedFraction", counted)
    base = sweep.sweep_base(spot_paper())
    draws = sweep.draw_block(base, parse_tolerances(TILTED), 12, 0, 40)
    layouts = [sweep.sample_layout(base, draws, i) for i in range(40)]
    assert all(sweep_spot.lean_spot_path(layout) for layout in layouts)
    table = sweep_spot.range_table(layouts, base.layout.spot)
    groups, lean_built = 0, []
    for layout in layouts:
        built.clear()
        runs, peaks = sweep_spot.spot_runs(layout, table)
        lean_built += built
        groups += len(peaks)
        # The runs are the scalar scan's, edge for edge.
        assert [(r.z_in, r.z_out, r.wafers) for r in runs] == \
            [(r.z_in, r.z_out, r.wafers) for r in scan_layout_runs(layout)]
    # BlockedFraction's own search for the groups of several wafers (doubles, cross) and the
    # few single wafers with a strip to halve; the rest from the table.
    assert 0 < len(lean_built) < 0.2 * groups
    assert sum(n == 1 for n in lean_built) < 0.05 * groups, (lean_built, groups)


def scan_layout_runs(layout):
    from waferscan.core.scan.layout_scan import scan_layout

    return scan_layout(layout).runs


def test_spot_block_equals_the_scalar_path_with_a_level_beam():
    """A level beam over level wafers: every strip's limits are the faces', each strip's piece
    continues the one before (BlockedFraction merges them into one), built strip by strip;
    tilted wafers beside them take the conic's corners."""
    level = "\n".join(line for line in TILTED.split("[beam_tilt]")[0].splitlines()) + """
[states]
present = 0.6
empty = 0.1
cross = 0.1
double = 0.1
thin = 0.1
"""
    tolerances = parse_tolerances(level)
    assert "beam_tilt" not in tolerances.quantities
    _, draws, fast, slow = block_pair(spot_paper(), tolerances, 21, 120)
    assert np.all(draws.direction == draws.direction[0])
    assert_same(fast, slow)


@pytest.mark.parametrize("shape", [BeamSpot(diameter=1.0), BeamSpot(width=2.0, height=0.6)])
def test_block_fraction_is_grouped_fraction_bit_for_bit(shape):
    """The block's one evaluation of every group of several layouts (each with its own beta)
    against spot.GroupedFraction of each layout alone."""
    base = sweep.sweep_base(replace(read_scenario(PAPER), spot=shape))
    draws = sweep.draw_block(base, parse_tolerances(TILTED), 13, 0, 12)
    rng = np.random.default_rng(5)
    block = sweep_spot._BlockFraction(shape)
    taus, owners, expected = [], [], []
    for i in range(12):
        layout = sweep.sample_layout(base, draws, i)
        beta = spot_module.spot_frame(layout.beam.direction, layout.lift_axis)[3]
        groups = spot_module.wafer_groups(layout, layout.wafers, shape)
        fractions = [spot_module.BlockedFraction(layout, [layout.wafers[j] for j in members],
                                                 shape, ranges)
                     for members, ranges, _ in groups]
        index = [block.add(beta, [getattr(f, n) for n in block.FIELDS]) for f in fractions]
        tau = np.concatenate([rng.uniform(lo - 0.3, hi + 0.3, 40) for _, _, (lo, hi) in groups])
        local = np.repeat(np.arange(len(groups)), 40)
        expected.append(spot_module.GroupedFraction(fractions)(tau, local))
        taus.append(tau)
        owners.append(np.array(index)[local])
    got = block.evaluate(np.concatenate(taus), np.concatenate(owners))
    want = np.concatenate(expected)
    assert np.array_equal(got, want)
    assert ((want > 0.0) & (want < 1.0)).sum() > 3000
