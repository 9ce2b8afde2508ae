"""Issue 27 item 15 follow-up: the workbench's start-up does not import the MCS link's and the
tolerance study's modules (gui/commands.py named their functions through imports at start-up);
the recorded lines that call them, ``waferscan.gui.commands.stop_tolerance_study()`` and the
MCS link's, still work and import them then."""

from pathlib import Path

import pytest

PROBE = Path(__file__).resolve().with_name("lazy_probe.py")


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    return run_gui_probe(PROBE)


def test_the_workbench_starts_without_the_mcs_and_tolerance_modules(gui):
    assert gui["commands_loaded"] is True
    assert gui["loaded_at_start"] == []


def test_their_lines_import_them_when_called(gui):
    assert gui["after_study_line"] == ["waferscan.gui.tolerance_dialog"]
    assert gui["same_function"] is True
    assert gui["after_mcs_name"] == ["waferscan.gui.mcs_script", "waferscan.gui.mcs_panel",
                                     "waferscan.gui.link_watch",
                                     "waferscan.gui.tolerance_dialog"]
    assert gui["listed"] == []  # every name in __all__ is there
    assert gui["unknown"] == "module 'waferscan.gui.commands' has no attribute 'no_such_name'"
