# Run by FreeCAD's GUI (tests/gui/test_gui_tolerance.py): the "Tolerance study…" command opens
# its dialog; with a scenario, a tolerance file, N, a seed and one worker set, Run sweeps in a
# QProcess; the progress bar ends full, the summary is read and both plots are shown; a click
# enlarges a plot; Run and Stop are recorded lines; Stop interrupts a long sweep. With
# WAFERSCAN_GUI_SWEEP_SMALL set, only opens the dialog on a small screen and measures it.
import json
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, console_calls, finish, later, result, start, wait_for)

import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

SETTINGS = json.loads(os.environ["WAFERSCAN_GUI_SWEEP"])


def step_open():
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_ToleranceStudy")
    import waferscan.gui.commands as commands

    dialog = commands.session.tolerance_study
    result["opened"] = dialog is not None and dialog.isVisible()
    dialog.input_edit.setText(SETTINGS["input"])
    dialog.tolerance_edit.setText(SETTINGS["tolerances"])
    dialog.n_spin.setValue(SETTINGS["n"])
    dialog.seed_spin.setValue(SETTINGS["seed"])
    dialog.workers_spin.setValue(SETTINGS["workers"])
    dialog.out_edit.setText(SETTINGS["out"])
    seen = []
    dialog.progress.valueChanged.connect(lambda v: seen.append((v, dialog.progress.maximum())))
    dialog.run_button.click()
    result["running"] = dialog.state
    wait_for("the sweep", lambda: dialog.state in ("done", "failed"),
             lambda: later(lambda: step_check(dialog, seen)), timeout_s=150)


def step_check(dialog, seen):
    result["state"] = dialog.state
    result["errors"] = dialog.errors
    result["summary"] = dialog.summary
    result["progress_seen"] = seen
    result["progress_end"] = [dialog.progress.value(), dialog.progress.maximum()]
    result["text"] = dialog.text.toPlainText()
    result["plots"] = [not label.pixmap().isNull() and label.pixmap().width()
                       for label in (dialog.confusion_label, dialog.margins_label)]
    dialog.grab().save(artifact("gui-tolerance-study.png"))
    shown = dialog.confusion_label.pixmap().width()
    click(dialog.confusion_label)
    window = dialog.confusion_label.enlarged
    result["enlarged"] = [window is not None and window.isVisible(),
                          window is not None and window.isSizeGripEnabled(), shown,
                          dialog.confusion_label.plot.width()]
    later(lambda: step_enlarged(dialog), 300)


def click(widget):
    """A left click in the middle of ``widget``, as the mouse gives it."""
    centre = QtCore.QPoint(widget.width() // 2, widget.height() // 2)
    for kind in (QtCore.QEvent.MouseButtonPress, QtCore.QEvent.MouseButtonRelease):
        QtGui.QApplication.sendEvent(widget, QtGui.QMouseEvent(
            kind, centre, QtCore.Qt.LeftButton, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier))


def step_enlarged(dialog):
    window = dialog.confusion_label.enlarged
    window.grab().save(artifact("gui-tolerance-plot-enlarged.png"))
    view = window.findChildren(QtGui.QLabel)[0]
    result["enlarged_width"] = view.pixmap().width()
    window.close()
    later(lambda: step_stop(dialog))


def step_stop(dialog):
    """A sweep far too long to wait for, stopped from its Stop button."""
    dialog.n_spin.setValue(50_000_000)
    dialog.out_edit.setText(SETTINGS["stopped_out"])
    dialog.run_button.click()
    result["stop_enabled"] = [dialog.stop_button.isEnabled(), dialog.run_button.isEnabled()]
    # Stopped 4 s after it started: the Dask workers are starting or sweeping by then.
    wait_for("the long sweep's process",
             lambda: dialog.process is not None and dialog.process.processId() > 0,
             lambda: later(lambda: step_stopping(dialog), 4000), timeout_s=60)


def step_stopping(dialog):
    result["pid"] = int(dialog.process.processId())
    dialog.stop_button.click()
    wait_for("the stopped sweep", lambda: dialog.state != "running",
             lambda: later(lambda: step_stopped(dialog)), timeout_s=60)


def step_stopped(dialog):
    result["stopped"] = [dialog.state, dialog.status.text(), dialog.stop_button.isEnabled(),
                         dialog.run_button.isEnabled(), dialog.process is None]
    stopped_out = SETTINGS["stopped_out"]
    result["stopped_out"] = sorted(os.listdir(stopped_out)) if os.path.isdir(stopped_out) \
        else None
    dialog.n_spin.setValue(SETTINGS["n"])
    later(lambda: step_active_document(dialog))


def step_active_document(dialog):
    """With no layout file given, the sweep takes the active document (saved to a copy)."""
    import waferscan.gui.commands as commands

    doc = commands.open_scenario(SETTINGS["input"])
    result["document"] = doc.Name
    dialog.input_edit.setText("")
    dialog.n_spin.setValue(SETTINGS["n_document"])
    dialog.run_button.click()
    result["document_args"] = dialog.last_arguments
    wait_for("the sweep of the active document", lambda: dialog.state in ("done", "failed"),
             lambda: later(lambda: step_document_done(dialog)), timeout_s=150)


def step_document_done(dialog):
    result["document_state"] = dialog.state
    result["document_errors"] = dialog.errors
    result["document_summary"] = dialog.summary
    result["console_calls"] = console_calls()
    dialog.close()
    finish()


def step_small_screen():
    """The dialog on a 1024 x 700 screen: all of it on the screen, Run and Stop included."""
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_ToleranceStudy")
    import waferscan.gui.commands as commands

    dialog = commands.session.tolerance_study
    later(lambda: step_small_measured(dialog), 500)


def step_small_measured(dialog):
    screen = QtGui.QApplication.primaryScreen().availableGeometry()
    frame = dialog.frameGeometry()
    buttons = [QtCore.QRect(b.mapToGlobal(QtCore.QPoint(0, 0)), b.size())
               for b in (dialog.run_button, dialog.stop_button)]
    result["screen"] = [screen.x(), screen.y(), screen.width(), screen.height()]
    result["frame"] = [frame.x(), frame.y(), frame.width(), frame.height()]
    result["buttons_on_screen"] = [screen.contains(b) for b in buttons]
    dialog.grab().save(artifact("gui-tolerance-study-small-screen.png"))
    dialog.close()
    finish()


start(step_small_screen if os.environ.get("WAFERSCAN_GUI_SWEEP_SMALL") else step_open)
