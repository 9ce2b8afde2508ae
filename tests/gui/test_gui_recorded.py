"""Issue 27 item 12, recorded scripting: the actions that did not appear in the Python console
now each run one line there, which a macro replays without a question: Tag as wafer on a
compound (the split answer in the line), the scan panel's Recipe and Sensor and slow scan
Apply, the MCS link's Save, Start watching and Stop watching. Each line, run again after the
document was put back (Undo, the panel closed, the file removed), gives the same document or
file."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("recorded_probe.py")
ARTIFACTS = REPO / "test-artifacts"
PREFIX = "waferscan.gui.commands."
DOC = "App.getDocument('SplitCell')"


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    for name in ("gui-recorded-split.png", "gui-recorded-settings.png", "gui-recorded-mcs.png"):
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_the_split_answer_is_in_the_tag_line_and_replays_without_a_question(gui):
    assert gui["split_calls"] == [f"{PREFIX}tag_selection('wafer', [{DOC}.getObject('Tool')], "
                                  "split=True)"]
    assert len(gui["split_questions"]) == 1 and "compound" in gui["split_questions"][0]
    made = gui["split_made"]
    # the compound kept (hidden), its box and its three discs, tagged as wafers
    assert [m[0] for m in made] == ["", "", "Wafer", "Wafer", "Wafer"]
    assert gui["split_undo"] == ["Tag as wafer", "Split compound into solids"]
    assert len(gui["split_undone"]) == 1  # the compound alone again
    replay = gui["split_replay"]
    assert replay["asked"] == [] and replay["error"] is None
    assert replay["made"] == made and replay["undo"] == gui["split_undo"]
    assert "Split Tool into 4 solids and tagged 3 as wafers" in gui["split_message"]
    assert (ARTIFACTS / "gui-recorded-split.png").stat().st_size > 1000


def test_the_retag_answer_is_in_the_line_too(gui):
    retag = gui["retag"]
    assert len(retag["calls"]) == 1 and len(retag["questions"]) == 1
    assert "already has a WaferScan role" in retag["questions"][0]
    assert retag["calls"][0].startswith(f"{PREFIX}tag_selection('scanner', [{DOC}.getObject(")
    assert retag["calls"][0].endswith(")], retag=True)")
    assert retag["made"] == ["Scanner", ["Tag as scanner"]]
    assert retag["undone"] == "Wafer", gui["retag_undo_names"]
    assert retag["replay"] == [[], None] and retag["replayed"] == retag["made"]


def test_recipe_and_sensor_apply_are_lines_that_replay_after_undo(gui):
    recipe, sensor = gui["settings_calls"][:1], gui["settings_calls"][-1:]
    assert recipe[0].startswith(f"{PREFIX}apply_recipe(App.getDocument('"), recipe
    assert recipe[0].endswith(", thickness_min=App.Units.Quantity('0.66 mm'), "
                              "rules='boundary')"), recipe
    assert sensor[0].startswith(f"{PREFIX}apply_sensor_settings(App.getDocument('"), sensor
    assert sensor[0].endswith(", threshold_on=0.7, jab=App.Units.Quantity('3.0 mm'))"), sensor
    assert gui["settings_messages"] == [
        "Written: ThicknessMin, ThicknessMinSet, Rules. Run scan or Replay to judge by them.",
        "Written: ThresholdOn, Jab. Run scan or Replay to scan with them."]
    before, applied = gui["settings_before"], gui["settings_applied"]
    assert before[:3] == [None, "waferscan", 0.5] and applied[:3] == [0.66, "boundary", 0.7]
    assert applied[3] == 3.0
    assert gui["settings_undo"] == ["WaferScan sensor and slow scan", "WaferScan recipe"]
    assert gui["settings_undone"] == before
    replay = gui["settings_replay"]
    assert replay["replays"] == [[[], None], [[], None]]
    assert replay["state"] == applied and replay["undo"] == gui["settings_undo"]
    # The panel follows what the macro wrote.
    assert replay["fields"] == ["0.66 mm", "boundary", "0.7", "3 mm"]
    assert all(m.startswith("Changed in the document") and "macro" in m
               for m in replay["messages"]), replay["messages"]
    assert (ARTIFACTS / "gui-recorded-settings.png").stat().st_size > 1000


def test_a_refused_recipe_line_writes_nothing_and_the_panel_says_why(gui):
    refused = gui["refused"]
    assert refused["message"] == ("Not written: ScanSettings.ThicknessMin: thickness_min 2 "
                                  "must be less than thickness_max 1.05")
    assert refused["state"] == gui["settings_applied"]
    assert refused["calls"][0].endswith("thickness_min=App.Units.Quantity('2.0 mm'))")


def test_mcs_save_is_a_line_that_writes_the_same_file(gui):
    assert len(gui["mcs_save_calls"]) == 1
    line = gui["mcs_save_calls"][0]
    assert line.startswith(f"{PREFIX}save_mcs_parameters(App.getDocument('")
    assert "# recorded by the probe" in line
    assert gui["mcs_save_replay"] == {"asked": [], "error": None, "same_bytes": True,
                                      "ends": "# recorded by the probe\n"[-24:]}


def test_mcs_start_and_stop_are_lines_and_start_opens_the_panel(gui):
    started, stopped = gui["mcs_started"], gui["mcs_stopped"]
    assert started["watching"] is True and started["store"] is True
    assert stopped["watching"] is False and stopped["state"] == "not watching"
    start, stop = gui["mcs_calls"]
    assert start.startswith(f"{PREFIX}start_mcs_link(App.getDocument('")
    assert start.endswith(f", {started['folder']!r}, store=True)")
    assert stop.startswith(f"{PREFIX}stop_mcs_link(App.getDocument('")
    again = gui["mcs_start_replay"]
    assert again["asked"] == [] and again["error"] is None and again["panel"] is True
    assert again["watching"] is True and again["folder"] == started["folder"]
    assert again["store"] is True
    assert gui["mcs_stop_replay"]["watching"] is False
    assert gui["mcs_stop_replay"]["error"] is None
    missing = gui["mcs_missing"]
    assert missing["error"].startswith("InputError: ") and "no such folder" in missing["error"]
    assert missing["watching"] is False and "no such folder" in missing["state"]
    assert (ARTIFACTS / "gui-recorded-mcs.png").stat().st_size > 1000


def test_store_while_watching_and_closing_the_panel_are_recorded(gui):
    store = gui["mcs_store"]
    assert store["watching"] is True and store["store"] is False
    assert len(store["calls"]) == 1
    assert store["calls"][0].startswith(f"{PREFIX}store_mcs_scans(App.getDocument('")
    assert store["calls"][0].endswith("), False)")
    assert gui["mcs_store_replay"] == [[], None]  # the panel is still open: nothing asked
    assert gui["mcs_closed"] == {"watching_before": True, "watching": False, "stop_lines": 1}
