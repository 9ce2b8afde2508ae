"""The translation range over arrays (``geometry.ranges.translation_ranges``) against the scalar
``translation_range``, wafer by wafer, bit for bit: level and tilted wafers, level and tilted
beams, bowed wafers, one emitter for all (a sweep's) and one per wafer (a spot's columns)."""

import numpy as np
import pytest
from scenarios import beams_and_wafers

from waferscan.core.geometry.beam import TOUCH_TOLERANCE
from waferscan.core.geometry.ranges import translation_range, translation_ranges
from waferscan.core.model import Beam, Wafer


def cases(rng, count, bowed):
    """(beam, wafer) pairs of every kind a sweep meets (scenarios.beams_and_wafers), the beams
    400 mm long; ``bowed`` gives a third of them a bow."""
    return [(beam, wafer) for _, beam, wafer in
            beams_and_wafers(rng, count, lengths=(400.0,), bowed=bowed)]


def arrays(pairs):
    return (np.array([b.direction for b, _ in pairs]), np.array([w.center for _, w in pairs]),
            np.array([w.normal for _, w in pairs]), np.array([w.radius for _, w in pairs]),
            np.array([w.thickness for _, w in pairs]), np.array([w.bow for _, w in pairs]))


def compare(pairs, emitters, lo, hi, hit, covered, axis, tol):
    """Asserts each covered wafer's answer is the scalar one exactly; returns (covered, met)."""
    seen = met = 0
    for j, ((beam, wafer), emitter) in enumerate(zip(pairs, emitters)):
        if not covered[j]:
            continue
        seen += 1
        expected = translation_range(emitter, beam, axis, wafer, tol=tol)
        if expected is None:
            assert not hit[j], (j, wafer, lo[j], hi[j])
        else:
            met += 1
            assert hit[j] and (lo[j], hi[j]) == expected, (j, wafer, expected, lo[j], hi[j])
    return seen, met


@pytest.mark.parametrize("tol", [0.0, TOUCH_TOLERANCE])
def test_one_emitter_per_wafer_flat_and_bowed(tol):
    rng = np.random.default_rng(3)
    axis = (0.0, 0.0, 1.0)
    pairs = cases(rng, 1600, bowed=True)
    emitters = [b.emitter for b, _ in pairs]
    direction, center, normal, radius, thickness, bow = arrays(pairs)
    lo, hi, hit, covered = translation_ranges(np.array(emitters), direction, axis, center, normal,
                                              radius, thickness, 400.0, tol, bow)
    seen, met = compare(pairs, emitters, lo, hi, hit, covered, axis, tol)
    assert met > len(pairs) // 3
    # What is left to the scalar function: the tilted bowed wafers (a third of half of them).
    tilted_bowed = sum(1 for _, w in pairs if w.bow and w.normal != (0.0, 0.0, 1.0))
    assert seen >= len(pairs) - tilted_bowed - 0.01 * len(pairs)
    assert not any(covered[j] for j, (_, w) in enumerate(pairs)
                   if w.bow and w.normal != (0.0, 0.0, 1.0))


def test_one_emitter_for_every_wafer_as_a_sweep_has_it():
    rng = np.random.default_rng(5)
    axis = (0.0, 0.0, 1.0)
    emitter = (-200.0, 0.0, 300.3)
    pairs = [(Beam(emitter, b.direction, 400.0), w) for b, w in cases(rng, 800, bowed=True)]
    direction, center, normal, radius, thickness, bow = arrays(pairs)
    lo, hi, hit, covered = translation_ranges(emitter, direction, axis, center, normal, radius,
                                              thickness, 400.0, TOUCH_TOLERANCE, bow)
    seen, met = compare(pairs, [emitter] * len(pairs), lo, hi, hit, covered, axis,
                        TOUCH_TOLERANCE)
    assert seen > 0.8 * len(pairs) and met > 0.3 * len(pairs)


