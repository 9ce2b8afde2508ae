# Run by FreeCAD's GUI (tests/gui/test_gui_mcs.py): the MCS link panel driven as an MCS drives it.
# Open the paper's layout and the panel on the folder WAFERSCAN_GUI_MCS; type a bad parameter and
# a good one; save; watch on file-system events only and write commands.txt; then on polling
# only and append to it; then a STOP; report the log and quit. The test compares results.txt
# and the history with the headless watcher's.
import os
import sys
from pathlib import Path

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import artifact, finish, later, result, start, wait_for, window_shot  # noqa: E402,E501

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402

FOLDER = Path(os.environ["WAFERSCAN_GUI_MCS"])
state = {}


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    Gui.runCommand("WaferScan_McsLink")
    from waferscan.gui.session import session
    panel = session.task_panel
    state["panel"] = panel
    result["panel_shown"] = Gui.Control.activeDialog()
    result["folder_from_preferences"] = panel.folder.text()
    panel.set_folder(str(FOLDER))
    result["start_text"] = panel.editor.toPlainText()  # no parameters.txt yet: the layout's
    # A typo on line 3: the panel says where, and will not save.
    lines = result["start_text"].splitlines()
    index = next(i for i, line in enumerate(lines) if line.startswith("z_step"))
    lines[index] = "z_step = -0.01"
    panel.editor.setPlainText("\n".join(lines) + "\n")
    result["bad_line"] = index + 1
    result["bad_check"] = panel.check.text()
    result["bad_save_enabled"] = panel.save_button.isEnabled()
    result["bad_marks"] = [m.cursor.blockNumber() + 1 for m in panel.editor.extraSelections()]
    result["bad_saved"] = panel.save_parameters()
    window_shot("gui-mcs-panel-error.png")
    # The MCS's own parameters: a slow scan at 0.01 mm.
    panel.editor.setPlainText("# from the MCS\nz_step = 0.01\nmode = slow\n")
    result["good_check"] = panel.check.text()
    result["good_saved"] = panel.save_parameters()
    result["parameters_file"] = (FOLDER / "parameters.txt").read_text(encoding="utf-8")
    # File-system events only: the first commands.
    # How long showing an answered scan holds the GUI thread (between two polls): measured,
    # for the record.
    import time
    shown_ms = result.setdefault("show_ms", [])
    show = getattr(panel, "show_scan", None)
    if show is not None:
        def timed(*args):
            started = time.perf_counter()
            show(*args)
            shown_ms.append(round(1000 * (time.perf_counter() - started), 1))
        panel.show_scan = timed
    state["placements"] = placements(App.ActiveDocument)
    state["undo"] = list(App.ActiveDocument.UndoNames)
    result["started_events"] = panel.start(events=True, poll_ms=0)
    result["state_events"] = panel.state.text()
    (FOLDER / "commands.txt").write_text("1 SCF\n2 SCS\n", encoding="utf-8")
    wait_for("two answers on file-system events", lambda: len(panel.log_rows()) >= 2, polling)


def shown_scan(doc):
    """What a user sees of the last scan answered: the results dialogs, the animation, the
    document (stored results, undo steps, the scanner's placement)."""
    from waferscan.gui.session import session

    windows = session.results_windows.get(doc.Name, {})
    table, code = windows.get("table"), windows.get("code")
    animation = getattr(state["panel"], "animation", None)
    return {"code": code.code_label.text() if code is not None else None,
            "table": table.rows() if table is not None else None,
            "animation": None if animation is None else
            {"frames": animation.frames, "ended": animation.ended,
             "in_view": animation.pose is not None, "scan_z": [animation.scan.start_z,
                                                               animation.scan.final_z],
             "mode": animation.scan.mode},
            "stored": [o.Name for o in doc.Objects if o.Name == "ScanResults"],
            "undo": list(doc.UndoNames)}


def placements(doc):
    return [[o.Name, list(o.Placement.Base), list(o.Placement.Rotation.Q)]
            for o in doc.Objects if hasattr(o, "Placement")]


