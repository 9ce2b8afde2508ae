# Run by FreeCAD's GUI (tests/gui/test_gui_missed.py): Run scan on the scenario
# WAFERSCAN_GUI_SCENARIO, whose beam passes beside every wafer: a message box says so at once,
# and the panel's status when the scan ends.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    finish, message_texts, result, start, task_panel, wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def begin():
    from waferscan.gui.playback import run_scan
    from waferscan.gui.scanning import open_scenario

    Gui.activateWorkbench("WaferScanWorkbench")
    doc = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    animation = run_scan(doc, duration_s=1.0)
    window_shot("gui-beam-misses-box.png")
    result["boxes"] = message_texts()
    result["code"] = animation.result.code
    wait_for("the scan's end", lambda: animation.ended, ended)


def ended():
    panel = task_panel()
    result["status"] = panel.status.text()
    window_shot("gui-beam-misses-panel.png")
    panel.animation.stop()
    Gui.Control.closeDialog()
    finish()


start(begin)
