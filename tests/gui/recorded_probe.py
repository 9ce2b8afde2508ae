# Run by FreeCAD's GUI (tests/gui/test_gui_recorded.py), issue 27 item 12: every action is one
# replayable line in the Python console. Tag as wafer on a compound answers the split question
# in its line; the scan panel's Recipe and Sensor Apply; the MCS link's Save, Start and Stop.
# Each line is read from the console, the document put back (Undo, or the panel closed and the
# file removed), and the line run again as a macro would: the same document or file, and no
# question asked.
import os
import sys
import tempfile

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    console_calls, finish, message_texts, open_section, result, scan_paper_layout, scan_settings, start,
    task_panel, wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import probe_steps as steps  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

state = {}


def calls(name):
    return [c for c in console_calls() if f".{name}(" in c]


def replay_line(line):
    """Run a recorded line as a macro would; returns the modal questions that came up (each
    answered with Cancel), and the error it raised (None)."""
    asked = []

    def watch():
        if not state.get("replaying"):  # a check still queued when the line had run
            return
        box = QtGui.QApplication.activeModalWidget()
        if box is not None:
            asked.append(box.text() if isinstance(box, QtGui.QMessageBox) else str(box))
            box.reject()
        if state.get("replaying"):
            QtCore.QTimer.singleShot(50, watch)

    state["replaying"] = True
    QtCore.QTimer.singleShot(50, watch)
    error = None
    try:
        Gui.doCommand(line)
    except Exception as exc:  # noqa: BLE001 (written into the result)
        error = f"{type(exc).__name__}: {exc}"
    state["replaying"] = False
    Gui.updateGui()
    return asked, error


def answer_next_question(button_text):
    """``probe_steps.answer_next_question``, the questions kept in the result."""
    steps.answer_next_question(button_text, result.setdefault("questions", []))


def show_console():
    for dock in Gui.getMainWindow().findChildren(QtGui.QDockWidget):
        if dock.objectName() == "Python console":
            dock.show()


# --- Tag as wafer on a compound: the split answer in the line ----------------------------

def split_state(doc):
    """What the split and the tagging made: (role, bottom Z, volume) of each object."""
    return sorted([getattr(o, "WaferScanRole", ""), round(o.Shape.BoundBox.ZMin, 3),
                   round(o.Shape.Volume, 1)] for o in doc.Objects)


def begin():
    import Part

    show_console()
    Gui.activateWorkbench("WaferScanWorkbench")
    doc = App.newDocument("SplitCell")
    V = App.Vector
    tool = doc.addObject("Part::Feature", "Tool")
    tool.Shape = Part.makeCompound([Part.makeCylinder(150, 0.7, V(0, 0, 10.0 * k))
                                    for k in (1, 2, 3)] + [Part.makeBox(10, 300, 50,
                                                                        V(200, 0, 0))])
    doc.recompute()
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(tool)
    answer_next_question("Split into solids")
    Gui.runCommand("WaferScan_TagWafer")
    Gui.updateGui()
    result["split_calls"] = calls("tag_selection")
    result["split_questions"] = list(result.get("questions", []))
    result["split_made"] = split_state(doc)
    result["split_undo"] = list(doc.UndoNames)[:2]
    Gui.SendMsgToActiveView("ViewFit")
    window_shot("gui-recorded-split.png")
    result["split_message"] = " ".join(message_texts())
    doc.undo()
    doc.undo()
    result["split_undone"] = split_state(doc)
    if result["split_calls"]:
        asked, error = replay_line(result["split_calls"][-1])
        result["split_replay"] = {"asked": asked, "error": error, "made": split_state(doc),
                                  "undo": list(doc.UndoNames)[:2]}
    retag(doc)
    App.closeDocument(doc.Name)
    first = scan_paper_layout()
    first.speed.setValue(1.0)
    wait_for("the scan's end", lambda: first.animation.ended, apply_settings)


def retag(doc):
    """A wafer tagged as the scanner: the re-tag question's answer goes into the line too."""
    wafer = next(o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "Wafer")
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(wafer)
    asked = len(result.get("questions", []))
    answer_next_question("Tag as scanner")
    Gui.runCommand("WaferScan_TagScanner")
    Gui.updateGui()
    message_texts()
    lines = [c for c in calls("tag_selection") if "('scanner'" in c]
    made = [wafer.WaferScanRole, list(doc.UndoNames)[:1]]
    result["retag_undo_names"] = list(doc.UndoNames)
    doc.undo()
    undone = getattr(wafer, "WaferScanRole", None)
    replayed = replay_line(lines[-1]) if lines else (None, "no line")
    message_texts()
    result["retag"] = {"calls": lines, "questions": result.get("questions", [])[asked:],
                       "made": made, "undone": undone, "replay": replayed,
                       "replayed": [getattr(wafer, "WaferScanRole", None),
                                    list(doc.UndoNames)[:1]]}


# --- the scan panel's Recipe and Sensor Apply ---------------------------------------------

def settings_state():
    from waferscan.cad.recipe_properties import limit_value

    obj = scan_settings()
    return [limit_value(obj, "ThicknessMin"), str(obj.Rules), float(obj.ThresholdOn),
            float(obj.Jab.Value)]


def fields(panel):
    return [panel.recipe_section.fields["ThicknessMin"].text(),
            panel.recipe_section.rules.currentText(),
            panel.sensor.fields["ThresholdOn"].text(), panel.sensor.fields["Jab"].text()]


