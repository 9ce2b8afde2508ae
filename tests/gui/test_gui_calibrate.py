"""The Calibrate command (SPEC §11) in a real FreeCAD GUI: on a carrier built 0.3 mm above the
taught seat at a 10.02 mm pitch, the dialog shows the current recipe beside the calibrated one,
as the core calibration gives them, and the check scan's code; Save recipe… writes what
`waferscan calibrate --out` writes, Apply to document writes the recipe into the layout in one
undo step, recorded as a line that replays without a dialog; a layout without a top reference
gets the failure's words."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.calibration import calibrate
from waferscan.core.scan.layout_scan import scan_layout

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("calibrate_probe.py")
PAPER_TEXT = (REPO / "resources" / "examples" / "paper.toml").read_text()
LOAD = "1100100001000010000100011"


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    """The paper's carrier as taught (slot 1 at 293.94, pitch 10), its wafers where a carrier
    0.3 mm higher at a 10.02 mm pitch holds them: references in slots 1 and 25, others between.
    The document's carrier is the taught recipe; the wafers are what the sensor finds."""
    path = tmp_path_factory.mktemp("gui-calibrate") / "drifted.toml"
    wafers = "".join(f"\n[[wafer]]\ncenter = [0.0, 400.0, {294.24 + (slot - 1) * 10.02!r}]\n"
                     f"normal = [0.0, 0.0, 1.0]\ndiameter = 300.0\nthickness = 0.7\n"
                     for slot, state in enumerate(LOAD, 1) if state == "1")
    path.write_text(PAPER_TEXT.replace('load = "1101221001220001010000010"', f'load = "{"0" * 25}"')
                    + wafers)
    return path


@pytest.fixture(scope="module")
def gui(run_gui_probe, scenario):
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(scenario),
                         WAFERSCAN_GUI_RECIPE=str(scenario.with_name("gui-recipe.txt")),
                         WAFERSCAN_GUI_ARTIFACTS=str(REPO / "test-artifacts"))


def test_the_dialog_shows_the_current_recipe_beside_the_calibrated_one(gui, scenario):
    expected = calibrate(read_scenario(scenario), scan_layout)
    assert gui["visible"] and gui["title"] == "WaferScan calibration: drifted"
    table = gui["table"]
    assert [row[0] for row in table] == [key for key, _, _ in expected.rows()]
    shown = {key: (old, new) for key, old, new in table}
    for key, old, new in expected.rows():
        assert shown[key] == (f"{old:.4f}" if isinstance(old, float) else str(old),
                              f"{new:.4f}" if isinstance(new, float) else str(new)), key
    # taught 293.94 and 10; the wafers' seats come back to within a step
    assert shown["first_slot_z"][0] == "293.9400" and shown["slot_pitch"][0] == "10.0000"
    assert abs(float(shown["first_slot_z"][1]) - 294.24) < 0.05
    assert abs(float(shown["slot_pitch"][1]) - 10.02) < 0.05 / 24
    assert f"slot code <b>{LOAD}</b>" in gui["check"]


def test_a_layout_without_a_top_reference_reports_the_failure(gui):
    (text,) = gui["error_boxes"]
    assert re.match(r"Calibration of paper\d* failed: no-top-wafer: no wafer in the top slot "
                    r"\(slot 25\): the highest run, ", text)
    assert text.endswith("is nearest slot 24's seat")


def test_save_recipe_writes_what_the_command_line_writes_byte_for_byte(gui, scenario):
    cli = scenario.with_name("cli-recipe.txt")
    subprocess.run([sys.executable, "-m", "waferscan.cli", "calibrate", str(scenario), "--out",
                    str(cli)], check=True, cwd=REPO, capture_output=True, timeout=300)
    assert gui["buttons"][-3:] == ["Save recipe…", "Apply to document", "Close"] or \
        set(gui["buttons"]) == {"Save recipe…", "Apply to document", "Close"}
    assert gui["recipe"].encode("utf-8") == cli.read_bytes()
    assert gui["recipe"] == scenario.with_name("gui-recipe.txt").read_text(encoding="utf-8")
    assert gui["status_after_save"].startswith("Recipe saved to ")
    assert gui["undo_after_save"] == gui["undo_before"]  # the document is not touched
    assert [p.name for p in scenario.parent.iterdir() if p.name.startswith(".")] == []


def _recipe(text):
    return dict(line.split(" = ") for line in text.splitlines() if " = " in line)


def test_apply_writes_the_recipe_into_the_document_in_one_undo_step(gui):
    recipe = _recipe(gui["recipe"])
    before, applied = gui["values_before"], gui["values_applied"]
    assert before == {"Pitch": 10.0, "SlotOriginZ": 0.0, "StartZ": 280.0, "FinalZ": 550.0,
                      "ThicknessCorrection": 1.0}
    assert applied["Pitch"] == float(recipe["slot_pitch"]) == 10.021
    assert 293.94 + applied["SlotOriginZ"] == pytest.approx(float(recipe["first_slot_z"]),
                                                             abs=1e-9)
    assert applied["StartZ"] == float(recipe["start_z"])
    assert applied["FinalZ"] == float(recipe["final_z"])
    assert applied["ThicknessCorrection"] == float(recipe["thickness_correction"]) == 0.964286
    assert gui["code_before"] != LOAD and gui["code_after_apply"] == LOAD
    assert gui["undo_after_apply"] == ["Apply calibration"] + gui["undo_before"]
    assert gui["enabled_after_apply"] == [False, False]
    assert "Applied to drifted as one undo step" in gui["status_after_apply"]
    assert gui["messages_after_apply"] == []
    # Edit → Undo restores every value
    assert gui["values_undone"] == before and gui["code_undone"] == gui["code_before"]


def test_the_buttons_are_recorded_lines_that_replay_without_a_dialog(gui, scenario):
    recipe = str(scenario.with_name("gui-recipe.txt"))
    calls = gui["console_calls"]
    assert f"waferscan.gui.commands.save_calibration_recipe(App.getDocument('drifted'), " \
        f"{recipe!r})" in calls
    assert "waferscan.gui.commands.apply_calibration(App.getDocument('drifted'))" in calls
    assert gui["modal_after_replay"] is False
    assert gui["values_replayed"] == gui["values_applied"]
    assert gui["undo_after_replay"][0] == "Apply calibration"


def test_the_recorded_lines_on_a_layout_that_cannot_be_calibrated_say_so(gui):
    assert len(gui["failed_lines"]) == 2
    apply, save = gui["failed_lines"]
    assert re.match(r"Apply calibration of paper\d*: nothing done: no-top-wafer: ", apply)
    assert re.match(r"Save recipe of paper\d*: nothing done: no-top-wafer: ", save)
    assert gui["failed_undo_unchanged"] and not gui["failed_file"]


def test_a_calibration_shown_is_not_applied_to_a_layout_edited_since(gui):
    assert gui["stale_messages"] == ["Apply to document: drifted changed since this "
                                     "calibration: run Calibrate again"]
    assert gui["stale_unchanged"] == [True, "Edit"]
