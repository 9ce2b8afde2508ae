"""Slow scanning's jab and sweep through the FreeCAD document (SPEC §13): the robot's joints move
(inverse kinematics for the straight advance, the wrist for the sweep), the beam read back from
the document is the analytic one, and the document engine agrees with the closed forms."""

import json
from dataclasses import replace
from functools import partial

import commands
import FreeCAD as App
import pytest
from scenarios import PAPER
from scenarios import SLOW_JAB as EXAMPLE

from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import mover_for, scan_document
from waferscan.cad.pocket_probe import RobotArm, ScannerArm
from waferscan.cad.reader import DocumentScene, beam_from, read_layout
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import slow_scan
from waferscan.core.scan.layout_scan import scan_layout

LAYOUT = read_scenario(EXAMPLE)


@pytest.fixture
def doc(built):
    return built(LAYOUT, "SlowScanTest")


def _robot_joints(doc):
    part = next(o for o in doc.Objects if "StartJoints" in o.PropertiesList)
    links = {o.RobotLink: App.Placement(o.Placement) for o in part.Group
             if "RobotLink" in o.PropertiesList}
    return links


def test_settings_are_stored_in_the_document_and_read_back(doc):
    settings = next(o for o in doc.Objects if "Jab" in o.PropertiesList)
    assert settings.Jab.Value == pytest.approx(20.0) and settings.Sweep.Value == pytest.approx(40)
    settings.Sweep = 12.5
    layout = read_layout(doc)
    assert (layout.scan.jab, layout.scan.sweep, layout.scan.sweep_radius) == (20.0, 12.5, 260.0)


def test_the_jab_and_sweep_move_the_robots_joints_and_the_beam_follows_the_closed_form(doc):
    scene = DocumentScene.of(doc)
    layout = read_layout(doc, scene)
    arm = RobotArm(mover_for(scene, layout), layout)
    scanner = scene.scanner()
    start = _robot_joints(doc)
    z = 364.29
    for advance, turn in ((0.0, 0.0), (10.0, 0.0), (26.6, 0.0), (26.6, 33.0), (5.0, -20.0)):
        arm.move(z, advance, turn)
        beam = beam_from(scanner)
        emitter, expected = slow_scan.beam_at(layout, z, advance, turn)
        assert beam.emitter == pytest.approx(emitter, abs=1e-9)
        assert beam.direction == pytest.approx(expected.direction, abs=1e-12)
    # The straight advance is made by the arm's joints: the shoulder, elbow and wrist turned.
    arm.move(z, 26.6, 0.0)
    joints = arm.joints(z, 26.6, 0.0)
    start_joints = arm.joints(z)
    for name in ("shoulder", "elbow", "wrist"):
        assert abs(joints[name] - start_joints[name]) > 0.5
    moved = _robot_joints(doc)
    assert (moved["forearm"].Base - start["forearm"].Base).Length > 1.0
    arm.restore()
    back = _robot_joints(doc)
    assert all((back[k].Base - start[k].Base).Length < 1e-9 for k in start)


def test_document_engine_agrees_with_the_closed_forms(doc):
    # The whole ±40° sweep (no clearance check: the sweep is not stopped), where the tines
    # cross the rims and slot 3's shift shows; then as scanned, stopped at clearance_min.
    analytic = scan_document(doc, "analytic", clearance=False)
    document = scan_document(doc, "document", clearance=False)
    assert document.code == analytic.code == "1151221601220001010000010"
    assert [(r.z_in, r.z_out) for r in document.runs] == \
        [(r.z_in, r.z_out) for r in analytic.runs]
    assert len(document.pockets) == 25
    for mine, exact in zip(document.pockets, analytic.pockets):
        assert (mine.front is None) == (exact.front is None)
        if exact.front is not None:
            assert mine.front == pytest.approx(exact.front, abs=1e-7)
        assert (mine.sweep is None) == (exact.sweep is None)
        if exact.sweep is not None:
            assert mine.sweep == pytest.approx(exact.sweep, abs=1e-7)
    # The protruding wafer (slot 8, 5 mm out) is met 5 mm earlier by the robot's own sensor.
    assert document.pockets[7].front == pytest.approx(document.pockets[0].front - 5.0, abs=1e-7)
    assert document.pockets[2].shift == pytest.approx(3.0, abs=1e-3)
    stopped = scan_document(doc, "analytic")
    measured = scan_document(doc, "document")
    assert measured.code == stopped.code == "1111221601220001010000010"
    for mine, exact in zip(measured.pockets, stopped.pockets):
        # The same body stops both sweeps: the angles agree to the search's 0.001 mm of
        # clearance, and each sweep's blocked angles are those reached.
        assert mine.reached == pytest.approx(exact.reached, abs=1e-3)
        if exact.sweep is not None:
            assert mine.sweep == pytest.approx(mine.reached, abs=1e-7)


