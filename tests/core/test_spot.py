"""Beam spot and amplifier (SPEC §10) against independent oracles.

Oracle 1: a level wafer crossed well inside its rim blocks a horizontal band of the spot; its
area is closed form (circular segments; a rectangle for a slit), solved here by scalar
bisection, independent of the model's strips and root finding.
Oracle 2: brute force, many rays over the spot, each by the exact segment-solid test of
SPEC §2 (``beam_hits_wafer``), for tilted wafers and grazing chords.
"""

from dataclasses import replace

import pytest
from scenarios import PAPER
from sensor_layouts import SEAT, T, band_fraction, one_wafer, oracle_edges, solve

from waferscan.core.files.scenario import read_scenario
from waferscan.core.geometry.beam import beam_hits_wafer
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.spot import Amplifier, BeamSpot, BlockedFraction, spot_frame

SPOTS = [BeamSpot(diameter=d) for d in (0.1, 0.3, 1.0, 2.0, 5.0)] + \
        [BeamSpot(width=w, height=h) for w, h in ((0.5, 0.1), (2.0, 1.2), (1.0, 5.0))]


@pytest.mark.parametrize("spot", SPOTS, ids=lambda s: f"{s.diameter}-{s.width}x{s.height}")
@pytest.mark.parametrize("on,off", [(0.1, 0.1), (0.3, 0.3), (0.5, 0.5), (0.7, 0.7), (0.9, 0.9),
                                    (0.6, 0.2), (0.9, 0.5), (0.5, 0.1)])
@pytest.mark.parametrize("direction", ["up", "down"])
def test_level_wafer_edges_within_a_micrometre_of_the_band_oracle(spot, on, off, direction):
    layout = one_wafer(spot, Amplifier(on, off), direction=direction)
    result = scan_layout(layout)
    expected = oracle_edges(spot, on, off, direction == "up")
    if expected is None:
        assert result.runs == ()
        assert result.code == "0"
        assert any("missed" in w for w in result.warnings)
        return
    assert len(result.runs) == 1
    run = result.runs[0]
    assert abs(run.z_in - expected[0]) <= 1e-3 * 1e-3
    assert abs(run.z_out - expected[1]) <= 1e-3 * 1e-3
    # Latch order: ON then OFF, in the direction of motion.
    assert [e["edge"] for e in result.edges] == ["on", "off"]
    assert result.edges[0]["z"] == run.z_in


def test_blocked_fraction_equals_the_band_area_exactly():
    for spot in SPOTS:
        layout = one_wafer(spot)
        fraction = BlockedFraction(layout, layout.wafers, spot)
        z0 = layout.beam.emitter[2]
        for i in range(201):
            z = SEAT - spot.half_height - 0.1 + i * (T + 2 * spot.half_height + 0.2) / 200
            assert abs(float(fraction(z - z0)) - band_fraction(spot, z)) <= 1e-9


def test_a_wafer_thinner_than_the_spot_is_missed_with_the_largest_fraction_said():
    spot = BeamSpot(diameter=5.0)
    layout = one_wafer(spot, Amplifier(0.5), z_step=0.01)
    result = scan_layout(layout)
    peak = band_fraction(spot, SEAT + T / 2)  # about 0.18
    assert peak < 0.5
    assert result.code == "0" and result.runs == ()
    (warning,) = [w for w in result.warnings if "missed" in w]
    assert f"{peak:.1%}" in warning and "slot 1" in warning


def test_stepped_output_switches_at_the_first_step_past_the_threshold():
    spot, on, off = BeamSpot(diameter=1.0), 0.8, 0.3
    for direction in ("up", "down"):
        layout = one_wafer(spot, Amplifier(on, off), z_step=0.05, direction=direction)
        (run,) = scan_layout(layout).runs
        grid = [SEAT - 5.0 + k * 0.05 for k in range(201)]
        b = [band_fraction(spot, z) for z in grid]
        order = range(201) if direction == "up" else range(200, -1, -1)
        state, on_k, off_k = False, None, None
        for k in order:
            if not state and b[k] >= on:
                state, on_k = True, k
            elif state and b[k] < off:
                off_k = k - 1 if direction == "up" else k + 1
                break
        assert run.z_in == pytest.approx(grid[on_k], abs=1e-12)
        assert run.z_out == pytest.approx(grid[off_k], abs=1e-12)


