"""Issue 27 item 8 in a real FreeCAD GUI: the paper's cell, turned 90 degrees about Z, exported
as STEP and imported again (FreeCAD's LinkGroup tree), tagged, and set up with "Set up carrier
and sensor" without typing a coordinate: slot 1's seat and the beam's ends picked in the 3D
view, the slot count and pitch derived from the carrier's ledges; the document then holds them
in each object's own frame, as one undo step and one recorded line, and scans to the paper's
code."""

import math
import re
from pathlib import Path

import pytest

from waferscan.addon import paper_scenario
from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import opened_layout
from waferscan.core.files.report import PAPER_CODE

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("frames_probe.py")
ARTIFACTS = REPO / "test-artifacts"
SHOTS = ("gui-frames-derived.png", "gui-frames-picked.png")


def turned_paper_scenario(folder):
    """The paper's scenario turned 90 degrees about Z (its carrier's front along +X), without
    its robot (the sensor lifts along Z)."""
    text = paper_scenario().read_text(encoding="utf-8")
    text = re.sub(r"\n\[robot\].*?\n\n", "\n\n", text, flags=re.S)
    replaced = {"emitter = [-80.0, 266.6, 280.0]": "emitter = [-266.6, -80.0, 280.0]",
                "direction = [1.0, 0.0, 0.0]": "direction = [0.0, 1.0, 0.0]",
                "center = [0.0, 400.0]": "center = [-400.0, 0.0]",
                "front = [0.0, -1.0]": "front = [1.0, 0.0]"}
    for old, new in replaced.items():
        assert old in text
        text = text.replace(old, new)
    assert "[robot]" not in text
    path = folder / "turned-paper.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def gui(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("frames")
    for name in SHOTS:
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(folder),
                         WAFERSCAN_GUI_SCENARIO=str(turned_paper_scenario(folder)),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), folder


def test_with_nothing_tagged_the_command_says_what_to_tag(gui):
    result, _ = gui
    assert len(result["untagged_messages"]) == 1
    assert "tag the carrier (Tag as carrier) and the sensor (Tag as scanner) first" in \
        result["untagged_messages"][0]
    assert result["untagged_panel"] is False


def test_a_pitch_that_is_not_a_length_is_said_and_changes_nothing(gui):
    result, _ = gui
    assert len(result["bad_pitch_messages"]) == 1
    assert result["bad_pitch_messages"][0].startswith("Pitch: 'ten' is not a length"), \
        result["bad_pitch_messages"]
    assert result["bad_pitch_open"] is True
    assert result["bad_pitch_undo"] == result["undo_before"]


def test_the_carrier_is_imported_in_a_turned_frame(gui):
    """0.20.2 keeps the product's frame on the compound it makes; FreeCAD 1.0 makes the product
    an App::Part in the global frame and places the solids in it (the own-frame conversion of
    a turned object is then checked headless, tests/cad/test_carrier_geometry.py)."""
    result, _ = gui
    assert "Foup" in result["imported_labels"] and "Sensor" in result["imported_labels"]
    turned = 90.0 if result["freecad_major"] < 1 else 0.0
    assert result["carrier_turned_deg"] == pytest.approx(turned, abs=1e-9)


def own_frame(placement, point):
    """``point`` (global) in the frame placed at ``placement`` ([Base, Q] as the probe gives)."""
    import FreeCAD as App

    placed = App.Placement(App.Vector(*placement[0]), App.Rotation(*placement[1]))
    return list(placed.inverse().multVec(App.Vector(*point)))


def test_the_panel_shows_the_slots_derived_from_the_carriers_ledges(gui):
    result, _ = gui
    assert result["panel_title"] == "Set up carrier and sensor"
    text = result["derived_text"]
    assert "25 slots" in text and "pitch 10 mm" in text, text
    assert "(-400 mm, 0 mm, 293.94 mm)" in text, text
    assert "25 support levels" in text and "8 level wafers" in text, text


def test_slot_1s_seat_is_picked_on_slot_1s_wafer(gui):
    result, _ = gui
    assert result["seat_before"] != ["-400 mm", "0 mm", "293.94 mm"]
    assert "Click slot 1's wafer" in result["seat_hint"]
    assert "its bottom centre is taken" in result["seat_status_bar"]
    assert result["seat_picked"] == ["-400 mm", "0 mm", "293.94 mm"]
    assert "W01's bottom centre" in result["seat_status"]
    assert result["seat_after_stray_click"] == result["seat_picked"]
    assert result["slots_pitch"] == [25, "10 mm"]
    assert result["seat_derived"] == result["seat_picked"]


def test_the_beams_ends_are_picked_in_the_3d_view(gui):
    result, _ = gui
    assert result["emitter_picked"] == ["-266.6 mm", "-80 mm", "283 mm"]
    assert result["receiver_picked"] == ["-266.6 mm", "80 mm", "283 mm"]
    assert result["status_after_picks"] == "Receiver picked: (-266.6 mm, 80 mm, 283 mm)."
    assert "Then click" not in result["status_bar_after_picks"]  # done: the hint is gone


