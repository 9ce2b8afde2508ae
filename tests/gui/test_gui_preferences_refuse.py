"""Issue 27 item 14 in a real FreeCAD GUI: the WaferScan preferences page refuses a bad value in
place (the field marked red with the reason beside it, a message at the top, OK and Apply kept
from storing it) instead of closing and dropping the whole Sensor group with a line in the hidden
Report view; OK with no edits stores nothing; "−1 mm" says it must be positive; the locale's
decimal comma is accepted."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("preferences_refuse_probe.py")
ARTIFACTS = REPO / "test-artifacts"
SHOT = ARTIFACTS / "gui-preferences-refused.png"


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    SHOT.unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_ok_with_no_edits_stores_nothing(gui):
    assert gui["stored_before"] == {}
    assert gui["untouched_page"]["ok_enabled"] is True and gui["untouched_page"]["problem"] == ""
    assert gui["stored_untouched"] == {}


def test_bad_values_are_marked_in_place_with_their_reasons(gui):
    page = gui["bad_page"]
    assert page["ok_enabled"] is False and page["apply_enabled"] in (False, None)
    assert page["problem"].startswith("3 fields marked in red need correcting")
    reasons = {name: [f["red"], f["reason"], f["reason_visible"]]
               for name, f in page["fields"].items()}
    assert reasons == {
        "PositionTolerance": [True, "'−1 mm' must be positive or 0", True],
        "ThresholdOff": [True, "threshold OFF 0.9 must not exceed threshold ON 0.5", True],
        "SensorResponse": [True, "'abc' is not a time (give s, ms or µs)", True]}


def test_ok_keeps_the_dialog_open_and_stores_nothing_while_a_field_is_bad(gui):
    assert gui["open_after_ok"] is True
    assert gui["stored_while_bad"] == {}


def test_corrected_with_a_decimal_comma_ok_stores_only_the_edits(gui):
    page = gui["good_page"]
    assert page["ok_enabled"] is True and page["problem"] == ""
    assert all(not f["red"] and not f["reason_visible"] for f in page["fields"].values())
    assert gui["open_after_good_ok"] is False
    assert gui["stored_good"] == {"PositionTolerance": 0.25, "ThresholdOff": 0.4,
                                  "SensorResponse": pytest.approx(0.0005)}


def test_a_bad_value_stored_by_hand_is_marked_but_blocks_ok_only_once_the_page_is_edited(gui):
    """It greyed OK for the whole preferences dialog (every page) until it was corrected."""
    page = gui["hand_page"]
    assert gui["hand_on_red"] is True  # ThresholdOn 2.0, set in the parameter editor
    assert page["ok_enabled"] is True and "not used" in page["problem"], page
    edited = gui["hand_edited_page"]
    assert edited["ok_enabled"] is False and "need" in edited["problem"]


def test_screenshot_saved():
    assert SHOT.stat().st_size > 1000
