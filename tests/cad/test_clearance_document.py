"""SPEC §15 through the FreeCAD document and the command line: the document's robot (its taught
pose, its URDF's collision geometry) or, without one, the scanner's heads; a contact is a warning
on stderr and in JSON, and results.txt answers status = error; a bad clearance_min is bad input.

Hand numbers (tests/robot/test_clearance.py): in the paper's layout the tines' inner tip corners
pass sqrt(70² + 133.4²) - 150 = 0.650 mm from the wafers' rims; without the robot the emitter's
head (radius 3 mm) passes sqrt(80² + 133.4²) - 153 = 2.549 mm from them."""

import json
import math
from dataclasses import replace

import FreeCAD as App
import pytest
from commands import waferscan
from scenarios import PAPER

from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.core.files.scenario import read_scenario

TINE_CORNER = math.hypot(70.0, 133.4) - 150.0
EMITTER_HEAD = math.hypot(80.0, 133.4) - 153.0


def test_the_document_robot_gives_the_paper_its_least_clearance():
    doc = build_document(read_scenario(PAPER), "ClearancePaper")
    try:
        report = scan_document(doc).clearance
        assert report.body == "robot"
        assert report.least.distance == pytest.approx(TINE_CORNER, abs=1e-6)
        assert report.least.part in ("tine_left", "tine_right")
        assert not report.contacts  # paper.toml accepts 0.5 mm
        assert scan_document(doc, clearance=False).clearance is None
    finally:
        App.closeDocument(doc.Name)


def test_without_a_robot_the_scanner_heads_stand_in_and_outputs_stay_as_they_were(tmp_path):
    doc = build_document(replace(read_scenario(PAPER), robot=None), "ClearanceScanner")
    try:
        result = scan_document(doc)
        assert result.clearance.body == "scanner"
        assert result.clearance.least.distance == pytest.approx(EMITTER_HEAD, abs=1e-6)
        assert result.clearance.least.part in ("emitter head", "receiver head")  # symmetric
        from waferscan.core.files.mcs import format_results

        # No robot and no contact: results.txt as before the clearance check.
        assert format_results(1, "SCF", result, timestamp="T") == \
            format_results(1, "SCF", replace(result, clearance=None), timestamp="T")
    finally:
        App.closeDocument(doc.Name)


def test_a_contact_warns_on_stderr_and_refuses_the_scan_in_results_txt(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("clearance_min = 1.0\n")
    out = tmp_path / "results.txt"
    done = waferscan("scan", PAPER, "--params", params, "--json", "--out", out)
    assert done.returncode == 0, done.stderr
    warning = [line for line in done.stderr.splitlines() if "contact:" in line]
    assert len(warning) == 1 and warning[0].startswith("waferscan: warning: contact: 0.650 mm "
                                                       "between tine_")
    data = json.loads(done.stdout)
    assert data["clearance"]["contacts"] == 1 and data["clearance"]["clearance_min"] == 1.0
    (motion,) = data["clearance"]["motions"]
    assert motion["motion"] == "stroke" and motion["distance"] == pytest.approx(TINE_CORNER)
    assert any(w.startswith("contact: 0.650 mm") for w in data["warnings"])
    lines = out.read_text().splitlines()
    assert "status = error" in lines and "clearance_min = 1.0" in lines
    assert "clearance = 0.650" in lines
    assert [line for line in lines if line.startswith("collision = 0.650 mm between tine_")]


@pytest.mark.parametrize("text, line", [("clearance_min = -1\n", 1),
                                        ("start_z = 280\nclearance_min = wide\n", 2)])
def test_a_bad_clearance_min_is_bad_input_naming_file_and_line(tmp_path, text, line):
    params = tmp_path / "parameters.txt"
    params.write_text(text)
    done = waferscan("scan", PAPER, "--params", params)
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {params}:{line}: clearance_min: ")
    assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1


def test_a_bad_clearance_min_in_a_scenario_names_its_line(tmp_path):
    scenario = tmp_path / "paper.toml"
    text = PAPER.read_text().replace("clearance_min = 0.5", "clearance_min = -0.5")
    scenario.write_text(text)
    number = text.splitlines().index("clearance_min = -0.5") + 1
    done = waferscan("scan", scenario)
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {scenario}:{number}: ")
    assert "clearance_min" in done.stderr and "Traceback" not in done.stderr
