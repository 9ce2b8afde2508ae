"""Issue 27 item 13 in a real FreeCAD GUI under the "Imperial decimal" unit schema: the Recipe
and "Sensor and slow scan" sections and the results table show inches (and the schema's
acceleration unit), typed values in any unit are understood, "−1 mm" is refused as not positive,
and the locale's decimal comma is accepted. A document saved with ScanSettings version 1 (times
in s, a negative thickness tolerance for half the thickness) opens migrated, and the property
editor shows the times in ms, the wrist's rates with their unit in the name and the thickness
tolerance in inches with its box."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("units_probe.py")
ARTIFACTS = REPO / "test-artifacts"
SHOTS = ("gui-units-inch-sections.png", "gui-units-inch-applied.png",
         "gui-units-inch-results.png", "gui-units-inch-property-editor.png")


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    for name in SHOTS:
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_the_recipe_shows_inches(gui):
    assert gui["schema"].startswith("Imperial decimal")
    assert gui["recipe_labels"] == ["Thickness min", "Thickness max", "Cross beyond",
                                    "Below seat", "Above seat"]  # no "(mm)"
    # SPEC §4's limits from t = 0.7, Δt = 0.35, Δp = 0.5 mm, in inches
    assert gui["recipe_placeholders"] == {
        "ThicknessMin": "0.0137795 in", "ThicknessMax": "0.0413386 in",
        "DoubleThreshold": "0.0688976 in", "PositionBelow": "0.019685 in",
        "PositionAbove": "0.019685 in"}


def test_the_sensor_section_shows_the_schemas_units(gui):
    assert gui["sensor_labels"]["Acceleration"] == "Acceleration"
    assert gui["sensor_labels"]["SamplePeriodMs"] == "Sample period"
    assert gui["sensor_texts"]["SpotDiameter"] == "0 in"
    assert gui["sensor_texts"]["Jab"] == "0 in"
    assert gui["sensor_texts"]["Acceleration"] == "0 in/min^2"
    assert gui["sensor_texts"]["SamplePeriodMs"] == "0 s"


def test_the_results_table_headers_and_lengths_are_in_inches(gui):
    assert gui["headers"][:7] == ["Slot", "Slot Z [in]", "Wafer", "IN [in]", "OUT [in]",
                                  "Diff [in]", "State"]
    slot, seat, _, z_in, z_out, diff, _ = gui["first_row"][:7]
    assert slot == "1" and float(diff) == pytest.approx(0.65 / 25.4, abs=1e-5)
    assert float(z_out) - float(z_in) == pytest.approx(float(diff), abs=2e-5)  # each rounded


def test_the_exported_csv_stays_in_mm(gui):
    assert gui["csv_lines"] == ["Slot,Slot Z [mm],Wafer,IN [mm],OUT [mm],Diff [mm],State",
                                "1,293.94,LP1_W01,293.950,294.600,0.650,present"]


def test_minus_one_mm_is_refused_as_not_positive(gui):
    assert gui["negative_applied"] is False
    assert gui["negative_message"] == "Not written: Thickness max: '−1 mm' must be positive or 0"
    assert gui["after_negative"] == [False, 0]


def test_inches_and_a_decimal_comma_are_understood(gui):
    assert gui["good_applied"] is True
    assert gui["good_message"] == ("Written: ThicknessMin, ThicknessMinSet, ThicknessMax, "
                                   "ThicknessMaxSet. Run scan or Replay to judge by them.")
    min_mm, min_set, max_mm, max_set, double_set, steps, name = gui["after_good"]
    assert min_mm == pytest.approx(0.026 * 25.4) and max_mm == pytest.approx(1.05)
    assert (min_set, max_set, double_set, steps, name) == (True, True, False, 1,
                                                         "WaferScan recipe")
    # shown back from the document in inches, with the German decimal comma
    assert gui["recipe_reloaded"] == {"ThicknessMin": "0,026 in", "ThicknessMax": "0,0413386 in",
                                      "DoubleThreshold": "", "PositionBelow": "",
                                      "PositionAbove": ""}


def test_a_time_and_an_acceleration_typed_with_their_units(gui):
    assert gui["sensor_applied"] is True, gui["sensor_message"]
    period, acceleration, latch = gui["after_sensor"]
    assert period == pytest.approx(0.5) and acceleration == pytest.approx(2000.0)  # ms, mm/s²
    assert latch == "sampled"
    # the acceleration in the schema's own unit, as the property editor shows it
    assert gui["sensor_reloaded"] == {"SamplePeriodMs": "0,5 ms",
                                      "Acceleration": "283465 in/min^2"}


def test_a_document_saved_the_old_way_is_shown_and_written_in_its_convention(gui):
    # limits as bare floats in mm, -1 for "not set": shown in inches, blanks not set
    assert gui["old_shown"] == {"ThicknessMin": "0,0259843 in", "ThicknessMax": "",
                                "DoubleThreshold": "", "PositionBelow": "", "PositionAbove": ""}
    assert gui["old_applied"] is True, gui["old_message"]
    assert gui["old_after"] == ["App::PropertyFloat", 0.66, 1.1, -1.0, 1]
    assert gui["old_read"] == [0.66, 1.1, None]


def test_the_property_editor_names_the_units_of_a_migrated_document(gui):
    # saved by the code before (SensorResponse 0.00025 s, SamplePeriod 0.0005 s, the tolerance
    # a float 0.3), opened: migrated to ScanSettings version 2
    assert gui["version1"] == [2, 0.25, 0.5, pytest.approx(0.3), True]
    # the Data tab shows a float with the schema's 2 decimals (German comma): the times in ms
    # read 0,25 and 0,50 (in s both would read 0,00); the unit is in each float's name
    assert gui["editor"] == {
        "SensorResponseMs": ["Sensor Response Ms", "0,25"],
        "SamplePeriodMs": ["Sample Period Ms", "0,50"],
        "WristSpeedDegPerS": ["Wrist Speed Deg Per S", "45,00"],
        "WristAccelerationDegPerS2": ["Wrist Acceleration Deg Per S2", "180,00"],
        # a length in the user's schema (0.3 mm = 0.0118 in), its box beside it
        "ThicknessTolerance": ["Thickness Tolerance", "0,01 in"],
        "ThicknessToleranceSet": ["Thickness Tolerance Set", "True"],
        "PositionTolerance": ["Position Tolerance", "0,02 in"]}


def test_screenshots_saved():
    for name in SHOTS:
        assert (ARTIFACTS / name).stat().st_size > 1000
