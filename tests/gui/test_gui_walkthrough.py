"""Issue 27's own-cell walkthrough in a real FreeCAD GUI, as a newcomer does it: the demo ("New
paper layout", robot included) exported as STEP, imported with FreeCAD's default settings (one
merged compound on 0.20.2), split and tagged, a carrier made of its walls and ledges, the beam's
rod tagged as the scanner, set up with Use derived and picks, scanned to the paper's slot code
without typing a coordinate; a headless scan of the saved file agrees."""

from pathlib import Path

import pytest

from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import opened_layout
from waferscan.core.files.report import PAPER_CODE

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("walkthrough_probe.py")
ARTIFACTS = REPO / "test-artifacts"
SHOTS = ("gui-walkthrough-1-imported.png", "gui-walkthrough-2-wafers.png",
         "gui-walkthrough-3-carrier.png", "gui-walkthrough-4-set-up.png",
         "gui-walkthrough-5-scanned.png")
# The paper's cell: 25 slots, 10 mm apart, slot 1's seat at (0, 400, 293.94); ten wafers,
# those of slots 4 and 7 cross-slotted.
SEAT = ["0 mm", "400 mm", "293.94 mm"]


@pytest.fixture(scope="module")
def walk(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("walkthrough")
    for name in SHOTS:
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(folder),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), folder


def test_the_demo_is_exported_and_imported_with_the_defaults(walk):
    result, _ = walk
    assert result["exported"] == ["LP1 assembly", "Robot"]
    prefs = result["import_preferences"]
    assert prefs["set"] == []  # a fresh user: nothing set, FreeCAD's defaults
    if not result.get("compound_made_from_file"):  # 0.20.2: one merged compound
        assert len(result["imported"]) == 1 and result["imported"][0][0] == "Part::Feature"
    assert result["imported"][-1][1] > 60


def test_tag_as_wafer_splits_and_tags_the_ten_wafers(walk):
    result, _ = walk
    assert "Split into solids" not in result["split_question"][0]
    assert "compound of" in result["split_question"][0]
    assert result["wafers"] == 10
    assert "tagged 10 as wafers" in result["wafer_message"][0]
    # What the guide quotes: the 66 others skipped, with why, the first ten in the message.
    message = result["wafer_message"][0]
    assert "Skipped 66, not wafer-like (selected now):\n• paper-cell solid 1: " in message
    assert "• and 56 more (the report view lists them all)" in message, message


def test_make_carrier_gathers_the_walls_and_ledges(walk):
    result, _ = walk
    # 5 walls and 2 ledges for each of the 25 slots, one run in the tree.
    assert result["carrier_run"][1:] == [55, True]
    assert result["carriers"] == [["App::Part", 55]]
    assert result["scanners"] and len(result["scanners"]) == 1


def test_the_slots_are_derived_from_the_carriers_ledges(walk):
    result, _ = walk
    assert "25 slots" in result["derived_text"] and "25 support levels" in result["derived_text"]
    assert result["derived_fields"] == [25, "10 mm", SEAT]


def test_the_beams_ends_are_picked(walk):
    result, _ = walk
    assert result["emitter_picked"] == ["-80 mm", "266.6 mm", "283 mm"]
    assert result["receiver_picked"] == ["80 mm", "266.6 mm", "283 mm"]
    assert result["messages_after_ok"] == []
    assert result["undo_after_frames"][0] == "Set carrier and sensor frames"


def test_the_cell_scans_to_the_papers_code_in_the_gui_and_headless(walk):
    result, folder = walk
    assert result["gui_code"] == PAPER_CODE
    with opened_layout(folder / "paper-cell.FCStd") as doc:
        assert scan_document(doc, "analytic").code == PAPER_CODE


def test_screenshots_of_each_step(walk):
    for name in SHOTS:
        assert (ARTIFACTS / name).stat().st_size > 1000, name


def test_each_step_is_one_recorded_line_in_order(walk):
    result, _ = walk
    calls = [c.split("(", 1)[0].replace("waferscan.gui.commands.", "")
             for c in result["console_calls"]]
    # From the demo's "New paper layout" on: what the newcomer did, a line a step.
    assert calls[calls.index("tag_selection"):] == [
        "tag_selection", "make_carrier_from_solids", "tag_selection", "open_frames_panel",
        "set_frames", "run_scan"], calls
    tags = [c for c in result["console_calls"] if "tag_selection(" in c]
    assert tags[0].startswith("waferscan.gui.commands.tag_selection('wafer', ")
    assert tags[1].startswith("waferscan.gui.commands.tag_selection('scanner', ")
