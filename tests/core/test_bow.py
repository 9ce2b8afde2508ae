"""Bowed wafers (SPEC §10) against closed forms, a point-membership brute force and the other
engines."""

import math
import random
from dataclasses import replace

import pytest
from scenarios import PAPER
from sensor_layouts import SEAT, T, one_wafer

from waferscan.core.files.scenario import parse_scenario, read_scenario
from waferscan.core.geometry.bow import beam_hits_bowed_wafer
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.spot import BeamSpot

DEPTH = 16.6  # the beam's chord lies R - DEPTH from the wafer's centre


def bowed(layout, bow):
    return replace(layout, wafers=tuple(replace(w, bow=bow) for w in layout.wafers))


@pytest.mark.parametrize("bow", [0.1, 0.05, -0.1, 0.3])
def test_level_bowed_wafer_edges_are_the_surfaces_over_the_chord(bow):
    # Along the chord r runs from d = R - DEPTH (its middle) out to R: the bottom surface
    # bow (1 - r²/R²) spans 0 .. bow (1 - d²/R²), the top t above it.
    layout = bowed(one_wafer(None), bow)
    (run,) = scan_layout(layout.with_scan(z_step=0.0)).runs
    d, r = 150.0 - DEPTH, 150.0
    middle = bow * (1 - d * d / (r * r))
    assert run.z_in == pytest.approx(SEAT + min(0.0, middle), abs=1e-9)
    assert run.z_out == pytest.approx(SEAT + T + max(0.0, middle), abs=1e-9)


def inside(point, wafer):
    """Point membership of the bowed solid, straight from its definition."""
    u = [p - c for p, c in zip(point, wafer.center)]
    h = sum(a * b for a, b in zip(u, wafer.normal))
    rho = math.sqrt(max(0.0, sum(a * a for a in u) - h * h))
    if rho > wafer.radius:
        return False
    w = wafer.bow * (1 - rho * rho / wafer.radius ** 2)
    return w <= h <= w + wafer.thickness


def brute_hits(emitter, beam, wafer, count=20000):
    for i in range(count + 1):
        lam = beam.length * i / count
        if inside(tuple(o + lam * e for o, e in zip(emitter, beam.direction)), wafer):
            return True
    return False


def test_tilted_bowed_wafer_edges_against_point_membership():
    paper = read_scenario(PAPER)
    cross = replace([w for w in paper.wafers if w.normal[2] < 1.0][0], bow=0.2)
    layout = replace(paper, wafers=(cross,)).with_scan(z_step=0.0)
    (run,) = scan_layout(layout).runs
    beam = layout.beam
    # Just inside each edge the brute force finds the wafer, just outside it does not (the
    # samples are 0.008 mm apart along a beam crossing at 2 degrees: 3e-4 mm in height).
    for z, expect in ((run.z_in + 2e-3, True), (run.z_in - 2e-3, False),
                      (run.z_out - 2e-3, True), (run.z_out + 2e-3, False)):
        assert brute_hits(layout.emitter_at(z), beam, cross) is expect
    flat = scan_layout(replace(layout, wafers=(replace(cross, bow=0.0),))).runs[0]
    # A tilted chord's ends lie at the rim, where the bow is 0: the run is the flat wafer's.
    assert run.z_in == pytest.approx(flat.z_in, abs=1e-8)
    assert run.z_out == pytest.approx(flat.z_out, abs=1e-8)


def test_exact_line_test_against_point_membership():
    rng = random.Random(5)
    layout = bowed(one_wafer(None, normal=(0.03, -0.02, 1.0)), 0.25)
    wafer = layout.wafers[0]
    disagree = 0
    for _ in range(300):
        z = SEAT + rng.uniform(-0.5, 1.3)
        emitter = layout.emitter_at(z)
        exact = beam_hits_bowed_wafer(emitter, layout.beam, wafer, tol=0.0)
        if exact != brute_hits(emitter, layout.beam, wafer, 4000):
            # Only a beam grazing the solid within the samples' spacing may differ.
            near = [brute_hits(layout.emitter_at(z + dz), layout.beam, wafer, 4000)
                    for dz in (-0.01, 0.01)]
            assert near[0] != near[1]
            disagree += 1
    assert disagree <= 5


@pytest.mark.parametrize("seed", range(4))
def test_engines_agree_on_bowed_layouts(seed):
    rng = random.Random(seed)
    paper = read_scenario(PAPER)
    wafers = tuple(replace(w, bow=rng.uniform(-0.3, 0.3)) for w in paper.wafers)
    layout = replace(paper, wafers=wafers).with_scan(start_z=290.0, final_z=410.0,
                                                      z_step=0.01)
    layout = replace(layout, beam=replace(layout.beam, emitter=(*layout.beam.emitter[:2],
                                                                290.0)))
    results = {e: scan_layout(layout, e) for e in ("analytic", "loop", "vector")}
    assert results["analytic"].runs == results["loop"].runs == results["vector"].runs
    assert results["analytic"].wafers == results["loop"].wafers == results["vector"].wafers


def test_scenario_bow_keys():
    text = open(PAPER).read()
    text = text.replace("[[carrier]]\n", "[[carrier]]\nwafer_bow = 0.08\n", 1)
    text += '\n[[wafer]]\ncarrier = "LP1"\nslot = 3\nbow = -0.05\n'
    layout = parse_scenario(text, "b.toml")
    bows = {w.slot: w.bow for w in layout.wafers}
    assert bows[1] == 0.08 and bows[3] == -0.05 and bows[5] == 0.08
    bad = text.replace("bow = -0.05", "bow = \"up\"")
    with pytest.raises(Exception) as caught:
        parse_scenario(bad, "b.toml")
    line = bad.splitlines().index('bow = "up"') + 1
    assert str(caught.value).startswith(f"b.toml:{line}: [[wafer]] #1 bow: ")


def test_a_bowed_wafer_under_a_spot():
    # A spot and a bow together: with threshold 0.5 and t >= the spot's radius the output
    # switches where the bowed chord's lowest bottom and highest top cross the spot's centre.
    layout = replace(bowed(one_wafer(BeamSpot(diameter=1.0)), 0.1))
    (run,) = scan_layout(layout).runs
    d = 150.0 - DEPTH
    middle = 0.1 * (1 - d * d / 150.0 ** 2)
    assert SEAT - 1e-3 < run.z_in < SEAT + middle
    assert SEAT + T < run.z_out < SEAT + T + middle + 1e-3
