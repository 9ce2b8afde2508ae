"""Issue 27 items 10 and 13: "Apply to document" of the calibration dialog on a document saved
with the earlier recipe limits (App::PropertyFloat in mm, -1 for "not set"), then Undo: the
document is back to what it was, property types included; Redo applies it again."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("calibrate_old_probe.py")
PAPER_TEXT = (REPO / "resources" / "examples" / "paper.toml").read_text()
LOAD = "1100100001000010000100011"  # test_gui_calibrate's drifted layout: references in 1 and 25


@pytest.fixture(scope="module")
def gui(run_gui_probe, tmp_path_factory):
    path = tmp_path_factory.mktemp("gui-calibrate-old") / "drifted.toml"
    wafers = "".join(f"\n[[wafer]]\ncenter = [0.0, 400.0, {294.24 + (slot - 1) * 10.02!r}]\n"
                     f"normal = [0.0, 0.0, 1.0]\ndiameter = 300.0\nthickness = 0.7\n"
                     for slot, state in enumerate(LOAD, 1) if state == "1")
    path.write_text(PAPER_TEXT.replace('load = "1101221001220001010000010"',
                                       f'load = "{"0" * 25}"') + wafers)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(path))


def test_apply_writes_the_calibrated_recipe_in_the_documents_own_kind_of_limits(gui):
    """Apply turned the limits into today's properties, which Undo could not take back (the
    new ThicknessMin went, the old one did not come back); it now writes them as the
    document keeps them, as the Recipe section does: floats in mm, -1 for not set."""
    assert gui["old_before"] is True
    assert gui["before"]["recipe"][0] == 0.6 and gui["before"]["recipe"][1:3] == [None, None]
    assert gui["old_applied"] is True
    assert gui["undo_applied"][0] == "Apply calibration"
    assert gui["applied"]["carrier"] != gui["before"]["carrier"]
    settings = gui["applied"]["settings"]
    assert settings["ThicknessMin"][0] == "App::PropertyFloat"
    assert "ThicknessMinSet" not in settings
    # the calibrated recipe, read back as the reader reads today's properties
    recipe = gui["applied"]["recipe"]
    for value, text in zip(recipe, (settings[p][1] for p in (
            "ThicknessMin", "ThicknessMax", "DoubleThreshold", "PositionBelow",
            "PositionAbove"))):
        assert float(text) == (-1.0 if value is None else pytest.approx(value, abs=1e-12))
    assert gui["applied"]["settings"] != gui["before"]["settings"]  # the range, the correction


def test_undo_gives_the_document_back_as_it_was(gui):
    assert gui["old_undone"] is True
    before, undone = gui["before"], gui["undone"]
    assert undone["carrier"] == before["carrier"]
    assert undone["recipe"] == before["recipe"]
    assert undone["settings"] == before["settings"]
    assert gui["undo_undone"] == gui["undo_before"]


def test_redo_applies_it_again(gui):
    assert gui["redone"] == gui["applied"]
