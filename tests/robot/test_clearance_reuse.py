"""SPEC §15's clearance check made cheaper without another float: the pairs a swept stroke's
boxes put out of reach are not measured (``_nearest_among``'s ``extents``), and what a scan of
the same layout makes again (the obstacles' arrays, the robot's start pose, the swept shapes) is
made once. Each answer is compared, to the last bit, with the one made without them. No
FreeCAD."""

import math
import random
from dataclasses import replace
from pathlib import Path

import coal
import numpy as np
import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import clearance as core
from waferscan.robot import clearance
from waferscan.robot.clearance import RobotBody, ScannerBody, clearance_for
from waferscan.robot.scenario_scan import carrier_solids

ROOT = Path(__file__).resolve().parents[2]
PAPER = read_scenario(ROOT / "resources" / "examples" / "paper.toml")
CARRIER = carrier_solids(PAPER)


def _extents(parts):
    boxes = np.array([clearance._box_halves(part[1]) for part in parts])
    turned = np.abs(np.array([part[2] for part in parts])) @ boxes[:, :3, None]
    return (turned[:, :, 0] + boxes[:, 3:]).T


def _exact(best):
    d, part, obstacle, slot, witness = best
    return repr((d, part, obstacle, slot, None if witness is None else witness.tolist()))


@pytest.mark.parametrize("carrier", [(), CARRIER])
def test_passing_over_pairs_apart_changes_no_answer(carrier):
    # Long boxes, capsules, cylinders and spheres about the wafers' rims and the carrier's
    # walls, some through them: the same closest pair with and without the boxes' test.
    body = RobotBody(PAPER, carrier=carrier)
    rng = random.Random(29)
    shapes = [lambda: coal.Box(rng.uniform(1, 20), rng.uniform(1, 20), rng.choice([4, 300])),
              lambda: coal.Cylinder(rng.uniform(1, 10), rng.choice([4.0, 300.0])),
              lambda: coal.Capsule(rng.uniform(1, 10), rng.choice([4.0, 300.0])),
              lambda: coal.Sphere(rng.uniform(1, 10))]
    for _ in range(200):
        parts = []
        for k in range(rng.randint(1, 6)):
            tilt = np.array([rng.gauss(0, 0.05), rng.gauss(0, 0.05), 1.0])
            where = np.array([rng.choice([-1, 1]) * rng.uniform(60, 165),
                              rng.uniform(240, 290), rng.uniform(270, 560)])
            parts.append((f"p{k}", rng.choice(shapes)(), clearance._frame_z(tilt), where, True))
        assert _exact(body._nearest(parts, None, None, _extents(parts))) == \
            _exact(body._nearest(parts))


def test_the_paper_stroke_measures_fewer_pairs_for_the_same_closest(monkeypatch):
    monkeypatch.setattr(clearance, "_SWEPT_MADE", {})  # none kept with _box_halves patched
    body = RobotBody(PAPER, carrier=CARRIER)
    (motion,) = core.scan_motions(PAPER)
    measured = []
    distance = clearance._Body._distance

    def counted(self, geometry, transform, index):
        measured.append(index)
        return distance(self, geometry, transform, index)

    monkeypatch.setattr(clearance._Body, "_distance", counted)
    least = body.swept(motion)
    with_boxes = len(measured)
    measured.clear()
    monkeypatch.setattr(clearance, "_box_halves", lambda geometry: None)  # no boxes
    assert repr(body.swept(motion)) == repr(least)
    assert with_boxes < len(measured)
    assert least.part == "tine_left" and least.distance == pytest.approx(0.650, abs=1e-3)


def test_a_body_made_again_shares_its_arrays_and_gives_the_same_answers():
    first, again = RobotBody(PAPER, carrier=CARRIER), RobotBody(PAPER, carrier=CARRIER)
    assert again.obstacles.centres is first.obstacles.centres  # made once, read only
    assert not first.obstacles.centres.flags.writeable
    assert (again.z0, again.axis, again.moves) == (first.z0, first.axis, first.moves)
    assert repr(clearance_for(PAPER, again)) == repr(clearance_for(PAPER, first))
    # Other wafers, another start: their own arrays and pose, as made afresh.
    moved = replace(PAPER, wafers=tuple(replace(w, center=(w.center[0], w.center[1] + 1.0,
                                                            w.center[2])) for w in PAPER.wafers))
    other = RobotBody(moved, carrier=CARRIER)
    assert other.obstacles.centres is not first.obstacles.centres
    assert other.obstacles.centres[0, 1] == first.obstacles.centres[0, 1] + 1.0
    lower = dict(first.start, lift=first.start["lift"] - 10.0)
    turned = RobotBody(PAPER, base=((0.0, -300.0, 0.0), -0.0), start=lower)
    clearance._POSE_MADE.clear()
    fresh = RobotBody(PAPER, base=((0.0, -300.0, 0.0), -0.0), start=lower)
    assert repr((turned.z0, turned.axis)) == repr((fresh.z0, fresh.axis))
    assert turned.z0 == pytest.approx(first.z0 - 10.0, abs=1e-9)


def test_the_scanners_heads_sweep_the_same():
    body = ScannerBody(PAPER, CARRIER)
    for motion in core.scan_motions(replace(PAPER, scan=replace(PAPER.scan,
                                                                direction="updown"))):
        least = body.swept(motion)
        clearance._SWEPT_MADE.clear()
        assert repr(ScannerBody(PAPER, CARRIER).swept(motion)) == repr(least)
        assert math.isfinite(least.distance)
