"""Run by the FreeCAD GUI (`freecad workbench_probe.py`) for test_gui_workbench.py.

Activates the WaferScan workbench, checks pinocchio, saves a screenshot, writes a JSON result
and quits. FreeCAD swallows a script's exception (the GUI just keeps running), so every failure
is caught and written into the result. Paths come from the environment: arguments after the
script would be opened by FreeCAD as documents.
"""

import json
import os
import traceback

import FreeCADGui as Gui
from PySide import QtCore, QtGui

RESULT = os.environ["WAFERSCAN_GUI_RESULT"]
SCREENSHOT = os.environ["WAFERSCAN_GUI_SCREENSHOT"]


def probe():
    result = {"ok": False}
    try:
        Gui.activateWorkbench("WaferScanWorkbench")
        Gui.updateGui()
        workbench = Gui.activeWorkbench()
        result["workbench_name"] = workbench.name()
        result["menu_text"] = workbench.MenuText
        result["icon"] = workbench.Icon

        import numpy
        import pinocchio
        result["pinocchio_version"] = pinocchio.__version__
        result["numpy_file"] = numpy.__file__

        window = Gui.getMainWindow()
        os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
        result["screenshot_saved"] = window.grab().save(SCREENSHOT)
        result["ok"] = True
    except Exception:
        result["error"] = traceback.format_exc()
    finally:
        with open(RESULT, "w", encoding="utf-8") as out:
            json.dump(result, out)
        QtGui.QApplication.quit()


# Start once the main window is up and the event loop runs.
QtCore.QTimer.singleShot(1000, probe)
