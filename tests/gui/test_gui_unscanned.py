"""Unscanned slots and warnings in the GUI (issue 9): after Run scan on a scenario whose scan
stops inside slot 18's window, the task panel says why part of the result is not known, and the
results table, the slot-code strip and the side view show the `?` state in its own colour."""

from pathlib import Path

import pytest

from waferscan.core.files.report import STATE_COLOURS
from waferscan.core.files.scenario import read_scenario
from waferscan.core.mapping import UNSCANNED
from waferscan.core.scan.layout_scan import scan_layout

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO / "resources" / "examples" / "paper.toml"
PROBE = Path(__file__).resolve().with_name("unscanned_probe.py")


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    path = tmp_path_factory.mktemp("gui-unscanned") / "short.toml"
    # Slot 18's window is 458.94..468.94: a scan to 467 sees its wafer but not all the window.
    path.write_text(PAPER.read_text().replace("final_z = 550.0", "final_z = 467.0"))
    return path


@pytest.fixture(scope="module")
def gui(run_gui_probe, scenario):
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(scenario))


def test_the_panel_shows_the_warning_after_run_scan(gui, scenario):
    result = scan_layout(read_scenario(scenario))
    assert result.code == "11012210012200010" + UNSCANNED * 8
    assert len(result.warnings) == 1
    assert "Warning: slots 18, 19, 20, 21, 22, 23, 24, 25 of 25 not wholly inside" \
        in gui["panel_status"]


def test_unscanned_slots_show_as_such_in_table_strip_and_side_view(gui, scenario):
    grey = list(STATE_COLOURS[UNSCANNED])
    assert grey not in [list(c) for k, c in STATE_COLOURS.items() if k != UNSCANNED]
    states = {int(row[0]): row[6] for row in gui["rows"]}
    assert [states[s] for s in range(18, 26)] == ["unscanned"] * 8
    assert states[17] == "empty" and states[16] == "present"
    slot_18 = next(i for i, row in enumerate(gui["rows"]) if row[0] == "18")
    assert gui["rows"][slot_18][2] == "LP1_W09"  # its wafer's run is still listed
    assert gui["state_colours"][slot_18] == grey
    assert gui["code"] == "11012210012200010????????"
    assert gui["e87"].endswith("00000000")
    assert gui["strip"][17:] == [[str(s), "?"] for s in range(18, 26)]
    assert all(f"rgb({grey[0]},{grey[1]},{grey[2]})" in style for style in gui["strip_styles"][17:])
    # The run in slot 18 is drawn in the unscanned colour.
    assert any(rgb == grey for rgb, _ in gui["side_view_colours"])
