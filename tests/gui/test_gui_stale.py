"""Issue 27, items 2 and 5: the scan panel never shows what the document no longer holds. After
an Undo (or Redo) of a Recipe or Sensor Apply, the sections' fields and message show the
document's values; Replay after the carrier was edited scans the document as it is now and
says so (it replayed the old scan: 25 slots after SlotCount = 20)."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("stale_probe.py")
ARTIFACTS = REPO / "test-artifacts"
NOT_SET = None  # ThicknessMinSet unticked


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_the_sections_follow_undo_and_redo(gui):
    before = gui["fields_before"]
    assert before["ThicknessMin"] == "" and float(before["ThresholdOn"]) == 0.5
    assert gui["recipe_applied"] is True and gui["sensor_applied"] is True
    assert gui["document_applied"] == [0.6, 0.7]
    assert gui["fields_applied"] == {"ThicknessMin": "0.6", "ThresholdOn": "0.7"}
    # Undo once: the sensor's Apply (the last step) is undone, the recipe's stays.
    assert gui["document_undone_once"] == [0.6, 0.5]
    assert gui["fields_undone_once"] == {"ThicknessMin": "0.6", "ThresholdOn": "0.5"}
    assert gui["document_undone"] == [NOT_SET, 0.5]
    assert gui["fields_undone"] == before
    for message in gui["messages_undone"]:
        assert message.startswith("Changed in the document (Undo, Redo"), message
    assert gui["document_redone"] == [0.6, 0.5]
    assert gui["fields_redone"] == {"ThicknessMin": "0.6 mm", "ThresholdOn": "0.5"}
    assert gui["fields_final"] == before
    assert (ARTIFACTS / "gui-scan-panel-undone.png").stat().st_size > 1000


def test_replay_of_an_unchanged_document_plays_the_same_scan(gui):
    assert gui["unchanged_same_result"] is True
    assert gui["unchanged_note"] is False


def test_replay_after_the_carrier_changed_scans_it_again_and_says_so(gui):
    assert len(gui["changed_code"]) == 20
    assert gui["changed_code"] == gui["changed_now_code"]
    assert gui["changed_note"] == [True, "The document changed since the last scan: Replay "
                                         "scanned it again."]
    assert gui["changed_code"] in gui["changed_status"]
    assert (ARTIFACTS / "gui-replay-rescanned.png").stat().st_size > 1000


def test_replay_is_a_recorded_line(gui):
    """Issue 27 item 12: Replay did not appear in the Python console; its line replays the
    document's last scan (or scans it again when it changed)."""
    replays = [c for c in gui["console_calls"] if ".replay_scan(" in c]
    assert len(replays) == 2, gui["console_calls"]
    assert all(c.startswith("waferscan.gui.commands.replay_scan(App.getDocument(") and
               ", duration_s=" in c for c in replays)
