"""The exact beam-wafer test against independent geometry, its scalar and numpy forms against
each other, the paper's mid-plane test and the closed-form translation range."""

import math
import random

import numpy as np
import pytest

from waferscan.core.geometry.beam import (
    beam_hits_wafer,
    beam_hits_wafers,
    paper_beam_hits_wafer,
    wafer_bounds,
    wafer_columns,
)
from waferscan.core.geometry.ranges import translation_range
from waferscan.core.model import Beam, Wafer, unit


def _random_case(rng):
    normal = rng.choice([(0.0, 0.0, 1.0), (1.0, 0.0, 0.0),
                         unit((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)))])
    wafer = Wafer("W", (rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)), normal,
                  rng.uniform(1.0, 20.0), rng.uniform(0.1, 3.0))
    direction = rng.choice([(1.0, 0.0, 0.0), (0.0, 0.0, 1.0), normal,
                            unit((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)))])
    emitter = (rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-8, 8))
    return emitter, Beam(emitter, direction, rng.uniform(0.5, 40.0)), wafer


def _inside(point, wafer, shrink=0.0):
    u = [p - c for p, c in zip(point, wafer.center)]
    un = sum(a * b for a, b in zip(u, wafer.normal))
    radial = math.sqrt(max(0.0, sum(a * a for a in u) - un * un))
    return shrink <= un <= wafer.thickness - shrink and radial <= wafer.radius - shrink


def test_scalar_and_numpy_forms_are_bit_identical():
    rng = random.Random(1)
    cases = [_random_case(rng) for _ in range(5000)]
    for emitter, beam, wafer in cases:
        cols = [np.array([v]) for v in (*wafer.center, *wafer.normal, wafer.radius,
                                        wafer.thickness)]
        vector = beam_hits_wafers(np.array(emitter[0]), np.array(emitter[1]),
                                  np.array(emitter[2]), beam, *cols)
        assert bool(vector[0]) == beam_hits_wafer(emitter, beam, wafer)


def test_horizontal_beam_and_wafer_against_plane_geometry():
    """Beam and wafer both horizontal: blocked iff the beam's height is within the thickness
    and the segment comes within R of the centre in XY."""
    rng = random.Random(2)
    agreements = {True: 0, False: 0}
    for _ in range(5000):
        wafer = Wafer("W", (rng.uniform(-50, 50), rng.uniform(-50, 50), 10.0), (0.0, 0.0, 1.0),
                      rng.uniform(50, 300), 0.7)
        heading = rng.uniform(0, 2 * math.pi)
        d = (math.cos(heading), math.sin(heading), 0.0)
        z = rng.choice([rng.uniform(9.0, 11.5), 10.0, 10.7])
        emitter = (rng.uniform(-250, 250), rng.uniform(-250, 250), z)
        beam = Beam(emitter, d, rng.uniform(10, 400))
        # Distance in XY from the centre to the segment.
        px, py = wafer.center[0] - emitter[0], wafer.center[1] - emitter[1]
        s = min(beam.length, max(0.0, px * d[0] + py * d[1]))
        distance = math.hypot(px - s * d[0], py - s * d[1])
        expected = 10.0 <= z <= 10.7 and distance <= wafer.radius
        if abs(distance - wafer.radius) < 1e-6:
            continue
        assert beam_hits_wafer(emitter, beam, wafer) == expected
        agreements[expected] += 1
    assert min(agreements.values()) > 500


def test_beam_along_the_axis():
    """A beam parallel to the wafer's axis (the radial quadratic degenerates)."""
    wafer = Wafer("W", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 10.0, 1.0)
    up = (0.0, 0.0, 1.0)
    assert beam_hits_wafer((4.9, 0.0, -5.0), Beam((4.9, 0.0, -5.0), up, 5.0), wafer)
    assert not beam_hits_wafer((5.1, 0.0, -5.0), Beam((5.1, 0.0, -5.0), up, 20.0), wafer)
    assert not beam_hits_wafer((0.0, 0.0, -5.0), Beam((0.0, 0.0, -5.0), up, 4.9), wafer)
    assert beam_hits_wafer((0.0, 0.0, 0.5), Beam((0.0, 0.0, 0.5), up, 0.1), wafer)  # inside


