# Run by FreeCAD's GUI (tests/gui/test_gui_scan.py): activate WaferScan, build the paper's
# layout with its command, run the animated scan to the end, read the results table and the
# slot-code dialog as a user sees them, save screenshots, report as JSON, quit.
import json
import os
import traceback

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

OUT = os.environ["WAFERSCAN_GUI_ARTIFACTS"]
result = {"ok": False}


def write_and_quit():
    with open(os.environ["WAFERSCAN_GUI_RESULT"], "w", encoding="utf-8") as handle:
        json.dump(result, handle)
    QtGui.QApplication.quit()


def after_animation():
    try:
        from waferscan.gui import commands
        table, dialog = commands._session["dialogs"]
        result["rows"] = table.rows()
        result["dialog_code"] = dialog.code_label.text()
        result["sheet_code"] = App.ActiveDocument.getObject("ScanResults").get("code")
        table.grab().save(os.path.join(OUT, "gui-results-table.png"))
        dialog.grab().save(os.path.join(OUT, "gui-slot-code.png"))
        view = Gui.ActiveDocument.ActiveView
        view.saveImage(os.path.join(OUT, "gui-after-scan.png"), 1200, 800, "White")
        result["ok"] = True
    except Exception:
        result["error"] = traceback.format_exc()
    write_and_quit()


def start():
    try:
        Gui.activateWorkbench("WaferScanWorkbench")
        Gui.runCommand("WaferScan_NewPaperLayout")
        from waferscan.gui import commands
        animation = commands.run_scan(App.ActiveDocument, steps_per_frame=50)
        result["frames"] = 0
        animation.timer.timeout.connect(lambda: result.__setitem__("frames", result["frames"] + 1))
        animation.finished.connect(lambda: QtCore.QTimer.singleShot(300, after_animation))
        QtCore.QTimer.singleShot(150, lambda: Gui.ActiveDocument.ActiveView.saveImage(
            os.path.join(OUT, "gui-during-scan.png"), 1200, 800, "White"))
    except Exception:
        result["error"] = traceback.format_exc()
        write_and_quit()


QtCore.QTimer.singleShot(800, start)
