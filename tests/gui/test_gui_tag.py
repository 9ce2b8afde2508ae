"""An engineer's own solids made into a layout in a real FreeCAD GUI: the preferences page, the tag
commands with their undo transactions and refusals, and a scan of the result that agrees with a
headless scan of the saved document."""

from pathlib import Path

import pytest

from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import opened_layout

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("tag_probe.py")
ARTIFACTS = REPO / "test-artifacts"


@pytest.fixture(scope="module")
def tagged(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("own-solids")
    return run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(folder),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), folder


def test_the_preferences_page_stores_what_was_typed_in_any_unit(tagged):
    gui, folder = tagged
    assert gui["defaults"] == [True, 0.5, 1.0, "", 10.0]  # 10 s for a whole scan
    assert gui["stored"][:3] == pytest.approx([0.25, 0.4064, 1.5])  # 0.016 in, 1500 um
    assert gui["stored"][3:] == [str(folder), 4.5]
    assert gui["reloaded"] == [False, pytest.approx(0.25), 4.5]


def test_a_box_is_refused_as_a_wafer_and_nothing_changes(tagged):
    gui, _ = tagged
    assert "Bracket is not a wafer" in gui["refusal"]
    assert gui["after_refusal"] == [None, None]
    assert gui["undo_after_refusal"] is True


def test_tagging_is_one_undo_step_each(tagged):
    gui, _ = tagged
    assert gui["tagged_wafers"] == ["Wafer", "Wafer"]
    assert gui["after_undo"] == [None, None]
    assert gui["after_redo"] == ["Wafer", "Wafer"]
    assert gui["undo_names"][:3] == ["Tag as scanner", "Tag as carrier", "Tag as wafer"]


def test_the_scan_of_tagged_solids_uses_the_preferences_and_agrees_headless(tagged):
    gui, folder = tagged
    assert gui["code"] == "10100"
    # No ScanSettings in the document: the scan added one, with the preferences' tolerances,
    # as its own undo step.
    assert gui["settings"][:3] == pytest.approx([0.25, 0.4064, 1.5])
    assert gui["settings"][3] is True  # the preferences' 0.25 mm, not half the thickness
    assert "Add WaferScan scan settings" in gui["undo_names_after_scan"]
    assert gui["speed_from_preferences"] == 4.5
    with opened_layout(folder / "own-solids.FCStd") as doc:
        headless = scan_document(doc, "analytic")
    assert headless.code == gui["code"]
    assert (ARTIFACTS / "gui-own-solids.png").stat().st_size > 1000
    assert (ARTIFACTS / "gui-preferences.png").stat().st_size > 1000


def test_a_range_typed_wrong_is_a_message_not_a_traceback(tagged):
    gui, _ = tagged
    assert len(gui["bad_range_messages"]) == 1
    # The first Run scan set the range to the slots' windows: slot 1's seat 10 - pitch/2 = 5.
    assert "ScanSettings: final_z (-5) is below start_z (5)" in gui["bad_range_messages"][0]
    assert gui["bad_range_panel"] is False


def test_another_tools_task_panel_is_left_alone(tagged):
    gui, _ = tagged
    assert gui["foreign_messages"] == ["task panel: another task panel is open: close it first"]


def test_exact_edges_scanned_downwards_animate_top_to_bottom(tagged):
    gui, _ = tagged
    assert "exact edges" in gui["exact_about"] and "direction down" in gui["exact_about"]
    assert gui["exact_first_z"] == pytest.approx(60.0)
    assert gui["exact_completed"] is True
    assert gui["exact_code"] == "10100"


def test_views_after_a_deletion_show_the_document_as_it_is(tagged):
    gui, _ = tagged
    rows = gui["rows_after_delete"]
    assert [row[2] for row in rows] == ["Wafer1", "-", "-", "-", "-"]
    assert [row[6] for row in rows] == ["present", "empty", "empty", "empty", "empty"]
    assert gui["crosscheck_after_delete"].startswith("Confirmed")
