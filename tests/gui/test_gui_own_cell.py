"""An engineer's own cell in a real FreeCAD GUI: exported as STEP and imported again with
FreeCAD's default import settings, tagged and scanned with the workbench's commands; the
commands stay usable while a task panel is open; closing the document during a scan ends the
panel cleanly."""

import re
from pathlib import Path

import pytest

from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import opened_layout

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("own_cell_probe.py")
ARTIFACTS = REPO / "test-artifacts"
# Two wafers seated in slots 1 and 3 of a 5-slot carrier (slot 1's seat at Z 10, pitch 10).
CODE = "10100"


@pytest.fixture(scope="module")
def cell(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("own-cell")
    (ARTIFACTS / "gui-own-cell.png").unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(folder),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), folder


def test_the_default_import_is_one_compound_and_tagging_it_offers_its_solids(cell):
    gui, _ = cell
    assert gui["merged_objects"] == [["Part::Feature", 6]]  # 3 walls, 2 wafers, a sensor in one
    assert "compound of 6 solids" in gui["cancelled_question"]
    assert gui["after_cancel"] == [1, True]  # cancelled: nothing changed
    split = gui["split"]
    assert split["objects"] == 7 and split["wafers"] == 2
    assert split["wafer_z"] == [10.0, 30.0]
    assert split["compound_visible"] is False
    # The split and the tagging are two undo steps (issue 27).
    assert split["undo"][:2] == ["Tag as wafer", "Split compound into solids"]
    assert "tagged 2 as wafers" in split_message(gui) and "Tag as carrier" in split_message(gui)
    # The walls and the sensor are skipped, with why.
    assert "Skipped 4, not wafer-like" in split_message(gui) and "has no cylindrical rim" in split_message(gui)
    assert gui["after_one_undo"] == [7, False, 0]  # the solids stay, untagged
    # Undone twice: the compound is back alone, visible; redone, split and tagged again.
    assert gui["after_undo"] == [1, True, [""]]
    assert gui["after_redo"] == 2


def split_message(gui):
    return " ".join(gui["split_message"])


def test_re_tagging_a_wafer_asks_first(cell):
    gui, _ = cell
    assert "already has a WaferScan role" in gui["retag_question"]
    assert "(wafer)" in gui["retag_question"]
    assert gui["retag_cancelled"] == "Wafer"


def test_tagging_a_carrier_says_what_to_set_in_a_dialog(cell):
    gui, _ = cell
    assert any("SlotCount" in text for text in gui["tag_messages"]), gui["tag_messages"]
    assert any("Emitter" in text for text in gui["tag_messages"])


def test_two_carriers_ask_which_to_scan_and_the_range_is_the_slots(cell):
    gui, folder = cell
    assert "2 objects tagged as carriers" in gui["carrier_question"]
    assert gui["merged_code"] == CODE
    # The sensor stands 140 mm above the carrier: the range is the slots' windows, 5 to 55 mm.
    assert gui["merged_range"] == pytest.approx([5.0, 55.0])
    assert "5 mm" in gui["merged_about"] and "55 mm" in gui["merged_about"]
    with opened_layout(folder / "merged-cell.FCStd") as doc:
        assert scan_document(doc, "analytic").code == CODE


def test_a_container_carrier_turns_see_through_and_a_solid_scanner_keeps_its_colour(cell):
    gui, _ = cell
    walls, beam_drawn, colour_kept = gui["link_running_look"]
    assert walls == {"Base": 70, "Left": 70, "Right": 70, "W1": 0, "W3": 0}
    assert beam_drawn is True and colour_kept is True
    walls, beam_drawn, colour_kept = gui["link_after_look"]
    assert walls == {"Base": 0, "Left": 0, "Right": 0, "W1": 0, "W3": 0}
    assert beam_drawn is False and colour_kept is True


def test_a_link_group_import_is_scanned_as_the_tree_shows_it(cell):
    gui, folder = cell
    # 0.20.2 imports the tree as link groups, 1.0 as App::Parts (docs/freecad-1.0.md)
    assert "App::LinkGroup" in gui["link_types"] or "App::Part" in gui["link_types"]
    scene = gui["link_scene"]
    assert scene["wafers"] == ["MyCell/FOUP/W1", "MyCell/FOUP/W3"]
    assert scene["carriers"] == ["MyCell/FOUP"]
    assert scene["scanners"] == ["MyCell/Sensor"]
    assert gui["link_errors"] == []
    assert gui["link_code"] == CODE
    with opened_layout(folder / "link-cell.FCStd") as doc:
        assert scan_document(doc, "analytic").code == CODE


@pytest.mark.parametrize("moment", ["enabled_paused", "enabled_done", "enabled_stopped",
                                    "enabled_mcs"])
def test_commands_stay_enabled_while_a_panel_is_open(cell, moment):
    gui, _ = cell
    assert gui[moment] == {name: True for name in gui[moment]}
    # Ours, File → New, and with the MCS panel (and a selection) Edit → Delete.
    assert len(gui[moment]) == (9 if moment == "enabled_mcs" else 8)


def test_the_results_table_opens_while_the_panel_is_open_and_after_stop(cell):
    gui, _ = cell
    assert len(gui["results_opened_with_panel"]) == 1
    assert "Stopped" in gui["stopped_status"]
    assert gui["results_after_stop"] == 1


def test_closing_the_document_during_a_scan_ends_and_closes_the_panel(cell):
    gui, _ = cell
    assert gui["after_close"] == {"dialog_open": False, "panel_open": False,
                                  "animation_ended": True, "running": False,
                                  "results_table_open": False}


def test_screenshot_saved():
    assert (ARTIFACTS / "gui-own-cell.png").stat().st_size > 1000


def test_the_commands_are_recorded_as_python_calls(cell):
    gui, _ = cell
    calls = gui["console_calls"]
    wafers = re.compile(r"waferscan\.gui\.commands\.tag_selection\('wafer', \["
                        r"App\.getDocument\('LinkCell'\)\.getObject\('{0}'\), "
                        r"App\.getDocument\('LinkCell'\)\.getObject\('{0}'\)\]\)"
                        .format(r"(Solid|Part__Feature)\d*"))  # 0.20.2's names, 1.0's
    assert any(wafers.fullmatch(c) for c in calls), calls
    assert "waferscan.gui.commands.run_scan(App.getDocument('LinkCell'))" in calls
    assert "waferscan.gui.commands.show_results_dialogs(App.getDocument('MergedCell'), " \
        "('table',))" in calls
