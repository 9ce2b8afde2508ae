"""The scan panel's "Sensor and slow scan" section (issues 14 and 17) in a real FreeCAD GUI:
values shown from ScanSettings, collapsed by default; a value the document's reader refuses is
refused in the panel with nothing written; a good one is written in one undo step and the
Replay scans with it: a 2 mm spot misses the paper's single 0.7 mm wafers (closed form of a
round spot cut by a band), a 5 mm jab in slow mode gives each pocket a front."""

import math
from pathlib import Path

import pytest

from waferscan.core.sensor.spot import DEFAULT_AMPLIFIER

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("sensor_section_probe.py")
ARTIFACTS = REPO / "test-artifacts"


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    (ARTIFACTS / "gui-scan-panel-sensor.png").unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def blocked_fraction(thickness, diameter):
    """The largest fraction of a round spot a horizontal band of ``thickness`` covers: the band
    centred on the spot, area 2(h·sqrt(r²-h²) + r²·asin(h/r)) over π r²."""
    u = min(thickness / diameter, 1.0)
    return 2.0 / math.pi * (math.asin(u) + u * math.sqrt(1.0 - u * u))


def test_the_section_shows_the_settings_collapsed(gui):
    assert gui["collapsed_visible"] is False and gui["expanded_visible"] is True
    shown = gui["shown_values"]
    assert float(shown["ThresholdOn"]) == DEFAULT_AMPLIFIER.threshold_on
    assert shown["SpotDiameter"].startswith("0") and shown["Jab"].startswith("0")
    assert gui["shown_latch"] == "step"


def test_a_refused_value_writes_nothing(gui):
    assert gui["bad_applied"] is False
    assert "ThresholdOff" in gui["bad_message"] and "must not exceed" in gui["bad_message"]
    spot, off, undo_steps = gui["after_bad"]
    assert spot == 0.0 and off == float(gui["shown_values"]["ThresholdOff"]) and undo_steps == 0


def test_a_good_value_is_one_undo_step(gui):
    assert gui["good_applied"] is True
    spot, _, undo_steps, name = gui["after_good"]
    assert spot == 2.0 and undo_steps == 1 and name == "WaferScan sensor and slow scan"
    assert "SpotDiameter" in gui["good_message"]


def test_replay_scans_with_the_spot_and_misses_the_thin_wafers(gui):
    assert gui["spot_params"] == [2.0]
    assert blocked_fraction(0.7, 2.0) < DEFAULT_AMPLIFIER.threshold_on  # 0.436: never ON
    first, spotted = gui["first_code"], gui["spot_code"]
    singles = [i for i, state in enumerate(first) if state == "1"]
    assert singles  # the paper has correctly seated single wafers
    assert all(spotted[i] == "0" for i in singles), (first, spotted)
    assert spotted != first


def test_a_jab_in_slow_mode_gives_the_pockets_fronts(gui):
    assert gui["jab_scan"] == ["slow", 5.0]
    pockets = gui["pockets"]
    assert len(pockets) == 25
    fronts = {slot: front for slot, front in pockets if front is not None}
    occupied = {i + 1 for i, state in enumerate(gui["first_code"]) if state != "0"}
    assert fronts and set(fronts) <= occupied
    assert all(0.0 <= front <= 5.0 for front in fronts.values())


def test_sampled_latching_a_slit_and_the_acceleration_are_set_in_the_panel(gui):
    applied, message = gui["sampled_bare"]
    assert applied is False and "sample_period" in message
    assert gui["sampled_applied"] is True
    assert gui["sampled_read"] == ["sampled", 0.002, 1500.0, 2.0, 0.5, 0.0]
