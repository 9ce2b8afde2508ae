"""Issue 27 item 8: "Set up carrier and sensor…" on a document with several tagged carriers and
none named by ScanSettings asks which, as Run scan does; Cancel opens nothing and says why; the
carrier chosen is the one the panel sets up and the one OK writes (in the recorded line and the
document), the other left as it was."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("frames_choice_probe.py")
ARTIFACTS = REPO / "test-artifacts"


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    (ARTIFACTS / "gui-frames-choice.png").unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_the_user_is_asked_which_carrier(gui):
    paper, spare = gui["labels"]
    assert len(gui["questions"]) == 2
    for question in gui["questions"]:
        assert f"2 objects tagged as carriers: {paper}, {spare}." in question
        assert "Which one is to be set up?" in question


def test_cancel_opens_no_panel_and_says_why(gui):
    assert gui["cancel_panel"] is False
    paper, spare = gui["labels"]
    assert any(f"several carriers ({paper}, {spare}): choose the one to set up" in m
               for m in gui["cancel_messages"]), gui["cancel_messages"]


def test_the_chosen_carrier_is_set_up_and_written(gui):
    _, spare = gui["labels"]
    assert gui["panel_open"] is True and gui["panel_carrier"] == gui["spare_name"]
    assert f"Carrier: {spare}" in gui["panel_box"]
    # an empty box: no slots derived from the other carrier's wafers
    assert gui["derived"].startswith("Derived: nothing (no wafers"), gui["derived"]
    assert gui["accepted"] is not False, gui["messages"]
    [line] = gui["lines"]
    assert "carrier=App.getDocument(" in line
    assert f".getObject({gui['spare_name']!r}), slot_count=7, " \
           "pitch=App.Units.Quantity('12.0 mm')" in line
    assert gui["spare_after"]["SlotCount"] == "7" and gui["spare_after"]["Pitch"] == "12.0 mm"
    assert gui["spare_after"] != gui["spare_before"]
    assert gui["paper_after"] == gui["paper_before"]  # the other carrier as it was
    assert gui["undo"] == ["Set carrier and sensor frames"]
    assert (ARTIFACTS / "gui-frames-choice.png").stat().st_size > 10_000
