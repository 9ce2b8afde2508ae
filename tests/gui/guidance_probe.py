# Run by FreeCAD's GUI (tests/gui/test_gui_guidance.py): Run scan on documents that are not ready,
# as a new user's are: nothing tagged; a carrier and a sensor but no wafer. Each says what to do
# next in a message box (a fresh FreeCAD hides the report view).
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, message_texts, result, start, wait_for  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    doc = App.newDocument("Untagged")
    box = doc.addObject("Part::Box", "Foup")
    box.Length, box.Width, box.Height = 340, 360, 70
    sensor = doc.addObject("Part::Box", "Sensor")
    sensor.Length, sensor.Width, sensor.Height = 160, 4, 4
    doc.recompute()
    Gui.runCommand("WaferScan_RunScan")
    result["untagged"] = message_texts()
    result["untagged_panel"] = bool(Gui.Control.activeDialog())
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(box)
    Gui.runCommand("WaferScan_TagCarrier")
    message_texts()
    Gui.runCommand("WaferScan_RunScan")
    result["no_scanner"] = message_texts()
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(sensor)
    Gui.runCommand("WaferScan_TagScanner")
    message_texts()
    Gui.Selection.clearSelection()
    Gui.runCommand("WaferScan_RunScan")
    result["no_wafers"] = message_texts()
    from waferscan.gui.session import session
    panel = session.task_panel
    panel.speed.setValue(panel.speed.minimum())
    wait_for("the scan's end", lambda: panel.animation.ended, done)


def done():
    from waferscan.gui.session import last_result
    result["no_wafers_code"] = last_result(App.ActiveDocument).code
    Gui.Control.closeDialog()
    finish()


start(begin)
