"""The exact beam-wafer test and the closed-form edges against FreeCAD's own B-rep geometry
(OpenCASCADE): the wafer as Part.makeCylinder, the beam as Part.makeLine, distToShape."""

import random

import FreeCAD
import Part
import pytest
from random_layouts import random_layout

from waferscan.addon import paper_scenario
from waferscan.core.files.scenario import read_scenario
from waferscan.core.geometry.beam import beam_hits_wafer
from waferscan.core.scan.engines import wafer_edges
from waferscan.core.scan.layout_scan import scan_layout

V = FreeCAD.Vector
CONFUSION = Part.Precision.confusion()  # 1e-7 mm: OpenCASCADE's own "touching"


def solid(wafer):
    return Part.makeCylinder(wafer.radius, wafer.thickness, V(*wafer.center), V(*wafer.normal))


def edge(layout, z):
    emitter = layout.emitter_at(z)
    receiver = tuple(o + layout.beam.length * d for o, d in zip(emitter, layout.beam.direction))
    return Part.makeLine(V(*emitter), V(*receiver))


def brep_distance(layout, wafer, z, shape=None):
    """Gap between the beam and the wafer solid. OpenCASCADE's distToShape measures to the
    solid's faces, so a beam lying wholly inside the wafer has a gap there too: such a beam
    (its emitter inside) is given distance 0."""
    shape = shape or solid(wafer)
    if shape.isInside(V(*layout.emitter_at(z)), 0.0, True):
        return 0.0
    return shape.distToShape(edge(layout, z))[0]


def test_exact_test_agrees_with_brep_on_sampled_beam_positions():
    """Random layouts, random scan positions near each wafer: where OpenCASCADE finds the beam
    on the solid the exact test says blocked, and where it finds a gap the test says clear."""
    rng = random.Random(11)
    counts = {True: 0, False: 0}
    for seed in range(40):
        layout = random_layout(random.Random(seed))
        for wafer in layout.wafers:
            edges = wafer_edges(layout, wafer)
            if edges is None:
                continue
            shape = solid(wafer)
            lo, hi = edges
            for z in [rng.uniform(lo - 1.0, hi + 1.0) for _ in range(6)]:
                distance = brep_distance(layout, wafer, z, shape)
                if CONFUSION < distance < 1e-5:
                    continue  # within OpenCASCADE's own precision of the rim: undecided
                blocked = distance <= CONFUSION
                assert beam_hits_wafer(layout.emitter_at(z), layout.beam, wafer) == blocked, \
                    (seed, wafer.name, z, distance)
                counts[blocked] += 1
    assert min(counts.values()) > 150


def test_closed_form_edges_agree_with_brep():
    """One micrometre inside each closed-form edge the B-rep beam touches the solid, one
    micrometre outside there is a gap (small where the beam grazes a steep face, but there)."""
    checked = 0
    for seed in range(40):
        layout = random_layout(random.Random(seed))
        for wafer in layout.wafers:
            edges = wafer_edges(layout, wafer)
            if edges is None or edges[1] - edges[0] < 1e-5:
                continue
            shape = solid(wafer)
            lo, hi = edges
            assert brep_distance(layout, wafer, lo + 1e-6, shape) <= CONFUSION
            assert brep_distance(layout, wafer, hi - 1e-6, shape) <= CONFUSION
            assert brep_distance(layout, wafer, lo - 1e-6, shape) > 1e-9
            assert brep_distance(layout, wafer, hi + 1e-6, shape) > 1e-9
            checked += 1
    assert checked > 100


def test_paper_runs_confirmed_with_brep():
    """Every IN and OUT of the paper's experiment: the beam is on the wafer there and clear of
    every wafer one step outside, as the paper confirmed with the CAD measure tool."""
    layout = read_scenario(paper_scenario())
    result = scan_layout(layout)
    shapes = [solid(w) for w in layout.wafers]
    step = layout.scan.z_step

    def blocked(z):
        return any(brep_distance(layout, w, z, s) <= CONFUSION
                   for w, s in zip(layout.wafers, shapes))

    for run in result.runs:
        assert blocked(run.z_in) and blocked(run.z_out)
        assert not blocked(run.z_in - step) and not blocked(run.z_out + step)


def test_paper_exact_edges_within_a_micrometre_of_brep_bisection():
    """Bisection on the B-rep distance finds each wafer's lower edge where the closed form does."""
    layout = read_scenario(paper_scenario())
    for wafer in layout.wafers:
        lo, hi = wafer_edges(layout, wafer)
        shape = solid(wafer)
        a, b = lo - 0.01, lo + 0.01  # clear at a, blocked at b
        assert brep_distance(layout, wafer, a, shape) > CONFUSION
        assert brep_distance(layout, wafer, b, shape) <= CONFUSION
        for _ in range(40):
            m = 0.5 * (a + b)
            if brep_distance(layout, wafer, m, shape) <= CONFUSION:
                b = m
            else:
                a = m
        assert b == pytest.approx(lo, abs=1e-6)
