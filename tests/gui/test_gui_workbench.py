"""The WaferScan workbench in a real FreeCAD GUI, under Xvfb."""

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("workbench_probe.py")
SCREENSHOT = REPO / "test-artifacts" / "gui-workbench.png"


@pytest.fixture(scope="module")
def gui_result(run_gui_probe):
    if SCREENSHOT.exists():
        SCREENSHOT.unlink()
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCREENSHOT=str(SCREENSHOT))


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
