"""SPEC §10's settings through the document: the ScanSettings object carries them in units,
they survive save and reload, a bad value names the object and property, and the command
line scans with them."""

import json
from dataclasses import replace

import FreeCAD as App
import pytest
from commands import waferscan
from scenarios import PAPER_TEXT, with_lines

from waferscan.addon import paper_scenario
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import read_layout
from waferscan.core.errors import InputError
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.spot import Amplifier, BeamSpot

PAPER = read_scenario(paper_scenario())
SENSED = replace(PAPER.with_scan(latch="sampled", acceleration=2500.0, sample_period=0.0005,
                                 scan_speed=200.0, sensor_response=250e-6),
                 robot=None, spot=BeamSpot(width=2.0, height=0.8), amplifier=Amplifier(0.6, 0.3))


@pytest.fixture
def doc(built):
    return built(SENSED, "SensorTest")


def test_the_settings_object_carries_the_sensor_in_units(doc, tmp_path):
    settings = doc.getObject("ScanSettings")
    assert settings.SpotWidth.Value == 2.0 and str(settings.SpotWidth.Unit) == str(
        App.Units.Length)
    assert settings.SpotHeight.Value == 0.8 and settings.SpotDiameter.Value == 0.0
    assert (settings.ThresholdOn, settings.ThresholdOff) == (0.6, 0.3)
    assert settings.Acceleration.Value == 2500.0 and settings.Latch == "sampled"
    read = read_layout(doc)
    assert (read.spot, read.amplifier) == (SENSED.spot, SENSED.amplifier)
    assert (read.scan.latch, read.scan.acceleration, read.scan.sample_period) == \
        ("sampled", 2500.0, 0.0005)
    path = tmp_path / "sensed.FCStd"
    doc.saveCopy(str(path))
    again = App.openDocument(str(path))
    try:
        reread = read_layout(again)
        assert (reread.spot, reread.amplifier, reread.scan) == (read.spot, read.amplifier,
                                                                 read.scan)
    finally:
        App.closeDocument(again.Name)


def test_the_document_scans_as_the_core_does(doc):
    through_document = scan_document(doc)
    direct = scan_layout(read_layout(doc))
    assert through_document.runs == direct.runs and through_document.edges == direct.edges
    assert through_document.code == direct.code
    assert len(direct.edges) == 2 * len(direct.runs) and direct.edges[0]["edge"] == "on"


def test_a_bad_threshold_names_the_object_and_property(doc):
    doc.getObject("ScanSettings").ThresholdOff = 0.9
    with pytest.raises(InputError) as caught:
        read_layout(doc)
    assert "ScanSettings.ThresholdOff" in str(caught.value)
    assert "must not exceed threshold_on 0.6" in str(caught.value)


def test_an_ideal_document_reads_as_before(tmp_path):
    plain = build_document(replace(PAPER, robot=None), "PlainTest")
    try:
        read = read_layout(plain)
        assert read.spot is None and read.amplifier is None and read.scan == PAPER.scan
    finally:
        App.closeDocument(plain.Name)


def test_cli_scan_with_a_spot_and_its_errors(tmp_path):
    scenario = tmp_path / "spot.toml"
    text = PAPER_TEXT
    scenario.write_text(with_lines(text, "sensor", "spot_diameter = 1.0"))
    done = waferscan("scan", scenario, "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["code"] == "1101221001220001010000010"
    assert data["params"]["spot_diameter"] == 1.0
    assert [e["edge"] for e in data["edges"][:2]] == ["on", "off"]
    bad = tmp_path / "bad.toml"
    bad.write_text(with_lines(text, "sensor", "threshold_on = 2"))
    done = waferscan("scan", bad)
    line = text.splitlines().index("[sensor]") + 2
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {bad}:{line}: [sensor] threshold_on: ")
    assert "Traceback" not in done.stderr
    done = waferscan("scan", scenario, "--json", "--engine", "loop")
    assert done.returncode == 2 and "analytic engine only" in done.stderr


def test_settings_made_without_the_sensor_properties_read_as_the_ideal_sensor():
    # The GUI's Run scan adds a ScanSettings object of its own (features.make_settings) to a
    # document of tagged solids: none of SPEC §10's properties are on it.
    from waferscan.cad.features import make_settings

    plain = build_document(replace(PAPER, robot=None), "BareSettings")
    try:
        plain.removeObject("ScanSettings")
        make_settings(plain, PAPER.scan, PAPER.mapping, None)
        read = read_layout(plain)
        assert read.spot is None and read.amplifier is None and read.scan.latch == "step"
    finally:
        App.closeDocument(plain.Name)


def test_crosscheck_of_a_spot_layout_confirms_its_line_beam(tmp_path):
    # At threshold 0.1 a 1 mm spot's runs start below the wafers, where the line is clear:
    # crosscheck judges the geometry, the line beam's edges, and confirms them.
    from waferscan.cad.crosscheck import crosscheck

    layout = replace(PAPER, robot=None, spot=BeamSpot(diameter=1.0), amplifier=Amplifier(0.1))
    doc = build_document(layout, "SpotCheck")
    try:
        spotted = scan_document(doc)
        assert spotted.runs[0].bottom < PAPER.wafers[0].center[2] - 0.2
        check = crosscheck(doc)
        assert check.ok and len(check.runs) == 10
        assert check.result.runs == scan_layout(replace(layout, spot=None,
                                                        amplifier=None)).runs
    finally:
        App.closeDocument(doc.Name)
