"""The WaferScan workbench in a real FreeCAD GUI, under Xvfb."""

import json
import os
import shutil
import signal
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("workbench_probe.py")
SCREENSHOT = REPO / "test-artifacts" / "gui-workbench.png"
FREECAD = shutil.which("freecad")
TIMEOUT_S = 180

pytestmark = pytest.mark.skipif(FREECAD is None, reason="FreeCAD (freecad) is not installed")


@pytest.fixture(scope="module")
def gui_result(tmp_path_factory):
    result_file = tmp_path_factory.mktemp("gui") / "result.json"
    if SCREENSHOT.exists():
        SCREENSHOT.unlink()
    env = dict(os.environ,
               QTWEBENGINE_DISABLE_SANDBOX="1",
               WAFERSCAN_GUI_RESULT=str(result_file),
               WAFERSCAN_GUI_SCREENSHOT=str(SCREENSHOT))
    command = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", FREECAD, str(PROBE)]
    # Own process group: on a timeout, xvfb-run, Xvfb and FreeCAD all go.
    proc = subprocess.Popen(command, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        output, _ = proc.communicate(timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        output, _ = proc.communicate()
        pytest.fail(f"FreeCAD GUI did not quit within {TIMEOUT_S} s:\n{output}")
    assert result_file.exists(), f"the probe wrote no result (rc {proc.returncode}):\n{output}"
    result = json.loads(result_file.read_text(encoding="utf-8"))
    assert result["ok"], result.get("error")
    return result


def test_workbench_is_active(gui_result):
    assert gui_result["workbench_name"] == "WaferScanWorkbench"
    assert gui_result["menu_text"] == "WaferScan"
    assert os.path.realpath(gui_result["icon"]) == str(REPO / "resources" / "icons" / "WaferScan.svg")


def test_pinocchio_imports_inside_the_gui(gui_result):
    assert gui_result["pinocchio_version"].startswith("4.")
    assert not gui_result["numpy_file"].startswith(str(REPO / ".venv"))


def test_screenshot_saved(gui_result):
    assert gui_result["screenshot_saved"]
    assert SCREENSHOT.stat().st_size > 0
