"""The robot's kinematics (Pinocchio) against a hand computation from the URDF, and the taught
start pose."""

import math
import random
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

from waferscan.robot.kinematics import WaferRobot, bundled_urdf

ROBOT = WaferRobot()
PAPER_BASE = ((0.0, -300.0, 0.0), 0.0)


def rot_z(a):
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def hand_fk(joints, frame):
    """Walk the URDF's joints from the root to ``frame`` with plain numpy (every joint of this
    robot turns or slides about Z, with zero rpy origins)."""
    root = ElementTree.parse(bundled_urdf()).getroot()
    by_child = {j.find("child").get("link"): j for j in root.iter("joint")}
    chain = []
    link = frame
    while link in by_child:
        joint = by_child[link]
        chain.append(joint)
        link = joint.find("parent").get("link")
    r, t = np.eye(3), np.zeros(3)
    for joint in reversed(chain):
        origin = np.array([float(v) for v in joint.find("origin").get("xyz").split()]) * 1000.0
        assert joint.find("origin").get("rpy") in (None, "0 0 0")
        t = t + r @ origin
        kind, name = joint.get("type"), joint.get("name")
        if kind == "revolute":
            r = r @ rot_z(math.radians(joints.get(name, 0.0)))
        elif kind == "prismatic":
            t = t + r @ np.array([0.0, 0.0, joints.get(name, 0.0)])
    return r, t


def random_joints(rng):
    return {name: rng.uniform(*ROBOT.limits[name]) for name in ROBOT.joint_names}


def test_joints_and_limits():
    assert ROBOT.joint_names == ("lift", "shoulder", "elbow", "wrist")
    assert ROBOT.limits["lift"] == pytest.approx((0.0, 600.0))
    assert ROBOT.limits["shoulder"] == pytest.approx((-170.0, 170.0), abs=1e-9)
    assert ROBOT.limits["elbow"] == pytest.approx((-160.0, 160.0), abs=1e-9)
    assert ROBOT.limits["wrist"] == pytest.approx((-270.0, 270.0), abs=1e-9)


def test_forward_kinematics_against_a_hand_computation():
    rng = random.Random(1)
    for _ in range(200):
        joints = random_joints(rng)
        for frame in ("beam_emitter", "beam_receiver", "fork", "forearm"):
            r, t = ROBOT.frame_placement(joints, frame)
            hand_r, hand_t = hand_fk(joints, frame)
            assert t == pytest.approx(hand_t, abs=1e-9)
            assert r == pytest.approx(hand_r, abs=1e-12)


def test_beam_is_horizontal_and_160_mm_at_any_pose():
    rng = random.Random(2)
    for _ in range(100):
        emitter, direction, length = ROBOT.beam(random_joints(rng), PAPER_BASE)
        assert length == pytest.approx(160.0, abs=1e-9)
        assert direction[2] == pytest.approx(0.0, abs=1e-12)


def test_lift_moves_the_beam_along_the_lift_axis():
    rng = random.Random(3)
    base = ((10.0, 20.0, 30.0), 37.0)
    axis = np.array(ROBOT.lift_axis(base))
    assert axis == pytest.approx((0, 0, 1))
    for _ in range(50):
        joints = random_joints(rng)
        joints["lift"] = rng.uniform(0.0, 300.0)
        d = rng.uniform(0.0, 300.0)
        before = np.array(ROBOT.beam(joints, base)[0])
        after = np.array(ROBOT.beam({**joints, "lift": joints["lift"] + d}, base)[0])
        assert after - before == pytest.approx(d * axis, abs=1e-9)


@pytest.mark.parametrize("base, emitter, direction", [
    (PAPER_BASE, (-80.0, 266.6, 280.0), (1.0, 0.0, 0.0)),  # the paper's layout
    (((0.0, 0.0, 0.0), 0.0), (300.0, 100.0, 400.0), (0.0, 1.0, 0.0)),
    (((100.0, 50.0, 20.0), 45.0), (200.0, 450.0, 500.0), (math.sqrt(0.5), -math.sqrt(0.5), 0.0)),
    (((0.0, 0.0, 0.0), 180.0), (-250.0, -300.0, 250.0), (-1.0, 0.0, 0.0)),
])
def test_taught_pose_puts_the_beam_where_asked(base, emitter, direction):
    joints = ROBOT.teach_start_pose(base, emitter, direction)
    got_emitter, got_direction, length = ROBOT.beam(joints, base)
    assert got_emitter == pytest.approx(emitter, abs=1e-6)
    assert got_direction == pytest.approx(direction, abs=1e-9)
    for name, value in joints.items():
        low, high = ROBOT.limits[name]
        assert low <= value <= high


def test_out_of_reach_and_bad_requests_are_refused():
    with pytest.raises(ValueError, match="arm reaches"):
        ROBOT.teach_start_pose(PAPER_BASE, (-80.0, 900.0, 280.0), (1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="lift joint would be"):
        ROBOT.teach_start_pose(PAPER_BASE, (-80.0, 266.6, 2000.0), (1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="horizontal"):
        ROBOT.teach_start_pose(PAPER_BASE, (-80.0, 266.6, 280.0), (0.0, 0.6, 0.8))


def test_visuals_are_primitives_in_millimetres():
    visuals = ROBOT.visuals()
    assert set(visuals) == {"base", "carriage", "upper_arm", "forearm", "fork"}
    column = visuals["base"][0]
    assert (column["kind"], column["radius"], column["length"]) == ("cylinder", 120.0, 500.0)
    assert column["t"] == pytest.approx((0.0, 0.0, 250.0))
    assert len(visuals["fork"]) == 4
