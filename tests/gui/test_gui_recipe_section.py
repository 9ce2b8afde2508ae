"""The scan panel's "Recipe" section (SPEC §11) in a real FreeCAD GUI: the recipe shown from
ScanSettings, collapsed by default, blank limits showing SPEC §4's; a window the reader refuses
is refused in the panel with nothing written; a good recipe is written in one undo step and the
Replay judges by it: from 0.66 mm the paper's single wafers (0.65 mm on the 0.05 mm grid) are
thin."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("recipe_section_probe.py")
ARTIFACTS = REPO / "test-artifacts"
PAPER_CODE = "1101221001220001010000010"


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    (ARTIFACTS / "gui-scan-panel-recipe.png").unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_the_section_shows_the_recipe_collapsed(gui):
    assert gui["collapsed_visible"] is False and gui["expanded_visible"] is True
    # nothing set: blank fields with SPEC §4's limits from t = 0.7, Δt = 0.35, Δp = 0.5
    assert gui["shown"] == {"ThicknessMin": ["", "0.35 mm"], "ThicknessMax": ["", "1.05 mm"],
                            "DoubleThreshold": ["", "1.75 mm"], "PositionBelow": ["", "0.5 mm"],
                            "PositionAbove": ["", "0.5 mm"]}
    assert gui["shown_rules"] == "waferscan" and gui["shown_correction"] == "1"
    assert gui["first_code"] == PAPER_CODE


def test_a_refused_window_writes_nothing(gui):
    assert gui["bad_applied"] is False
    assert gui["bad_message"] == ("Not written: ScanSettings.ThicknessMin: thickness_min 0.9 "
                                  "must be less than thickness_max 0.8")
    assert gui["after_bad"] == [None, None, 0]  # not set, as before


def test_a_good_recipe_is_one_undo_step_and_the_replay_judges_by_it(gui):
    assert gui["good_applied"] is True
    assert gui["good_message"] == ("Written: ThicknessMin, ThicknessMinSet, Rules. Run scan or "
                                   "Replay to judge by them.")
    assert gui["after_good"] == [0.66, None, "boundary", 1, "WaferScan recipe"]
    assert gui["replay_plan"] == ["boundary", [0.66, 0.7 + 0.35]]
    assert gui["replay_code"] == PAPER_CODE.replace("1", "4")
    assert gui["replay_label"].startswith("Recipe: boundary rules: present 0.66 to 1.05 mm")
