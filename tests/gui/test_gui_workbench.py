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


COMMANDS = ["New paper layout", "Open scenario…", "Tag selection", "Set up carrier and sensor…",
            "Run scan", "Calibrate",
            "MCS link…", "Host link…", "Results table", "Slot code", "Cross-check with CAD",
            "Tolerance study…", "Preferences…"]


def test_the_toolbar_has_every_command_with_its_own_icon_and_a_tooltip(gui_result):
    toolbar = gui_result["toolbar"]
    assert [text for text, _, _, _ in toolbar] == COMMANDS
    for text, tip, has_icon, drawn in toolbar:
        assert tip and has_icon, text
        assert drawn > 0.15, f"{text}: its icon is nearly empty at 24 px"
    pixmaps = gui_result["pixmaps"]
    # One SVG per command, the three tag commands, Make carrier from solids and Untag in their
    # drop-down each their own, all in resources/icons.
    assert len(set(pixmaps.values())) == len(COMMANDS) + 5
    for name, path in pixmaps.items():
        assert path.endswith(f"{name if name != 'WaferScan_Tag' else 'WaferScan_TagSelection'}.svg")
        assert Path(path).is_file(), path


def test_the_menu_lists_the_tag_commands_one_by_one(gui_result):
    menu = gui_result["menu"]
    assert menu[:2] == COMMANDS[:2]
    assert menu[2:7] == ["Tag as wafer", "Tag as carrier", "Tag as scanner",
                         "Make carrier from solids", "Untag"]
    assert menu[7:] == COMMANDS[3:]


def test_the_preferences_command_opens_the_waferscan_page(gui_result):
    assert "WaferScan" in gui_result["preferences"]["groups"]
    assert gui_result["preferences"]["shot"]
