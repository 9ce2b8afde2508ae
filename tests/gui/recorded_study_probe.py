# Run by FreeCAD's GUI (tests/gui/test_gui_recorded_study.py), issue 27: the tolerance study's
# Run is recorded as one replayable line. With the Output folder left empty the sweep writes to a
# temporary folder of the dialog's, and the line names none (that folder will not be there when a
# macro replays it); with a folder chosen, the line names it. Each line is run again as a macro
# would, the dialog closed first: a new dialog sweeps and shows the result.
import os
import sys
import tempfile

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import console_calls, finish, result, start, wait_for  # noqa: E402

import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

state = {}
N = 40


def show_console():
    for dock in Gui.getMainWindow().findChildren(QtGui.QDockWidget):
        if dock.objectName() == "Python console":
            dock.show()


def runs():
    return [c for c in console_calls() if ".run_tolerance_study(" in c]


def dialog():
    from waferscan.gui.session import session

    return session.tolerance_study


def seen(d):
    """What a user sees of the dialog's sweep, and where it wrote."""
    out = d.out_used
    return {"state": d.state, "errors": list(d.errors), "status": d.status.text(),
            "out_field": d.out_edit.text(), "placeholder": d.out_edit.placeholderText(),
            "out_used": out, "scratch": d._scratch,
            "summary_written": out is not None and os.path.exists(os.path.join(out, "summary.json")),
            "n": (d.summary or {}).get("n")}


def begin():
    from waferscan.addon import paper_scenario

    show_console()
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_ToleranceStudy")
    d = dialog()
    d.input_edit.setText(str(paper_scenario()))
    d.n_spin.setValue(N)
    d.workers_spin.setValue(0)
    result["out_default"] = d.out_edit.text()
    d.run_button.click()
    wait_for("the sweep to a temporary folder", lambda: d.state in ("done", "failed"),
             lambda: temporary_done(d), timeout_s=120)


def temporary_done(d):
    result["temporary"] = seen(d)
    result["temporary_line"] = runs()[-1:]
    chosen = tempfile.mkdtemp(prefix="chosen-study-")
    state["chosen"] = os.path.join(chosen, "out")
    result["chosen"] = state["chosen"]
    d.out_edit.setText(state["chosen"])
    d.run_button.click()
    wait_for("the sweep to the chosen folder", lambda: d.state in ("done", "failed"),
             lambda: chosen_done(d), timeout_s=120)


def chosen_done(d):
    result["chosen_run"] = seen(d)
    result["chosen_line"] = runs()[-1:]
    d.close()
    Gui.updateGui()
    replay(0)


def replay(k):
    """Run the k-th recorded line again, as a macro would, with no dialog open."""
    lines = [result["temporary_line"], result["chosen_line"]][k]
    if not lines:
        result.setdefault("replays", []).append({"error": "no line"})
        return next_replay(k)
    old = dialog()
    if k == 1:  # the chosen folder's sweep again: its files are written anew
        os.remove(os.path.join(state["chosen"], "summary.json"))
    error = None
    try:
        Gui.doCommand(lines[-1])
    except Exception as exc:  # noqa: BLE001 (written into the result)
        error = f"{type(exc).__name__}: {exc}"
    d = dialog()
    wait_for("the replayed sweep", lambda: d.state in ("done", "failed"),
             lambda: replayed(k, d, old, error), timeout_s=120)


def replayed(k, d, old, error):
    result.setdefault("replays", []).append({"error": error, "new_dialog": d is not old,
                                             **seen(d)})
    d.close()
    Gui.updateGui()
    next_replay(k)


def next_replay(k):
    if k == 0:
        replay(1)
    else:
        finish()


start(begin)
