"""The robot in the document: links from the URDF placed by Pinocchio, the taught start pose
stored in the document, the scanner where Pinocchio says, scans that set the lift joint."""

from dataclasses import replace

import FreeCAD as App
import numpy as np
import pytest
from scenarios import PAPER_CODE as CODE

from waferscan.addon import paper_scenario
from waferscan.cad import roles
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import DocumentScene, read_layout
from waferscan.cad.robot import RobotMover
from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import RobotSpec
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.robot.kinematics import WaferRobot

PAPER = read_scenario(paper_scenario())


@pytest.fixture
def robot_doc(built):
    layout = PAPER if PAPER.robot is not None else replace(PAPER, robot=RobotSpec())
    return built(layout, "RobotTest"), layout


def robot_part(doc):
    return next(o for o in doc.Objects if roles.role_of(o) == roles.ROBOT)


def scanner_beam(doc):
    """Emitter and receiver read back through the document's global placements."""
    scanner = DocumentScene.of(doc).scanner()
    placement = scanner.placement()
    holder = roles.role_holder(scanner.obj)
    return (np.array(placement.multVec(holder.Emitter)),
            np.array(placement.multVec(holder.Receiver)))


def test_taught_pose_is_stored_and_puts_the_beam_on_the_scenarios(robot_doc):
    doc, layout = robot_doc
    part = robot_part(doc)
    assert list(part.JointNames) == list(WaferRobot().joint_names)
    assert len(part.StartJoints) == len(part.JointNames)
    emitter, receiver = scanner_beam(doc)
    assert emitter == pytest.approx(layout.beam.emitter, abs=1e-9)
    direction = (receiver - emitter) / np.linalg.norm(receiver - emitter)
    assert direction == pytest.approx(layout.beam.direction, abs=1e-12)
    assert np.linalg.norm(receiver - emitter) == pytest.approx(layout.beam.length, abs=1e-9)


def test_document_and_pinocchio_agree_on_the_scanner(robot_doc):
    """At any lift position, the scanner read back from the document is where Pinocchio's
    forward kinematics puts the emitter and receiver frames, to 1e-9 mm."""
    doc, layout = robot_doc
    scene = DocumentScene.of(doc)
    mover = RobotMover(scene, read_layout(doc, scene))
    robot = WaferRobot()
    for z in (280.0, 333.33, 415.5, 550.0):
        mover.move_to(z)
        joints = mover.joints_at(z)
        emitter, receiver = scanner_beam(doc)
        base = np.array(robot_part(doc).Placement.toMatrix().A).reshape(4, 4)
        base_r, base_t = base[:3, :3], base[:3, 3]
        for frame, read in (("beam_emitter", emitter), ("beam_receiver", receiver)):
            _, t = robot.frame_placement(joints, frame)
            assert read == pytest.approx(base_r @ np.asarray(t) + base_t, abs=1e-9)
        assert emitter[2] == pytest.approx(z, abs=1e-9)
    mover.restore()
    emitter, _ = scanner_beam(doc)
    assert emitter == pytest.approx(layout.beam.emitter, abs=1e-9)


def test_links_follow_the_lift_joint(robot_doc):
    doc, layout = robot_doc
    scene = DocumentScene.of(doc)
    mover = RobotMover(scene, read_layout(doc, scene))
    fork = next(o for o in doc.Objects if getattr(o, "RobotLink", "") == "fork")
    before = App.Vector(fork.Placement.Base)
    mover.move_to(layout.scan.start_z + 100.0)
    assert (fork.Placement.Base - before).Length == pytest.approx(100.0, abs=1e-9)
    mover.restore()


@pytest.mark.parametrize("engine", ["document", "brep", "analytic"])
def test_the_robot_scans_the_paper_experiment(robot_doc, engine):
    doc, layout = robot_doc
    reference = scan_layout(PAPER)
    result = scan_document(doc, engine)
    assert result.code == CODE
    # Stepped positions are grid values: the robot's scan must land on exactly the same ones.
    assert [(r.z_in, r.z_out) for r in result.runs] == \
        [(r.z_in, r.z_out) for r in reference.runs]


def test_robot_layout_survives_save_and_reload(robot_doc, tmp_path):
    doc, _ = robot_doc
    path = str(tmp_path / "robot.FCStd")
    doc.saveAs(path)
    start = list(robot_part(doc).StartJoints)
    App.closeDocument(doc.Name)
    reopened = App.openDocument(path)
    try:
        assert list(robot_part(reopened).StartJoints) == start
        assert scan_document(reopened, "document").code == CODE
    finally:
        App.closeDocument(reopened.Name)
