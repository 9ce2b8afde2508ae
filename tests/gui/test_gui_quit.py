"""FreeCAD told to quit (``QApplication.quit()``, as a script or macro may) while a scan plays:
it exits cleanly. Before, the animation was ended by the GUI document's deletion, which on a
quit comes after the main window's: it took the status bar's progress bar off a main window
already gone (SIGSEGV), and FreeCAD then hung in its crash handler until killed.

FreeCAD 1.0 crashes on ``QApplication.quit()`` with a 3D view open whatever plays: closing the
last view, it prints a command to its Python console, already deleted
(``Gui::Application::onLastWindowClosed`` in the backtrace; the "idle" case shows it with no
scan at all). There, a crash is accepted only with that backtrace of FreeCAD's own."""

import json
import os
import shutil
from pathlib import Path

import pytest
from processes import run_in_own_group

from waferscan.bench.xvfb import xvfb_run

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("quit_probe.py")
EXAMPLES = REPO / "resources" / "examples"
FREECAD = shutil.which("freecad")


FREECAD_1_QUIT_CRASH = "Gui::Application::onLastWindowClosed"


def freecad_major():
    import FreeCAD

    return int(FreeCAD.Version()[0])


@pytest.mark.parametrize("phase, scenario", [("stroke", "paper.toml"),
                                             ("pockets", "slow_jab.toml"),
                                             ("idle", "paper.toml")])
def test_quitting_during_a_scan_exits_cleanly(tmp_path, phase, scenario):
    if FREECAD is None:
        pytest.skip("FreeCAD (freecad) is not installed")
    result_file = tmp_path / "result.json"
    env = dict(os.environ, QTWEBENGINE_DISABLE_SANDBOX="1", WAFERSCAN_GUI_RESULT=str(result_file),
               WAFERSCAN_GUI_PROBES=str(PROBE.parent), WAFERSCAN_GUI_QUIT_IN=phase,
               WAFERSCAN_GUI_SCENARIO=str(EXAMPLES / scenario))
    command = [*xvfb_run("1400x1000"), FREECAD, "-u", str(tmp_path / "user.cfg"), str(PROBE)]
    returncode, output, timed_out = run_in_own_group(command, timeout=150, env=env)
    assert not timed_out, output[-3000:]  # before: hung after the crash
    result = json.loads(result_file.read_text(encoding="utf-8"))
    assert result["ok"], result.get("error")
    if phase != "idle":
        assert result["playing"] is True and result["frame"] > 10
    assert "animation stopped" not in output, output[-3000:]
    if freecad_major() >= 1 and returncode != 0:
        assert FREECAD_1_QUIT_CRASH in output, output[-3000:]  # FreeCAD's own, as when idle
        assert "statusBar" not in output, output[-3000:]  # the crash this test was made for
        return
    assert returncode == 0, output[-3000:]
    assert "SIGSEGV" not in output and "Segmentation fault" not in output, output[-3000:]