def test_a_scanner_without_a_robot_jabs_and_sweeps_by_its_placement():
    layout = replace(LAYOUT, robot=None)
    made = build_document(layout, "SlowScanNoRobot")
    try:
        scene = DocumentScene.of(made)
        assert not scene.robots
        read = read_layout(made, scene)
        arm = ScannerArm(mover_for(scene, read), read)
        arm.move(334.29, 12.0, -7.5)
        emitter, expected = slow_scan.beam_at(read, 334.29, 12.0, -7.5)
        beam = beam_from(scene.scanner())
        assert beam.emitter == pytest.approx(emitter, abs=1e-9)
        assert beam.direction == pytest.approx(expected.direction, abs=1e-12)
        arm.restore()
        document = scan_document(made, "document", clearance=False)  # the whole ±40°
        analytic = scan_layout(layout)
        assert document.code == analytic.code
        for mine, exact in zip(document.pockets, analytic.pockets):
            assert mine.front == pytest.approx(exact.front, abs=1e-7) if exact.front else \
                mine.front == exact.front
            assert mine.sweep == pytest.approx(exact.sweep, abs=1e-7) if exact.sweep else \
                mine.sweep == exact.sweep
    finally:
        App.closeDocument(made.Name)


def test_a_robot_whose_wrist_is_not_at_sweep_radius_is_refused(doc):
    settings = next(o for o in doc.Objects if "SweepRadius" in o.PropertiesList)
    settings.SweepRadius = 250.0
    with pytest.raises(Exception, match="sweep_radius = 260"):
        scan_document(doc, "document")


waferscan = partial(commands.waferscan, timeout=600)  # slow scans through the command line


def test_cli_slow_scan_of_the_paper_with_jab_and_sweep_reports_front_and_sweep(tmp_path):
    # A sweep after a 5 mm jab from the paper's pose, whose tines are already in the wafers:
    # it cannot turn (SPEC §13 amended), bad input naming parameters.txt's sweep line.
    params = tmp_path / "parameters.txt"
    params.write_text("jab = 5\nsweep = 40\n")
    done = waferscan("scan", PAPER, "--mode", "slow", "--params", params)
    assert done.returncode == 2 and done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr == (f"waferscan: error: {params}:2: sweep: cannot turn at slot 1: before "
                           f"it turns, tine_left is inside LP1_W01 by 0.350 mm\n")
    params.write_text("jab = 5\n")
    out = tmp_path / "results.txt"
    done = waferscan("scan", PAPER, "--mode", "slow", "--params", params, "--json",
                     "--out", out)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    loaded = [s for s in data["slots"] if s["state"] == 1]
    # The paper's start pose already has the beam 16.6 mm into the wafers: front 0, and said.
    assert all(s["front"] == 0.0 for s in loaded)
    assert all(s["sweep"] is None and s["sweep_reached"] is None for s in loaded)
    assert data["slots"][2]["front"] is None and data["slots"][2]["sweep"] is None
    assert "cannot tell a protruding wafer" in done.stderr
    assert data["durations"]["slow"] > data["durations"]["fast"] > 0
    # SPEC §15: the 5 mm jab runs the tines 0.350 mm into the wafers, so the MCS is answered
    # status = error, with one collision line per motion that comes too close, and no table
    # (the robot must not run it).
    text = out.read_text()
    assert "\nstatus = error\n" in text and "\nclearance_min = 0.5\n" in text
    collisions = [line for line in text.splitlines() if line.startswith("collision = ")]
    assert any("slot 1 jab advanced" in line for line in collisions)
    assert all("tine_" in line for line in collisions)
    assert "slot\t" not in text
    assert data["clearance"]["contacts"] == len(collisions)