def polling():
    panel = state["panel"]
    result["rows_events"] = panel.log_rows()
    doc = App.ActiveDocument
    store = getattr(panel, "store", None)  # the checkbox (None: a panel without one)
    result["store_default"] = None if store is None else store.isChecked()
    result["shown_events"] = shown_scan(doc)
    result["placements_unmoved"] = placements(doc) == state["placements"]
    window_shot("gui-mcs-scan.png")
    # Polling only: an unknown command and a scan with parameters that no longer make sense.
    result["started_polling"] = panel.start(events=False, poll_ms=100)
    result["state_polling"] = panel.state.text()
    (FOLDER / "parameters.txt").write_text("start_z = 600\n", encoding="utf-8")
    with open(FOLDER / "commands.txt", "a", encoding="utf-8") as handle:
        handle.write("3 FROB\n4 SCF\n")
    wait_for("two more answers by polling", lambda: len(panel.log_rows()) >= 4, replaced)


def replaced():
    panel = state["panel"]
    # commands.txt replaced by rename, as many MCSs write it, with events and polling.
    (FOLDER / "parameters.txt").write_text("z_step = 0.02\n", encoding="utf-8")
    panel.start()
    result["state_both"] = panel.state.text()
    tmp = FOLDER / "commands.txt.new"
    tmp.write_text("1 SCF\n2 SCS\n3 FROB\n4 SCF\n5 SCF\n6 STOP\n", encoding="utf-8")
    os.replace(tmp, FOLDER / "commands.txt")
    wait_for("the answers after the rename", lambda: len(panel.log_rows()) >= 6, done)


def done():
    panel = state["panel"]
    result["rows"] = panel.log_rows()
    result["editor_final"] = panel.editor.toPlainText()  # the MCS's last parameters.txt
    window_shot("gui-mcs-panel.png")
    panel.stop()
    result["state_stopped"] = panel.state.text()
    # Stopped: a new command waits for the next start.
    with open(FOLDER / "commands.txt", "a", encoding="utf-8") as handle:
        handle.write("7 SCF\n")
    later(after_stop, 700)


def after_stop():
    panel = state["panel"]
    result["rows_after_stop"] = len(panel.log_rows())
    panel.reject()
    result["panel_closed"] = not Gui.Control.activeDialog()
    # One task panel at a time: a scan started while the link watches ends the watching.
    Gui.runCommand("WaferScan_McsLink")
    from waferscan.gui.session import session
    panel = session.task_panel
    second = FOLDER / "second"
    second.mkdir()
    panel.set_folder(str(second))
    result["watching_second"] = panel.start()
    # Store results in the document: the next scan is kept as Run scan keeps it.
    state["panel"] = panel
    if getattr(panel, "store", None) is not None:
        panel.store.setChecked(True)
    (second / "commands.txt").write_text("1 SCF\n", encoding="utf-8")
    wait_for("the stored scan's answer", lambda: len(panel.log_rows()) >= 1,
             lambda: stored(panel, second))


def stored(panel, second):
    from waferscan.gui.session import session

    doc = App.ActiveDocument
    shown = shown_scan(doc)
    sheet = doc.getObject("ScanResults")
    shown["sheet_code"] = sheet.get("code") if sheet is not None else None
    shown["sheet_rows"] = [[str(sheet.getContents(f"{c}{r}")) for c in "ABCDEFG"]
                           for r in (2, 3)] if sheet is not None else None
    result["shown_stored"] = shown
    result["stored_answer"] = (second / "results.txt").read_text(encoding="utf-8")
    code = session.results_windows.get(doc.Name, {}).get("code")
    if code is not None:
        code.grab().save(artifact("gui-mcs-slot-code.png"))
    animation = getattr(panel, "animation", None)
    if animation is None:
        third_folder(panel)
        return
    # The arm on its way up, as the MCS's scan moved it.
    def half_way():
        result["moving"] = {"z": animation.z, "ended": animation.ended,
                            "placements_unmoved": placements(doc) == state["placements"]}
        window_shot("gui-mcs-scan-moving.png")
        third_folder(panel)

    wait_for("the arm half-way", lambda: animation.ended or animation.z > 400.0, half_way)


def third_folder(panel):
    from waferscan.gui.session import session

    # A folder typed into the field: watching stops, that folder's parameters show.
    third = FOLDER / "third"
    third.mkdir()
    panel.folder.setText(str(third))
    panel.folder.editingFinished.emit()
    result["watching_after_folder_edit"] = panel.watching
    result["editor_after_folder_edit"] = panel.editor.toPlainText()
    panel.folder.editingFinished.emit()  # focus lost again, nothing changed: nothing happens
    result["watching_before_scan"] = panel.start()
    Gui.runCommand("WaferScan_RunScan")
    result["watching_after_scan"] = panel.watching
    session.task_panel.reject()
    finish()


start(begin)