def test_a_click_in_the_tree_while_picking_gives_no_point_and_the_pick_waits(gui):
    """A tree click selects a whole object and FreeCAD hands (0, 0, 0) as its point: the
    emitter became the origin."""
    tree = gui[0]["tree_click"]
    assert tree["unchanged"] and tree["still_picking"]
    assert "click the point in the 3D view" in tree["status"]


def test_the_panel_fits_the_default_combo_view_with_every_line_shown(gui):
    result, _ = gui
    assert result["clipped_labels"] == []


def test_ok_writes_the_frames_as_one_undo_step_in_each_objects_own_frame(gui):
    result, _ = gui
    assert result["panel_open_after_ok"] is False
    assert result["messages_after_ok"] == []
    assert result["undo_after"] == ["Set carrier and sensor frames"] + result["undo_before"]
    own = result["own_frame"]
    assert own["SlotCount"] == 25 and own["Pitch"] == pytest.approx(10.0)
    # The carrier's own frame: at (-250, 100, 50), turned -90 degrees about Z; by hand, a
    # global (x, y, z) is (100 - y, x + 250, z - 50) in it. Slot 1's seat (-400, 0, 293.94):
    base, quaternion = own["SlotOrigin"]
    carrier, sensor = result["carrier_placement"], result["sensor_placement"]
    assert base == pytest.approx(own_frame(carrier, [-400.0, 0.0, 293.94]), abs=1e-9)
    # The points picked (3 mm above the beam; FreeCAD keeps a clicked point in single
    # precision: -266.6 is -266.600006):
    assert own["Emitter"] == pytest.approx(own_frame(sensor, [-266.6, -80.0, 283.0]), abs=1e-4)
    assert own["Receiver"] == pytest.approx(own_frame(sensor, [-266.6, 80.0, 283.0]), abs=1e-4)
    if result["freecad_major"] < 1:  # and by hand, in the frames the STEP file gave them
        assert base == pytest.approx([100.0, -150.0, 243.94], abs=1e-9)
        # Its front (-Y of the slot frame) along global +X: the slot frame is turned 90 degrees
        # globally, so 180 degrees in the carrier's own frame.
        assert [abs(q) for q in quaternion] == pytest.approx([0.0, 0.0, 1.0, 0.0], abs=1e-9)
        # The sensor's own frame: at (10, 20, 30), turned 180 degrees; by hand, a global
        # (x, y, z) is (10 - x, 20 - y, z - 30) in it.
        assert own["Emitter"] == pytest.approx([276.6, 100.0, 253.0], abs=1e-4)
        assert own["Receiver"] == pytest.approx([276.6, -60.0, 253.0], abs=1e-4)
    seen = result["global"]
    assert seen["slots"] == 25 and seen["pitch"] == pytest.approx(10.0)
    assert seen["first_slot_z"] == pytest.approx(293.94)
    assert seen["center"] == pytest.approx([-400.0, 0.0], abs=1e-9)
    assert seen["front"] == pytest.approx([1.0, 0.0], abs=1e-9)
    assert seen["emitter"] == pytest.approx([-266.6, -80.0, 283.0], abs=1e-4)
    assert seen["direction"] == pytest.approx([0.0, 1.0, 0.0])
    assert math.isclose(seen["length"], 160.0)


def test_the_change_is_one_recorded_line_that_replays(gui):
    result, _ = gui
    lines = [c for c in result["console_calls"] if "set_frames(" in c]
    assert lines == [
        "waferscan.gui.commands.set_frames(App.getDocument('Cell'), carrier=App.getDocument("
        f"'Cell').getObject({lines[0].split('getObject(')[1].split(')')[0]}), slot_count=25, "
        "pitch=App.Units.Quantity('10.0 mm'), seat=App.Vector(-400.0, 0.0, 293.94), "
        "front=(1.0, 0.0), scanner=" + lines[0].split("scanner=")[1]]
    ends = re.search(r"emitter=App\.Vector\((.*?)\), receiver=App\.Vector\((.*?)\)\)$", lines[0])
    picked = [[float(v) for v in ends[i].split(", ")] for i in (1, 2)]
    assert picked == [pytest.approx([-266.6, -80.0, 283.0], abs=1e-4),
                      pytest.approx([-266.6, 80.0, 283.0], abs=1e-4)]
    assert "waferscan.gui.commands.open_frames_panel(App.getDocument('Cell'))" in \
        result["console_calls"]
    undone = result["own_frame_undone"]
    assert undone["SlotOrigin"] != result["own_frame"]["SlotOrigin"]
    assert undone["Emitter"] != result["own_frame"]["Emitter"]
    assert result["own_frame_replayed"] == result["own_frame"]
    assert result["messages_after_replay"] == []


def test_the_cell_set_up_by_picking_scans_to_the_papers_code(gui):
    result, folder = gui
    assert result["gui_code"] == PAPER_CODE
    with opened_layout(folder / "turned-cell.FCStd") as doc:
        assert scan_document(doc, "analytic").code == PAPER_CODE


def test_screenshots_saved(gui):
    for name in SHOTS:
        assert (ARTIFACTS / name).stat().st_size > 1000, name
