# Run by FreeCAD's GUI (tests/gui/test_gui_tolerance.py): the "Tolerance study…" command opens
# its dialog; with a scenario, a tolerance file, N, a seed and one worker set, Run sweeps in a
# QProcess; the progress bar ends full, the summary is read and both plots are shown.
import json
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import artifact, finish, later, result, start, wait_for  # noqa: E402

import FreeCADGui as Gui  # noqa: E402

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
    dialog.close()
    finish()


start(step_open)
