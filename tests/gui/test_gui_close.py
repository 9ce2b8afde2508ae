"""Issue 27, item 1: closing a document while its scan plays ends the scan and closes its
panel, on every way of closing one (the tab, Ctrl+W, File → Close, App.closeDocument, FreeCAD
itself), with a robot and with the scanner alone. FreeCAD crashed (SIGSEGV) on Ctrl+W with the
robot: the animation put the robot's view back after FreeCAD had deleted it."""

import json
import os
import shutil
from pathlib import Path

import pytest
from processes import run_in_own_group
from scenarios import PAPER_TEXT, PAPER_WITHOUT_ROBOT

from waferscan.bench.xvfb import xvfb_run

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("close_probe.py")
ARTIFACTS = REPO / "test-artifacts"
FREECAD = shutil.which("freecad")


@pytest.fixture(scope="module", params=["robot", "scanner alone"])
def closes(request, tmp_path_factory):
    if FREECAD is None:
        pytest.skip("FreeCAD (freecad) is not installed")
    folder = tmp_path_factory.mktemp("gui-close")
    scenario = folder / "paper.toml"
    scenario.write_text(PAPER_TEXT if request.param == "robot" else PAPER_WITHOUT_ROBOT,
                        encoding="utf-8")
    result_file = folder / "result.json"
    shot = f"gui-close-{request.param.replace(' ', '-')}.png"
    env = dict(os.environ, QTWEBENGINE_DISABLE_SANDBOX="1", WAFERSCAN_GUI_RESULT=str(result_file),
               WAFERSCAN_GUI_PROBES=str(PROBE.parent), WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS),
               WAFERSCAN_GUI_SCENARIO=str(scenario), WAFERSCAN_GUI_SHOT=shot)
    command = [*xvfb_run("1400x1000"), FREECAD, "-u", str(folder / "user.cfg"), str(PROBE)]
    returncode, output, timed_out = run_in_own_group(command, timeout=300, env=env)
    assert not timed_out, output
    assert result_file.exists(), f"the probe wrote no result (rc {returncode}):\n{output}"
    result = json.loads(result_file.read_text(encoding="utf-8"))
    assert result["ok"], result.get("error")
    return request.param, result, returncode, output


def test_every_way_of_closing_ends_the_scan_and_closes_its_panel(closes):
    _, result, _, _ = closes
    assert sorted(result["closes"]) == ["api", "ctrl_w", "file_close", "tab"]
    for way, seen in result["closes"].items():
        assert seen == {"was_running": True, "ended": True, "closed": True,
                        "timer_active": False, "panel_open": False, "task_dialog": False,
                        "same_panel": True}, way


def test_freecad_closes_cleanly_during_a_scan(closes):
    _, result, returncode, output = closes
    assert result["quit_running"] is True
    assert returncode == 0, output
    assert "Segmentation fault" not in output and "SIGSEGV" not in output


def test_no_line_about_deleted_objects(closes):
    _, _, _, output = closes
    assert "ReferenceError" not in output and "deleted object" not in output, output
    assert "animation stopped" not in output, output
