"""One validation for every reader (core.files.validation): values that pass their own checks but
overflow together, and a FreeCAD layout's carrier and scanner properties, are bad input with the
reader's own file, line, key or property — never a traceback, an empty code or a wrong one."""

import math

import FreeCAD as App
import pytest
from commands import waferscan as cli
from scenarios import paper_with

from waferscan.addon import paper_scenario
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.core.errors import InputError
from waferscan.core.files.mcs import apply_parameters, parse_parameters
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

PAPER = read_scenario(paper_scenario())


def object_labelled(doc, label):
    return doc.getObjectsByLabel(label)[0]


@pytest.mark.parametrize("prop, value, message", [
    ("Pitch", 0.0, "LP1.Pitch: the pitch must be greater than 0"),
    ("Pitch", math.nan, "LP1.Pitch: the pitch must be greater than 0"),
    ("SlotCount", 0, "LP1.SlotCount: expected a whole number of slots from 1 to 10,000, got 0"),
    ("SlotCount", -5, "LP1.SlotCount: expected a whole number of slots from 1 to 10,000, got -5"),
    ("SlotCount", 10_000_000, "LP1.SlotCount: expected a whole number of slots from 1 to 10,000"),
    ("WaferThickness", 0.0, "LP1.WaferThickness: the wafer thickness must be greater than 0"),
    ("WaferThickness", math.nan, "LP1.WaferThickness: the wafer thickness must be greater"),
    ("WaferThickness", 20.0, "LP1.WaferThickness: wafer_thickness 20 must be less than the "
                             "pitch 10"),
])
def test_carrier_properties_are_checked(paper_doc, prop, value, message):
    carrier = next(o for o in paper_doc.Objects if "SlotCount" in o.PropertiesList)
    setattr(carrier, prop, value)
    with pytest.raises(InputError) as caught:
        scan_document(paper_doc, "analytic")
    assert str(caught.value).startswith(f"{paper_doc.Name}: ")
    assert message.replace("LP1", carrier.Label) in str(caught.value)


@pytest.mark.parametrize("prop, value, message", [
    ("LiftAxis", (1, 0, 0), ".LiftAxis: the lift axis must point upwards"),
    ("LiftAxis", (0, 0, math.inf), ".LiftAxis: must be a finite, non-zero direction"),
    ("Emitter", (math.nan, 0, 0), ".Emitter: the emitter must be finite"),
    ("Receiver", (math.inf, 0, 0), ".Receiver: "),
])
def test_scanner_properties_are_checked(paper_doc, prop, value, message):
    scanner = next(o for o in paper_doc.Objects if "LiftAxis" in o.PropertiesList)
    setattr(scanner, prop, App.Vector(*value))
    with pytest.raises(InputError) as caught:
        scan_document(paper_doc, "analytic")
    assert f"{scanner.Label}{message}" in str(caught.value)


def line_of(path, text):
    return next(n for n, line in enumerate(path.read_text().split("\n"), 1) if text in line)


def test_scenario_overflowing_lag_is_bad_input(tmp_path):
    path = paper_with(tmp_path, "[scan]\n",
                      "[scan]\nscan_speed = 1e200\nsensor_response = 1e200\n")
    with pytest.raises(InputError) as caught:
        read_scenario(path)
    assert caught.value.line == line_of(path, "sensor_response = 1e200")
    assert "[scan] sensor_response: scan_speed 1e+200 mm/s × sensor_response 1e+200 s makes " \
           "the sensor latch inf mm late; at most 100,000 mm" in str(caught.value)


def test_scenario_base_yaw_is_bounded(tmp_path):
    path = paper_with(tmp_path, "base_yaw = 0.0", "base_yaw = 1e308")
    with pytest.raises(InputError) as caught:
        read_scenario(path)
    assert caught.value.line == line_of(path, "base_yaw")
    assert "[robot] base_yaw: must be within ±360 degrees, got 1e+308" in str(caught.value)


@pytest.mark.parametrize("text, key, message", [
    ("scan_speed = 1e200\nsensor_response = 1e200\n", "sensor_response", "latch inf mm late"),
    ("scan_speed = 1e200\nsensor_response = 1e200\ndirection = updown\n", "sensor_response",
     "latch inf mm late"),
    ("first_slot_z = 1e308\nmode = slow\n", "first_slot_z",
     "first_slot_z must be within ±1,000,000 mm"),
    ("slot_pitch = 1e308\nmode = slow\n", "slot_pitch", "the pitch must be greater than 0 and "
                                                       "at most 1,000,000 mm"),
])
def test_parameters_that_overflow_together_are_bad_input(text, key, message):
    parameters = parse_parameters(text, "parameters.txt")
    with pytest.raises(InputError) as caught:
        scan_layout(apply_parameters(PAPER, parameters))
    assert caught.value.line == parameters.lines[key]
    assert f"parameters.txt:{parameters.lines[key]}: {key}: " in str(caught.value)
    assert message in str(caught.value)


def test_a_valid_layout_still_scans(paper_doc):
    assert scan_document(paper_doc, "analytic").code == scan_layout(PAPER).code


def test_a_urdf_that_is_not_urdf_is_bad_input(tmp_path):
    (tmp_path / "robot.urdf").write_text("not xml at all\n")
    path = paper_with(tmp_path, "base_yaw = 0.0", 'base_yaw = 0.0\nurdf = "robot.urdf"')
    with pytest.raises(InputError) as caught:
        build_document(read_scenario(path), "BadUrdf")
    assert str(caught.value).startswith(f"{tmp_path / 'robot.urdf'}: not a URDF robot WaferScan "
                                        "can move (The file")
    assert "\n" not in str(caught.value)


def test_the_command_line_refuses_overflows_with_exit_2(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("scan_speed = 1e200\nsensor_response = 1e200\n")
    done = cli("scan", paper_scenario(), "--params", params)
    assert (done.returncode, done.stderr) == (2, (
        f"waferscan: error: {params}:2: sensor_response: scan_speed 1e+200 mm/s × "
        "sensor_response 1e+200 s makes the sensor latch inf mm late; at most 100,000 mm\n"))
    bad = paper_with(tmp_path, "base_yaw = 0.0", "base_yaw = 1e308")
    expected = f"waferscan: error: {bad}:{line_of(bad, 'base_yaw')}: [robot] base_yaw: must " \
               "be within ±360 degrees, got 1e+308\n"
    for args in (("crosscheck", bad), ("watch", tmp_path, "--layout", bad, "--once")):
        done = cli(*args)
        assert (done.returncode, done.stderr) == (2, expected)
