"""The paper's experiment in the FreeCAD GUI: build it and scan it with the workbench's commands,
drive the animation from its task panel, and compare the results table, the slot-code dialog
and the cross-check with the headless scan."""

from pathlib import Path

import pytest

from waferscan.addon import paper_scenario
from waferscan.cad.crosscheck import crosscheck
from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import opened_layout
from waferscan.core.mapping import E87

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("scan_probe.py")
ARTIFACTS = REPO / "test-artifacts"
SHOTS = ("gui-results-table.png", "gui-slot-code.png", "gui-after-scan.png",
         "gui-during-scan.png", "gui-scan-panel.png", "gui-main-window.png")


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    return tmp_path_factory.mktemp("gui-scan") / "paper-scanned.FCStd"


@pytest.fixture(scope="module")
def gui(run_gui_probe, saved):
    for name in SHOTS:
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS),
                         WAFERSCAN_GUI_SAVE=str(saved))


@pytest.fixture(scope="module")
def headless():
    with opened_layout(paper_scenario()) as doc:
        result = scan_document(doc, "analytic")
        return result, crosscheck(doc, result)


def test_the_table_and_the_dialog_show_the_headless_results(gui, headless):
    result, _ = headless
    assert gui["dialog_code"] == gui["sheet_code"] == gui["clipboard"] == result.code
    assert result.code == "1101221001220001010000010"
    assert len(gui["rows"]) == 25
    expected = [[str(slot), f"{seat:.2f}", ", ".join(wafers) or "-",
                 "" if z_in is None else f"{z_in:.3f}", "" if z_out is None else f"{z_out:.3f}",
                 "" if diff is None else f"{diff:.3f}", state]
                for slot, seat, wafers, z_in, z_out, diff, state in result.table_rows()]
    assert gui["rows"] == expected
    assert gui["strip"] == [[str(s.slot), str(s.state)] for s in result.slot_map.slots]
    assert result.e87 in gui["e87_label"]
    assert "".join(str(E87[s.state]) for s in result.slot_map.slots) == result.e87


def test_the_csv_export_is_the_table(gui):
    import csv

    with open(gui["csv"], newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["Slot", "Slot Z [mm]", "Wafer", "IN [mm]", "OUT [mm]", "Diff [mm]", "State"]
    assert rows[1:] == gui["rows"]


def test_the_results_survive_save_and_reload_as_a_spreadsheet(gui, saved, headless):
    import FreeCAD as App

    result, _ = headless
    doc = App.openDocument(str(saved))
    try:
        sheet = doc.getObject("ScanResults")
        assert sheet.get("code") == result.code
        rows = [[str(sheet.get(f"{column}{row}")) if sheet.getContents(f"{column}{row}") else ""
                 for column in "ABCDEFG"] for row in range(2, 27)]
    finally:
        App.closeDocument(doc.Name)
    assert [row[0] for row in rows] == [str(s) for s in range(1, 26)]
    assert [row[6] for row in rows] == [r[6] for r in gui["rows"]]
    for column in (1, 3, 4, 5):  # numbers: slot Z, IN, OUT, diff
        assert [float(row[column]) if row[column] else None for row in rows] == \
            [float(r[column]) if r[column] else None for r in gui["rows"]]


def test_states_are_coloured_and_a_row_selects_its_wafer(gui):
    from waferscan.core.files.report import STATE_COLOURS

    colour = {code: "#%02x%02x%02x" % rgb for code, rgb in STATE_COLOURS.items()}
    codes = [int(c) for c in "1101221001220001010000010"]
    assert gui["state_colours"] == [colour[c] for c in codes]
    assert gui["selected"] == ["LP1_W01"]
    # The side view draws the runs in the colours of their slots' states.
    for code in (1, 2):
        assert colour[code] in gui["side_view_colours"]


def test_the_task_panel_pauses_and_shows_what_the_beam_sees(gui):
    assert gui["task_panel_shown"]
    assert gui["paused_running"] is False
    assert gui["paused_buttons"] == [True, False, True]
    assert gui["paused_beam_label"] == "blocked by LP1_W04"
    assert 336.6 <= gui["paused_z"] <= 341.95  # the cross-slotted wafer's run
    assert gui["paused_position_field"] == pytest.approx(gui["paused_z"], abs=1e-4)
    assert gui["highlight"] == pytest.approx([0.95, 0.55, 0.1], abs=0.01)
    assert gui["beam_colour"] == pytest.approx([0.9, 0.1, 0.1], abs=0.01)
    # The carrier is see-through and the beam thick while the scan runs, as before after it.
    assert gui["see_through_during"] == [70, 4.0]
    assert gui["see_through_after"][0] == 0 and gui["see_through_after"][1] < 4.0
    assert gui["completed"] is True
    assert "1101221001220001010000010" in gui["panel_status"]
    # Played against the clock (120 s for the whole scan up to the pause, then 4 s): frames go
    # forward only, skipping what the clock has passed, and the last position is shown.
    shown, forward, last, frames, seconds = gui["frames"]
    assert forward and last == frames - 1 == 5400 and seconds == 4.0
    assert 1 < shown <= frames


def test_the_cross_check_command_confirms_the_scan(gui, headless):
    _, check = headless
    assert gui["crosscheck_ok"] is True
    assert gui["crosscheck_deviation"] == pytest.approx(check.largest_deviation, abs=1e-9)
    assert gui["crosscheck_deviation"] <= 1e-6
    assert gui["crosscheck_box"].startswith("Confirmed")
    # SPEC §15: the stroke's least clearance confirmed by the B-rep too, in the details.
    assert gui["crosscheck_box"].endswith("and the clearance of 1 motion.")
    details = gui["crosscheck_details"]
    assert "clearance (SPEC §15)" in details and "fast stroke up" in details
    assert "0.650457" in details and "OK: |B-rep - coal| <= 0.001 mm" in details


def test_a_link_deleted_mid_animation_ends_it_cleanly(gui):
    assert gui["fault_completed"] is False
    assert gui["fault"] and "Stopped" in gui["fault_status"]


def test_screenshots_were_saved():
    for name in SHOTS:
        assert (ARTIFACTS / name).stat().st_size > 1000, name


def test_the_panel_shows_the_recipe_it_judges_by(gui):
    # The paper's layout has no recipe: SPEC §4's limits from t = 0.7, Δt = 0.35, Δp = 0.5.
    assert gui["recipe_label"] == ("Recipe: waferscan rules: present 0.35 to 1.05 mm, seat "
                                   "−0.5/+0.5 mm, cross-slotted beyond 1.75 mm")


def test_export_csv_is_a_recorded_line(gui):
    """Issue 27 item 12: Export CSV… did not appear in the Python console."""
    exports = [c for c in gui["console_calls"] if ".export_results_csv(" in c]
    assert len(exports) == 1, gui["console_calls"]
    assert exports[0].startswith("waferscan.gui.commands.export_results_csv(App.getDocument(")
    assert exports[0].endswith(f", {gui['csv']!r})")


def test_an_export_that_cannot_be_written_is_a_message(gui):
    written, messages = gui["bad_export"]
    assert written is None
    assert any("Export CSV: nothing written" in m and "no folder /no-such-folder" in m
               for m in messages), messages
