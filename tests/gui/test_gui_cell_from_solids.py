"""Issue 27 items 6, 7 and 9 in a real FreeCAD GUI: a STEP compound split and only its wafers
tagged (what was skipped said, with why); Untag; a carrier made of loose solids; the carrier's
wafer size taken from the wafers; the scan range follows the carrier until the user sets it."""

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("cell_from_solids_probe.py")
ARTIFACTS = REPO / "test-artifacts"


@pytest.fixture(scope="module")
def cell(run_gui_probe, tmp_path_factory):
    for name in ("gui-split-tagged.png", "gui-split-skipped.png", "gui-range-follows.png"):
        (ARTIFACTS / name).unlink(missing_ok=True)
    folder = tmp_path_factory.mktemp("tool-cell")
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS),
                         WAFERSCAN_GUI_MCS=str(folder))


def test_only_the_wafers_of_a_split_compound_are_tagged(cell):
    split = cell["split"]
    assert split["solids"] == 19
    assert split["tagged"] == 10 and split["tagged_are_the_wafers"] is True
    # The split and the tagging are two undo steps.
    assert split["undo"][:2] == ["Tag as wafer", "Split compound into solids"]
    assert cell["after_one_undo"] == [20, 0, ""]  # the solids stay, untagged
    assert cell["after_redo"] == 10


def test_what_was_skipped_is_said_with_why(cell):
    message = cell["split_message"]
    assert "tagged 10 as wafers" in message and "Skipped 9, not wafer-like" in message
    assert "Tool solid 14: a cylinder 120 mm across and 300 mm high" in message  # the column
    assert "Tool solid 15: a cylinder 160 mm across and 20 mm high" in message  # the collar
    assert "Tool solid 17: a cylinder 0.8 mm across and 160 mm high" in message  # a rod
    assert "Tool solid 11: has no cylindrical rim" in message  # a wall
    assert "Untag" in message and "Make carrier from solids" in message
    assert len(cell["selected_after"]) == 9  # the skipped solids, to pick the carrier from
    assert (ARTIFACTS / "gui-split-skipped.png").stat().st_size > 1000


def test_the_role_shows_in_the_trees_description_column(cell):
    if ["Labels & Attributes", "Description"] not in cell["tree_columns"]:
        # FreeCAD 1.0 hides the column by default (0.20.2 shows it): the user is told where.
        assert "Tree settings → Show description" in cell["split_message"]
    assert cell["tree_wafer"] == "Wafer (WaferScan)"
    assert cell["tree_rod"] == ""
    assert cell["label2"] == ["Wafer (WaferScan)", ""]
    assert (ARTIFACTS / "gui-split-tagged.png").stat().st_size > 1000


def test_untag_restores_the_object_in_one_undo_step(cell):
    assert cell["untagged"] == {"role": None, "label2": "", "properties_as_untagged": True,
                                "undo": ["Untag", "Tag as wafer"]}
    assert cell["untag_undone"] == ["Wafer", "Wafer (WaferScan)"]
    assert cell["untag_redone"] == [None, ""]
    assert cell["untag_nothing"] == ["selection: Tool solid 15 has no WaferScan role to remove"]


def test_a_disc_tagged_on_its_own_is_tagged_with_a_word(cell):
    wafer_role, collar_role, message = cell["explicit_collar"]
    assert [wafer_role, collar_role] == ["Wafer", "Wafer"]
    assert "Tagged as you asked, though Tool solid 15 is a cylinder 160 mm across" in message
    assert cell["collar_after_untag"] == [None, ""]


def test_a_carrier_made_of_loose_solids_takes_the_wafers_size(cell):
    carrier = cell["carrier"]
    assert carrier["size"] == pytest.approx([300.0, 0.7])  # not the default 0.775 mm
    assert carrier["count"] == 1 and carrier["type"] == "App::Part"
    assert carrier["walls_inside"] is True
    assert carrier["label2"] == "Carrier (WaferScan)"
    assert carrier["undo"][0] == "Make carrier from solids"
    assert "those of the 10 tagged wafers" in carrier["message"]
    assert cell["carrier_undone"] == [0, [True, True, True]]


def test_a_carrier_made_inside_a_placed_part_moves_nothing(cell):
    nested = cell["nested"]
    assert nested["parent"] == "Cell" and nested["moved"] is False
    assert nested["inside"] == ["Carrier", "Carrier"]
    assert "No wafers are tagged yet" in nested["message"]  # the defaults, said
    messages, unchanged = cell["two_containers"]
    assert messages == ["selection: the selected solids lie in different containers (Carrier, "
                        "the document itself): select solids of one container, or tag that "
                        "container as the carrier"]
    assert unchanged is True


def test_a_wafer_tagged_after_its_carrier_of_another_size_is_said(cell):
    thin_role, carrier_thickness, message = cell["thin"]
    assert thin_role == "Wafer" and carrier_thickness == pytest.approx(0.7)  # left as it was
    assert "Carrier holds 300 mm, 0.7 mm wafers (its WaferDiameter and WaferThickness), but " \
        "Thin is 300 mm, 0.5 mm" in message


def test_the_commands_are_recorded(cell):
    calls = cell["console_calls"]
    solid = r"App\.getDocument\('ToolCell'\)\.getObject\('Tool_S0\d\d'\)"
    assert any(re.fullmatch(rf"waferscan\.gui\.commands\.untag_selection\(\[{solid}\]\)", c)
               for c in calls), calls
    assert any(re.fullmatch(rf"waferscan\.gui\.commands\.make_carrier_from_solids\(\[{solid}, "
                            rf"{solid}, {solid}\]\)", c) for c in calls), calls


def test_the_scan_range_follows_the_carrier_until_set(cell):
    first, second, third = cell["first"], cell["second"], cell["third"]
    assert first["range"] == pytest.approx([5.0, 255.0])  # 25 slots by default
    assert first["code"] == "1" * 10 + "0" * 15, first
    assert second["range"] == pytest.approx([5.0, 105.0])  # SlotCount 10
    assert second["code"] == "1" * 10
    assert third["range"] == pytest.approx([5.0, 60.0])  # FinalZ set: kept at SlotCount 12
    # What the property editor shows, and why.
    assert first["stored"] == pytest.approx([5.0, 255.0]) and first["follows"] is True
    assert second["stored"] == pytest.approx([5.0, 105.0]) and second["follows"] is True
    # Shown as scanned by Run scan, in its one undo step with the results; what only reads the
    # document (the results dialogs, the cross-check) scans the followed range and writes
    # nothing (it wrote StartZ and FinalZ, an undo step of its own).
    assert second["undo"][0] == "WaferScan results"
    assert "Scan range follows the carrier" not in second["undo"]
    read_only = cell["read_only"]
    assert read_only["range"] == pytest.approx([5.0, 105.0])
    assert read_only["stored"] == pytest.approx([5.0, 255.0]) and read_only["undo_same"]
    assert third["follows"] is False
    assert (ARTIFACTS / "gui-range-follows.png").stat().st_size > 1000