def test_a_beam_beside_a_wafer_and_degenerate_rims():
    axis = (0.0, 0.0, 1.0)
    level = (0.0, 0.0, 1.0)
    pairs = [
        # the beam's line misses the rim: no range
        (Beam((-200.0, 400.0, 299.0), (1.0, 0.0, 0.0), 400.0), Wafer("A", (0, 0, 300), level,
                                                                     300.0, 0.775)),
        # the beam ends before the wafer
        (Beam((-1000.0, 0.0, 299.0), (1.0, 0.0, 0.0), 400.0), Wafer("B", (0, 0, 300), level,
                                                                     300.0, 0.775)),
        # a vertical beam through a level wafer (the beam along the axis): the scalar function's
        (Beam((0.0, 0.0, 290.0), (0.0, 0.0, 1.0), 400.0), Wafer("C", (0, 0, 300), level,
                                                                300.0, 0.775)),
        # a wafer standing on edge, beam and lift along its faces: the scalar function's
        (Beam((-200.0, 0.0, 300.0), (1.0, 0.0, 0.0), 400.0), Wafer("D", (0, 0, 300),
                                                                   (0.0, 1.0, 0.0), 300.0, 0.775)),
    ]
    emitters = [b.emitter for b, _ in pairs]
    direction, center, normal, radius, thickness, bow = arrays(pairs)
    lo, hi, hit, covered = translation_ranges(np.array(emitters), direction, axis, center, normal,
                                              radius, thickness, 400.0, 0.0, bow)
    assert covered.tolist() == [True, True, False, False]
    assert hit.tolist() == [False, False, False, False]
    compare(pairs, emitters, lo, hi, hit, covered, axis, 0.0)
    empty = translation_ranges(np.zeros(3), np.zeros((0, 3)), axis, np.zeros((0, 3)),
                               np.zeros((0, 3)), np.zeros(0), np.zeros(0), 400.0, 0.0)
    assert [len(x) for x in empty] == [0, 0, 0, 0]


@pytest.mark.parametrize("seed", [0, 1])
def test_a_tilted_beam_over_level_wafers_is_the_general_regions_answer(seed):
    """A sweep's [beam_tilt] over level wafers (``_slanted_extremes``) gives the floats of the
    general region's corners (``_extremes`` with the rim as two lines) bit for bit, signed
    zeros and the parallel test's edge included, on wafers and beams placed on round values
    (corners exactly on a face, beams ending on the rim) as well as drawn ones."""
    from waferscan.core.geometry import ranges

    rng = np.random.default_rng(seed)
    n = 40_000
    tilt = np.radians(rng.normal(0.0, 0.05, n))
    direction = np.stack([np.ones(n), rng.uniform(-0.2, 0.2, n), np.tan(tilt)], axis=1)
    direction[::7, 2] = rng.choice([1e-3, -1e-3, 2.0 ** -10, -(2.0 ** -12)], len(direction[::7]))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    emitter = np.stack([rng.uniform(-210, -150, n), rng.uniform(-160, 160, n),
                        rng.uniform(295, 305, n)], axis=1)
    center = np.stack([rng.uniform(-2, 2, n), rng.uniform(-2, 2, n), np.full(n, 300.0)], axis=1)
    center[::5], emitter[::5] = np.round(center[::5]), np.round(emitter[::5] * 4) / 4
    normal = np.tile([0.0, 0.0, 1.0], (n, 1))
    thickness = rng.choice([0.775, 0.5, 1.0, 0.0], n)
    for length, tol in ((400.0, TOUCH_TOLERANCE), (120.0, 0.0)):
        r = np.full(n, 150.0) + tol
        r2 = r * r
        wn, en, an, p, q, g = ranges._frame(tuple(emitter.T), tuple(direction.T),
                                            tuple(center.T), tuple(normal.T), (0.0, 0.0, 1.0))
        assert not np.any(g) and np.all(en != 0.0)
        unit = tuple(b / np.sqrt(ranges._dot(q, q)) for b in q)
        qu, gu, pu = ranges._dot(q, unit), ranges._dot(g, unit), ranges._dot(p, unit)
        disc = pu * pu - (ranges._dot(p, p) - r2)
        with np.errstate(divide="ignore", invalid="ignore"):
            general = ranges._extremes(wn, en, an, p, q, g, r, r2, thickness, length, tol,
                                       (qu, gu, pu, np.sqrt(np.maximum(disc, 0.0))))
            edge, lo, hi, empty = ranges._slanted_extremes(wn, en, an, p, q, r, r2, thickness,
                                                           length, tol)
        assert np.array_equal(edge, general[0])
        assert lo.tobytes() == general[1].tobytes() and hi.tobytes() == general[2].tobytes()
        assert np.array_equal(empty, disc < 0.0)
        assert (lo <= hi).sum() > n // 2  # most of them met
