"""Issue 27, item 3, in the GUI: Run scan of a layout whose beam passes 10 mm in front of every
wafer says so at once (a message box) and in the panel when the scan ends, in the words of the
core's warning (tests/core/test_missed_by_beam.py); it was a silent all-empty map. The beam is
drawn in the 3D view before any scan (it was only while one played), for WaferScan's own
scanner and for a user's solid tagged as scanner."""

import html
from pathlib import Path

from scenarios import PAPER_WITHOUT_ROBOT

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("missed_probe.py")
ARTIFACTS = REPO / "test-artifacts"
WARNING = ("the beam misses 10 of the 10 wafers at every height (LP1_W01, LP1_W02, LP1_W03 and 7 "
           "more), passing 10.000 mm beside them: their slots read empty; check where the "
           "scanner's emitter and receiver are")


def test_a_beam_beside_the_wafers_is_said_at_once_and_when_the_scan_ends(run_gui_probe,
                                                                         tmp_path):
    scenario = tmp_path / "beside.toml"
    text = PAPER_WITHOUT_ROBOT.replace("emitter = [-80.0, 266.6, 280.0]",
                                       "emitter = [-80.0, 240.0, 280.0]")
    assert text != PAPER_WITHOUT_ROBOT
    scenario.write_text(text, encoding="utf-8")
    gui = run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(scenario),
                        WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))
    assert gui["code"] == "0" * 25
    assert gui["boxes"] == [f"beside: T{WARNING[1:]}."]
    assert f"Warning: {html.escape(WARNING)}" in gui["status"]
    # The scanner's own frame: the beam along its X, 160 mm long.
    beam = [True, [0.0, 0.0, 0.0], [160.0, 0.0, 0.0]]
    assert gui["preview_before"] == beam
    assert gui["preview_during"][0] is False  # the scan draws the beam its own way
    assert gui["preview_after"] == beam
    assert gui["own_tagged"] == beam  # Tag as scanner's defaults
    assert gui["own_moved"] == [True, [0.0, 0.0, 0.0], [50.0, 0.0, 0.0]]
    assert gui["own_closed"] == [False]
    for name in ("gui-beam-misses-box.png", "gui-beam-misses-panel.png",
                 "gui-beam-before-scan.png"):
        assert (ARTIFACTS / name).stat().st_size > 1000
