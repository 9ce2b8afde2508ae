# Run by FreeCAD's GUI (tests/gui/test_gui_calibrate.py): open a scenario whose carrier sits off
# its nominal seat and pitch, run the Calibrate command, and read the recipe table and the check
# scan's code as a user sees them; save the recipe through the dialog's file chooser, apply it
# to the document, undo it and replay the recorded line; then the paper's layout, which has no
# wafer in slot 25: the failure's words in a message box.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, console_calls, finish, later, message_texts, result, start)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

RECIPE = os.environ["WAFERSCAN_GUI_RECIPE"]
state = {}


def document_values(doc):
    """What Apply writes, as the document holds it."""
    carrier = doc.getObject("LP1")
    settings = next(o for o in doc.Objects if "ThicknessCorrection" in o.PropertiesList)
    return {"Pitch": float(carrier.Pitch.Value), "SlotOriginZ": carrier.SlotOrigin.Base.z,
            "StartZ": float(settings.StartZ.Value), "FinalZ": float(settings.FinalZ.Value),
            "ThicknessCorrection": settings.ThicknessCorrection}


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    from waferscan.gui.scanning import open_scenario, result_now
    from waferscan.gui.session import session
    from waferscan.gui.calibration_view import table_contents

    doc = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    Gui.updateGui()
    result["document"] = doc.Name
    result["code_before"] = result_now(doc).code
    result["values_before"] = document_values(doc)
    result["undo_before"] = list(doc.UndoNames)
    Gui.runCommand("WaferScan_Calibrate")
    Gui.updateGui()
    dialog = session.dialogs[0]
    state.update(doc=doc, dialog=dialog)
    result["title"] = dialog.windowTitle()
    result["visible"] = dialog.isVisible()
    result["table"] = table_contents(dialog)
    result["check"] = dialog.findChild(QtGui.QLabel, "check").text()
    result["buttons"] = [b.text() for b in dialog.findChildren(QtGui.QPushButton)]
    dialog.grab().save(artifact("gui-calibration.png"))

    def choose_file():  # the file chooser, as a user types a name into it
        chooser = QtGui.QApplication.activeModalWidget()
        if not isinstance(chooser, QtGui.QFileDialog):
            QtCore.QTimer.singleShot(50, choose_file)
            return
        result["chooser_title"] = chooser.windowTitle()
        name = chooser.findChild(QtGui.QLineEdit, "fileNameEdit")
        name.setText(RECIPE)
        result["chooser_files"] = chooser.selectedFiles()
        buttons = chooser.findChild(QtGui.QDialogButtonBox)
        buttons.button(QtGui.QDialogButtonBox.Save).click()
        result["chooser_open"] = chooser.isVisible()

    QtCore.QTimer.singleShot(100, choose_file)
    dialog.findChild(QtGui.QPushButton, "save").click()  # returns once the chooser is closed
    result["messages_after_save"] = message_texts()
    if not os.path.exists(RECIPE):
        finish(f"no recipe written: {result}")
        return
    result["recipe"] = open(RECIPE, encoding="utf-8", newline="").read()
    result["status_after_save"] = dialog.findChild(QtGui.QLabel, "status").text()
    result["undo_after_save"] = list(doc.UndoNames)
    later(apply_it)


def apply_it():
    from waferscan.gui.scanning import result_now

    doc, dialog = state["doc"], state["dialog"]
    apply = dialog.findChild(QtGui.QPushButton, "apply")
    apply.click()
    Gui.updateGui()
    result["values_applied"] = document_values(doc)
    result["undo_after_apply"] = list(doc.UndoNames)
    result["code_after_apply"] = result_now(doc).code
    result["status_after_apply"] = dialog.findChild(QtGui.QLabel, "status").text()
    result["enabled_after_apply"] = [apply.isEnabled(),
                                     dialog.findChild(QtGui.QPushButton, "save").isEnabled()]
    result["messages_after_apply"] = message_texts()
    dialog.grab().save(artifact("gui-calibration-applied.png"))
    Gui.runCommand("Std_Undo")
    Gui.updateGui()
    result["values_undone"] = document_values(doc)
    result["code_undone"] = result_now(doc).code
    # The recorded line, replayed as a macro would: no dialog, the same values.
    calls = console_calls()
    result["console_calls"] = calls
    line = next(c for c in calls if "apply_calibration(" in c)
    Gui.doCommand(line)
    Gui.updateGui()
    result["modal_after_replay"] = QtGui.QApplication.activeModalWidget() is not None
    result["values_replayed"] = document_values(doc)
    result["undo_after_replay"] = list(doc.UndoNames)
    dialog.close()
    # A calibration shown, then the layout edited: its buttons say so and write nothing.
    from waferscan.gui.session import session

    Gui.runCommand("WaferScan_Calibrate")
    Gui.updateGui()
    stale = session.dialogs[0]
    settings = next(o for o in doc.Objects if "ThicknessCorrection" in o.PropertiesList)
    doc.openTransaction("Edit")
    settings.ZStep = 0.02
    doc.commitTransaction()
    values = document_values(doc)
    stale.findChild(QtGui.QPushButton, "apply").click()
    Gui.updateGui()
    result["stale_messages"] = message_texts()
    result["stale_unchanged"] = [document_values(doc) == values, doc.UndoNames[0]]
    stale.close()
    later(failure)


def failure():
    from waferscan.gui.session import session

    Gui.runCommand("WaferScan_NewPaperLayout")
    Gui.updateGui()
    Gui.runCommand("WaferScan_Calibrate")
    Gui.updateGui()
    boxes = [b for b in session.message_boxes if b.isVisible()]
    result["error_boxes"] = [b.text() for b in boxes]
    for box in boxes:
        box.close()
    # The recorded lines on a layout that cannot be calibrated: said, nothing written.
    doc = App.ActiveDocument
    undo = list(doc.UndoNames)
    Gui.doCommand(f"waferscan.gui.commands.apply_calibration(App.getDocument({doc.Name!r}))")
    Gui.doCommand(f"waferscan.gui.commands.save_calibration_recipe("
                  f"App.getDocument({doc.Name!r}), {RECIPE + '.never'!r})")
    Gui.updateGui()
    result["failed_lines"] = message_texts()
    result["failed_undo_unchanged"] = list(doc.UndoNames) == undo
    result["failed_file"] = os.path.exists(RECIPE + ".never")
    finish()


start(begin)