def test_sampled_points_inside_the_solid_mean_a_hit():
    """Wherever a sample point of the segment lies inside the solid, the test says blocked; where
    the test says clear, no sample is inside even a slightly grown solid."""
    rng = random.Random(3)
    hits = 0
    for _ in range(3000):
        emitter, beam, wafer = _random_case(rng)
        samples = [tuple(o + s * d for o, d in zip(emitter, beam.direction))
                   for s in np.linspace(0.0, beam.length, 801)]
        inside = any(_inside(p, wafer) for p in samples)
        result = beam_hits_wafer(emitter, beam, wafer)
        if inside:
            assert result
            hits += 1
        if not result:
            assert not any(_inside(p, wafer, shrink=-1e-6) for p in samples)
    assert hits > 80


def test_paper_test_matches_the_exact_one_for_level_wafers():
    """Level wafer, level beam (e.n = 0, the paper's equation 3): same answer away from edges."""
    rng = random.Random(4)
    for _ in range(2000):
        wafer = Wafer("W", (0.0, 400.0, 100.0), (0.0, 0.0, 1.0), 300.0, 0.7)
        z = rng.uniform(99.5, 101.2)
        emitter = (-80.0, rng.uniform(240.0, 300.0), z)
        beam = Beam(emitter, (1.0, 0.0, 0.0), 160.0)
        exact = beam_hits_wafer(emitter, beam, wafer)
        if min(abs(z - 100.0), abs(z - 100.7)) < 1e-6 or abs(emitter[1] - 250.0) < 0.05:
            continue
        assert paper_beam_hits_wafer(emitter, beam, wafer) == exact


def test_paper_test_ignores_thickness_of_a_tilted_wafer():
    """Tilted wafer: the mid-plane test sees a zero-thickness disc, the exact test the solid."""
    tilt = math.radians(2.0)
    wafer = Wafer("W", (0.0, 0.0, 0.0), (-math.sin(tilt), 0.0, math.cos(tilt)), 300.0, 0.7)
    beam_at = lambda z: ((-80.0, 10.0, z), Beam((-80.0, 10.0, z), (1.0, 0.0, 0.0), 160.0))
    top_exact = max(z / 1000 for z in range(-5000, 5000) if beam_hits_wafer(*beam_at(z / 1000), wafer))
    top_paper = max(z / 1000 for z in range(-5000, 5000)
                    if paper_beam_hits_wafer(*beam_at(z / 1000), wafer))
    assert top_exact - top_paper == pytest.approx(0.7 * math.cos(tilt) / 2, abs=0.002)


def test_translation_range_along_the_reach_direction_finds_the_front_edge():
    """The same closed form with the reach direction as axis: a jab finds the wafer's front."""
    wafer = Wafer("W", (0.0, 400.0, 100.0), (0.0, 0.0, 1.0), 300.0, 0.7)
    beam = Beam((-80.0, 200.0, 100.3), (1.0, 0.0, 0.0), 160.0)
    lo, hi = translation_range(beam.emitter, beam, (0.0, 1.0, 0.0), wafer, tol=0.0)
    assert lo == pytest.approx(400.0 - 150.0 - 200.0, abs=1e-9)
    assert hi == pytest.approx(400.0 + 150.0 - 200.0, abs=1e-9)


def test_bounds_enclose_the_solid():
    rng = random.Random(5)
    for _ in range(200):
        _, _, wafer = _random_case(rng)
        (x0, y0, z0), (x1, y1, z1) = wafer_bounds(wafer)
        for _ in range(50):
            a, b = rng.uniform(0, 2 * math.pi), rng.uniform(0, 1)
            n = wafer.normal
            helper = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
            u = unit(np.cross(n, helper))
            v = np.cross(n, u)
            p = (np.array(wafer.center) + wafer.radius * math.sqrt(b) * (math.cos(a) * np.array(u)
                 + math.sin(a) * v) + rng.uniform(0, wafer.thickness) * np.array(n))
            assert x0 - 1e-9 <= p[0] <= x1 + 1e-9
            assert y0 - 1e-9 <= p[1] <= y1 + 1e-9
            assert z0 - 1e-9 <= p[2] <= z1 + 1e-9


def test_wafer_columns_order():
    w = Wafer("W", (1.0, 2.0, 3.0), (0.0, 0.0, 1.0), 10.0, 0.5)
    assert [c[0] for c in wafer_columns([w])] == [1.0, 2.0, 3.0, 0.0, 0.0, 1.0, 5.0, 0.5]
    assert all(c.size == 0 for c in wafer_columns([]))