def brute_fraction(layout, z, n=160):
    """Share of n x n rays over the spot (those inside it) that meet a wafer, each by the exact
    test of SPEC §2."""
    spot = layout.spot
    u, v, alpha, beta = spot_frame(layout.beam.direction, layout.lift_axis)
    centre = layout.emitter_at(z)
    hit = total = 0
    for i in range(n):
        s = -spot.half_width + (i + 0.5) * 2 * spot.half_width / n
        for j in range(n):
            h = -spot.half_height + (j + 0.5) * 2 * spot.half_height / n
            if spot.round and s * s + h * h > spot.half_width ** 2:
                continue
            total += 1
            emitter = tuple(c + s * a + h * b for c, a, b in zip(centre, u, v))
            hit += any(beam_hits_wafer(emitter, layout.beam, w, tol=0.0) for w in layout.wafers)
    return hit / total


def test_tilted_cross_slotted_wafer_against_many_rays():
    paper = read_scenario(PAPER)
    cross = [w for w in paper.wafers if abs(w.normal[2]) < 1.0][0]
    spot = BeamSpot(diameter=2.0)
    layout = replace(paper, wafers=(cross,), spot=spot)
    fraction = BlockedFraction(layout, layout.wafers, spot)
    z0 = layout.beam.emitter[2]
    result = scan_layout(replace(layout, scan=replace(layout.scan, z_step=0.0)))
    (run,) = result.runs
    for z in (run.z_in - 0.8, run.z_in, run.z_in + 0.5, 0.5 * (run.z_in + run.z_out),
              run.z_out - 0.3, run.z_out, run.z_out + 0.9):
        assert abs(float(fraction(z - z0)) - brute_fraction(layout, z, 120)) <= 0.003


def test_grazing_chord_against_many_rays():
    # The beam crosses 0.8 mm inside the rim: across a 3 mm slit the chord shrinks to nothing.
    spot = BeamSpot(width=3.0, height=1.0)
    layout = one_wafer(spot, depth=0.8, normal=(0.02, 0.0, 1.0))
    fraction = BlockedFraction(layout, layout.wafers, spot)
    z0 = layout.beam.emitter[2]
    for z in (SEAT - 0.6, SEAT - 0.2, SEAT + 0.3, SEAT + 0.9, SEAT + 1.2):
        assert abs(float(fraction(z - z0)) - brute_fraction(layout, z, 120)) <= 0.003


def test_the_ideal_sensor_leaves_the_paper_bit_for_bit():
    paper = read_scenario(PAPER)
    before = scan_layout(paper)
    after = scan_layout(replace(paper, spot=BeamSpot(), amplifier=Amplifier()))
    assert after.runs == before.runs and after.wafers == before.wafers
    assert after.code == before.code == "1101221001220001010000010"
    assert after.warnings == before.warnings and after.edges == ()


def test_paper_with_a_1mm_spot_reads_what_the_spot_geometry_predicts():
    # t = 0.7 >= the spot's radius: at threshold 0.5 the output switches where a face crosses
    # the spot's centre, so a level wafer reads exactly t (continuous) and the code is kept.
    paper = replace(read_scenario(PAPER), spot=BeamSpot(diameter=1.0))
    exact = scan_layout(paper.with_scan(z_step=0.0))
    assert exact.code == "1101221001220001010000010"
    level = [r for r in exact.runs if len(r.wafers) == 1 and r.diff < 1.0]
    assert len(level) == 8
    for run in level:
        assert abs(run.diff - 0.7) <= 1e-6
    # A lower threshold reads more: up to t + d as the threshold goes to 0.
    low = scan_layout(replace(paper.with_scan(z_step=0.0), amplifier=Amplifier(0.1)))
    spot = BeamSpot(diameter=1.0)
    lo = solve(lambda z: band_fraction(spot, z) - 0.1, SEAT - 1.0, SEAT + T / 2)
    hi = solve(lambda z: band_fraction(spot, z) - 0.1, SEAT + T / 2, SEAT + T + 1.0)
    for run in [r for r in low.runs if len(r.wafers) == 1 and r.diff < 2.0]:
        assert abs(run.diff - (hi - lo)) <= 1e-6
        assert 0.7 < run.diff < 1.7