def apply_settings():
    panel = task_panel()
    doc = App.ActiveDocument
    open_section(panel.recipe_section)
    open_section(panel.sensor)
    result["settings_before"] = settings_state()
    recipe = panel.recipe_section
    recipe.fields["ThicknessMin"].setText("0.66")
    recipe.rules.setCurrentIndex(recipe.rules.findText("boundary"))
    recipe.apply_button.click()
    panel.sensor.fields["ThresholdOn"].setText("0.7")
    panel.sensor.fields["Jab"].setText("3 mm")
    panel.sensor.apply_button.click()
    result["settings_messages"] = [recipe.message.text(), panel.sensor.message.text()]
    result["settings_calls"] = calls("apply_recipe") + calls("apply_sensor_settings")
    result["settings_applied"] = settings_state()
    result["settings_undo"] = list(doc.UndoNames)[:2]
    # A refused recipe: its line runs, the panel says why, nothing is written.
    recipe.fields["ThicknessMin"].setText("2 mm")
    recipe.apply_button.click()
    result["refused"] = {"message": recipe.message.text(), "state": settings_state(),
                         "calls": calls("apply_recipe")[len(calls("apply_recipe")) - 1:]}
    recipe.fields["ThicknessMin"].setText("0.66 mm")
    Gui.runCommand("Std_Undo")
    Gui.runCommand("Std_Undo")
    Gui.updateGui()
    result["settings_undone"] = settings_state()
    result["fields_undone"] = fields(panel)
    replays = []
    for line in result["settings_calls"]:
        replays.append(replay_line(line))
    result["settings_replay"] = {"replays": replays, "state": settings_state(),
                                 "undo": list(doc.UndoNames)[:2], "fields": fields(panel),
                                 "messages": [recipe.message.text(),
                                              panel.sensor.message.text()]}
    window_shot("gui-recorded-settings.png", dock_width=420)
    panel.animation.stop()
    Gui.Control.closeDialog()
    Gui.updateGui()
    mcs()


# --- the MCS link's Save, Start and Stop -----------------------------------------------------

def mcs_state(panel):
    return {"watching": panel.watching, "folder": str(panel.folder_path()),
            "state": panel.state.text(), "store": panel.store.isChecked()}


def read_bytes(path):
    try:
        with open(path, "rb") as handle:
            return handle.read()
    except OSError:
        return None


def mcs():
    from waferscan.gui.mcs_panel import McsTaskPanel

    folder = tempfile.mkdtemp(prefix="recorded-mcs-")
    parameters = os.path.join(folder, "parameters.txt")
    Gui.runCommand("WaferScan_McsLink")
    panel = task_panel()
    panel.folder.setText(folder)
    panel.folder.editingFinished.emit()
    panel.editor.setPlainText(panel.editor.toPlainText().rstrip("\n") +
                              "\n# recorded by the probe")
    panel.save_button.click()
    saved = read_bytes(parameters)
    result["mcs_save_calls"] = calls("save_mcs_parameters")
    if saved is not None:
        os.remove(parameters)
    asked, error = replay_line(result["mcs_save_calls"][-1]) if result["mcs_save_calls"] \
        else (None, "no line")
    result["mcs_save_replay"] = {"asked": asked, "error": error,
                                 "same_bytes": saved is not None and
                                 read_bytes(parameters) == saved,
                                 "ends": (saved or b"")[-24:].decode()}
    panel.store.setChecked(True)
    panel.start_button.click()
    result["mcs_started"] = mcs_state(panel)
    panel.stop_button.click()
    result["mcs_stopped"] = mcs_state(panel)
    result["mcs_calls"] = calls("start_mcs_link") + calls("stop_mcs_link")
    Gui.Control.closeDialog()  # the panel closed: the start line opens it again
    Gui.updateGui()
    start_lines = calls("start_mcs_link")
    if not start_lines:  # nothing recorded (before issue 27): nothing to replay
        result["mcs_start_replay"] = {"error": "no line", "panel": False}
        finish()
        return
    asked, error = replay_line(start_lines[-1])
    again = task_panel()
    result["mcs_start_replay"] = {
        "asked": asked, "error": error, "panel": isinstance(again, McsTaskPanel) and
        again is not panel and again.is_open(), **mcs_state(again)}
    window_shot("gui-recorded-mcs.png", dock_width=420)
    again.store.click()  # while watching: its own line
    result["mcs_store"] = {"calls": calls("store_mcs_scans"), **mcs_state(again)}
    stop_lines = calls("stop_mcs_link")
    asked, error = replay_line(stop_lines[-1]) if stop_lines else (None, "no line")
    result["mcs_stop_replay"] = {"asked": asked, "error": error, **mcs_state(again)}
    for line in result["mcs_store"]["calls"][-1:]:  # not watching: a line that says so
        result["mcs_store_replay"] = replay_line(line)
    # Watching again, then the panel closed with its Close button: the link stops, recorded.
    replay_line(start_lines[-1])
    watching = again.watching
    stops = len(calls("stop_mcs_link"))
    again.reject()
    Gui.updateGui()
    result["mcs_closed"] = {"watching_before": watching, "watching": again.link is not None,
                            "stop_lines": len(calls("stop_mcs_link")) - stops}
    # A folder that is not there: the line raises, the panel says why; no traceback.
    missing = os.path.join(folder, "not-there")
    asked, error = replay_line(f"waferscan.gui.commands.start_mcs_link("
                               f"App.getDocument({App.ActiveDocument.Name!r}), {missing!r})")
    result["mcs_missing"] = {"error": error, **mcs_state(task_panel())}
    task_panel().shut_down()
    Gui.Control.closeDialog()
    finish()


start(begin)