def test_cli_example_prints_pockets_and_durations():
    done = waferscan("scan", EXAMPLE)
    assert done.returncode == 0, done.stderr
    assert "code 1111221601220001010000010" in done.stdout
    row = [line.split() for line in done.stdout.splitlines() if line.split()[:1] == ["8"]][-1]
    assert row[2:4] == ["5.000", "10.000"]  # front, and a seated wafer's
    assert row[-3:] == ["-0.339", "..", "+0.339"]  # the angles turned
    assert "simulated duration: fast 2.70 s" in done.stdout
    # SPEC §13 amended: the sweeps stop short of the wafers, still blocked: no position judged.
    assert "slot 3: the sweep stopped where the fork comes within clearance_min" in done.stderr
    assert "to the right" not in done.stderr and "contact" not in done.stderr


def test_bad_slow_settings_name_file_line_and_key(tmp_path):
    scenario = tmp_path / "bad.toml"
    scenario.write_text(EXAMPLE.read_text().replace("sweep = 40.0", "sweep = 120.0"))
    done = waferscan("scan", scenario)
    line = EXAMPLE.read_text().splitlines().index(
        next(s for s in EXAMPLE.read_text().splitlines() if s.startswith("sweep ="))) + 1
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith(f"waferscan: error: {scenario}:{line}: [scan] sweep: must be "
                                  f"at most 90"), done.stderr
    params = tmp_path / "parameters.txt"
    params.write_text("# slow\njab = -2\n")
    done = waferscan("scan", EXAMPLE, "--params", params)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr == f"waferscan: error: {params}:2: jab: must not be negative, got ' -2'\n"


def test_a_jab_beyond_the_arms_reach_is_refused_naming_the_joint():
    from waferscan.core.errors import InputError

    # Wafers of 150 mm: the fork's tines (x = ±80) pass beside them, so a 600 mm jab is not
    # refused for striking them (core/files/validation.py) and meets the arm's reach instead.
    carrier = replace(LAYOUT.scanned_carrier, wafer_diameter=150.0, support_span=140.0)
    small = build_document(replace(LAYOUT, carriers=(carrier,), wafers=()), "SlowScanReach")
    try:
        settings = next(o for o in small.Objects if "Jab" in o.PropertiesList)
        settings.Jab = 600.0
        with pytest.raises(InputError,
                           match=r"the jab of 600 mm at .*(arm reaches|beyond its limits)"):
            scan_document(small, "document")
    finally:
        App.closeDocument(small.Name)


def test_the_documents_reader_refuses_a_jab_into_the_seated_wafers(doc):
    # One check for every reader (core/files/validation.py): the tines (the beam's ends at x = ±80,
    # y = 240) reach a seated wafer's rim after 400 - sqrt(150² - 80²) - 240 = 33.114 mm.
    from waferscan.core.errors import InputError

    settings = next(o for o in doc.Objects if "Jab" in o.PropertiesList)
    settings.Jab = 33.0
    assert read_layout(doc).scan.jab == pytest.approx(33.0)
    settings.Jab = 40.0
    with pytest.raises(InputError) as caught:
        read_layout(doc)
    assert f"{settings.Label}.Jab: 40 mm would drive the fork's tines" in str(caught.value)
    assert "after 33.114 mm" in str(caught.value)
    settings.Jab = 20.0
    settings.SweepRadius = 2e6
    with pytest.raises(InputError, match=rf"{settings.Label}\.SweepRadius: must be at most "):
        read_layout(doc)
