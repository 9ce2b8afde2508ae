# Run by FreeCAD's GUI (tests/gui/test_gui_calibrate.py): open a scenario whose carrier sits off
# its nominal seat and pitch, run the Calibrate command, and read the recipe table and the check
# scan's code as a user sees them; then the paper's layout, which has no wafer in slot 25: the
# failure's words in a message box.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import artifact, finish, result, start  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    from waferscan.gui.scanning import open_scenario
    from waferscan.gui.session import session
    from waferscan.gui.calibration_view import table_contents

    open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    Gui.updateGui()
    result["document"] = App.ActiveDocument.Name
    Gui.runCommand("WaferScan_Calibrate")
    Gui.updateGui()
    dialog = session.dialogs[0]
    result["title"] = dialog.windowTitle()
    result["visible"] = dialog.isVisible()
    result["table"] = table_contents(dialog)
    result["check"] = dialog.findChild(QtGui.QLabel, "check").text()
    dialog.grab().save(artifact("gui-calibration.png"))
    dialog.close()
    Gui.runCommand("WaferScan_NewPaperLayout")
    Gui.updateGui()
    Gui.runCommand("WaferScan_Calibrate")
    Gui.updateGui()
    boxes = [b for b in session.message_boxes if b.isVisible()]
    result["error_boxes"] = [b.text() for b in boxes]
    finish()


start(begin)
