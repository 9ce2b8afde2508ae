# Run by FreeCAD's GUI (tests/gui/test_gui_mcs_lock.py): the MCS link panel watching a folder
# (WAFERSCAN_GUI_MCS/<case>) loses the folder's lock to another link, as the core's
# test_mcs_link_lock does it (flock is per open file: a second link in this process holds it as
# another process would). Cases: the lock file deleted, the folder removed and recreated. What
# the panel shows, and that it answers nothing more, is written to the result.
import os
import shutil
import sys
from pathlib import Path

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, later, result, start, wait_for, window_shot  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402

BASE = Path(os.environ["WAFERSCAN_GUI_MCS"])
CASES = ["lock_deleted", "folder_recreated"]
state = {"others": []}


def never_scans(command, should_stop):
    raise AssertionError("the other link is never polled")


def next_case():
    if not CASES:
        for other in state["others"]:
            other.close()
        finish()
        return
    case = CASES.pop(0)
    folder = BASE / case
    folder.mkdir()
    from waferscan.gui.mcs_script import open_mcs_panel
    from waferscan.gui.session import session

    if App.ActiveDocument is None:
        Gui.activateWorkbench("WaferScanWorkbench")
        Gui.runCommand("WaferScan_NewPaperLayout")
    elif session.task_panel is not None and session.task_panel.is_open():
        session.task_panel.reject()
    panel = open_mcs_panel(App.ActiveDocument, folder)
    panel.start(events=True, poll_ms=100)
    state.update(case=case, folder=folder, panel=panel)
    (folder / "commands.txt").write_text("1 SCF\n", encoding="utf-8")
    wait_for("seq 1 answered", lambda: len(panel.log_rows()) == 1, take_the_lock)


def take_the_lock():
    from waferscan.core.files.mcs_link import LOCK, McsLink

    folder, case = state["folder"], state["case"]
    result[case] = {"watching_before": state["panel"].watching}
    # In one step: the panel's timer cannot poll between the loss and the other link's lock.
    if case == "lock_deleted":
        os.remove(folder / LOCK)
    else:
        shutil.rmtree(folder)
        folder.mkdir()
        (folder / "commands.txt").write_text("1 SCF\n", encoding="utf-8")
    state["others"].append(McsLink(folder, never_scans, log=lambda text: None))
    with open(folder / "commands.txt", "a", encoding="utf-8") as handle:
        handle.write("2 SCF\n")
    panel = state["panel"]
    wait_for("the panel to stop watching", lambda: not panel.watching,
             lambda: later(stopped, 500), timeout_s=30)


def stopped():
    panel, folder, case = state["panel"], state["folder"], state["case"]
    seen = result[case]
    seen.update(state=panel.state.text(), style=panel.state.styleSheet(),
                start_enabled=panel.start_button.isEnabled(),
                stop_enabled=panel.stop_button.isEnabled(), rows=panel.log_rows(),
                panel_open=panel.is_open())
    window_shot(f"gui-mcs-lock-lost-{case}.png")
    # More commands: nobody in this FreeCAD answers them.
    with open(folder / "commands.txt", "a", encoding="utf-8") as handle:
        handle.write("3 SCF\n")
    later(after_more, 1500)


def after_more():
    panel, folder, case = state["panel"], state["folder"], state["case"]
    seen = result[case]
    seen["rows_after"] = len(panel.log_rows())
    seen["results_after"] = (folder / "results.txt").read_text(encoding="utf-8") \
        if (folder / "results.txt").exists() else None
    seen["history_after"] = sorted(os.listdir(folder / "history")) \
        if (folder / "history").exists() else []
    later(next_case)


start(next_case)
