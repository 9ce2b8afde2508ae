"""Shared by the GUI probes (scripts that FreeCAD's GUI runs): the JSON result, steps chained
through the event loop, and waiting for a condition without blocking the GUI. FreeCAD swallows a
script's exception, so every failure is caught and written into the result."""

import json
import os
import time
import traceback

from PySide import QtCore, QtGui

ARTIFACTS = os.environ.get("WAFERSCAN_GUI_ARTIFACTS", "")
result = {"ok": False}


def finish(error=None):
    """Write the result (ok unless ``error``) and quit FreeCAD."""
    if error is None:
        result["ok"] = True
    else:
        result["ok"] = False
        result["error"] = error
    with open(os.environ["WAFERSCAN_GUI_RESULT"], "w", encoding="utf-8") as handle:
        json.dump(result, handle, default=str)
    QtGui.QApplication.quit()


def guarded(step):
    """``step`` run so that an exception ends the probe with its traceback."""

    def run(*args):
        try:
            step(*args)
        except Exception:
            finish(traceback.format_exc())

    return run


def later(step, ms=0):
    QtCore.QTimer.singleShot(ms, guarded(step))


def wait_for(what, condition, then, timeout_s=90):
    """Call ``then`` once ``condition()`` holds, checking every 50 ms while the GUI runs."""
    deadline = time.monotonic() + timeout_s

    def check():
        if condition():
            then()
        elif time.monotonic() > deadline:
            finish(f"timed out after {timeout_s} s waiting for {what}")
        else:
            QtCore.QTimer.singleShot(50, guarded(check))

    later(check, 50)


def artifact(name):
    os.makedirs(ARTIFACTS, exist_ok=True)
    return os.path.join(ARTIFACTS, name)


def start(first_step, ms=800):
    """Run ``first_step`` once the main window is up and the event loop runs."""
    later(first_step, ms)


def task_dock():
    """The dock that holds FreeCAD's task view, as a list of none or one: the Combo View in
    0.20.2, its own "Tasks" dock in 1.0's default layout (docs/freecad-1.0.md)."""
    import FreeCADGui as Gui

    window = Gui.getMainWindow()
    for widget in window.findChildren(QtGui.QWidget):
        if widget.metaObject().className() != "Gui::TaskView::TaskView" or not widget.isVisible():
            continue
        while widget is not None and not isinstance(widget, QtGui.QDockWidget):
            widget = widget.parentWidget()
        if widget is not None:
            return [widget]
    return [d for d in window.findChildren(QtGui.QDockWidget) if d.objectName() == "Combo View"]


def window_shot(name, dock_width=400):
    """A screenshot of the main window as a user sees it. Under Xvfb, grabbing the window
    leaves the OpenGL 3D view blank, so the view is rendered on its own and drawn in its place.
    The combo view is widened to ``dock_width`` first, as a user would."""
    import FreeCADGui as Gui

    window = Gui.getMainWindow()
    combo = task_dock()
    if combo:
        window.resizeDocks(combo, [dock_width], QtCore.Qt.Horizontal)
    Gui.updateGui()
    shot = window.grab()
    views = [w for w in window.findChildren(QtGui.QWidget)
             if w.metaObject().className() == "SIM::Coin3D::Quarter::QuarterWidget"
             and w.isVisible()]
    if views and Gui.ActiveDocument is not None:
        view = views[0]
        rendered = artifact(f".{name}.view.png")
        Gui.ActiveDocument.ActiveView.saveImage(rendered, view.width(), view.height(), "Current")
        painter = QtGui.QPainter(shot)
        painter.drawImage(view.mapTo(window, QtCore.QPoint(0, 0)), QtGui.QImage(rendered))
        painter.end()
        os.remove(rendered)
    result.setdefault("view_found", bool(views))
    shot.save(artifact(name))


# --- steps several probes take as a user would ---------------------------------------------

def task_panel():
    """The workbench's task panel shown last."""
    from waferscan.gui.session import session

    return session.task_panel


def message_texts():
    """The texts of the (non-blocking) message boxes shown since the last call; they are
    closed."""
    from waferscan.gui.qt import alive
    from waferscan.gui.session import session

    shown = [m for m in session.message_boxes if alive(m) and m.isVisible()]
    texts = [box.text() for box in shown]
    for box in shown:
        box.close()
    return texts


def open_preferences(then):
    """Open the preferences with the workbench's command and show the WaferScan page; ``then
    (dialog)`` runs in it. Returns once the dialog is closed (it is modal)."""
    import FreeCADGui as Gui

    def on_dialog():
        dialog = QtGui.QApplication.activeModalWidget()
        if dialog is None:
            QtCore.QTimer.singleShot(50, guarded(on_dialog))
            return
        for tree in dialog.findChildren(QtGui.QListWidget):
            for i in range(tree.count()):
                if tree.item(i).text() == "WaferScan":
                    tree.setCurrentRow(i)
        QtGui.QApplication.processEvents()
        then(dialog)

    QtCore.QTimer.singleShot(100, guarded(on_dialog))
    Gui.runCommand("WaferScan_Preferences")  # modal: returns once the dialog is closed


def accept_preferences(on_page):
    """``open_preferences``, ``on_page(dialog)`` on the WaferScan page (to read or type its
    fields), then OK clicked."""

    def then(dialog):
        on_page(dialog)
        ok = [b for b in dialog.findChildren(QtGui.QPushButton)
              if b.text().replace("&", "") == "OK"]
        ok[0].click()

    open_preferences(then)


def answer_next_question(button_text, log):
    """Click ``button_text`` in the next modal question box, as a user would (another button
    missing: the box is rejected); its text goes into ``log``."""

    def answer():
        box = QtGui.QApplication.activeModalWidget()
        if not isinstance(box, QtGui.QMessageBox):
            QtCore.QTimer.singleShot(50, answer)
            return
        log.append(box.text())
        for button in box.buttons():
            if button.text() == button_text:
                button.click()
                return
        box.reject()

    QtCore.QTimer.singleShot(50, answer)


def scan_paper_layout():
    """The paper's layout built and scanned with the workbench's commands; returns the scan's
    task panel (its animation playing)."""
    import FreeCADGui as Gui

    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    Gui.updateGui()
    Gui.runCommand("WaferScan_RunScan")
    return task_panel()


def scan_scenario(steps_per_frame):
    """The scenario file named by WAFERSCAN_GUI_SCENARIO built into a document and scanned as
    Run scan does, ``steps_per_frame`` scan positions a frame; returns the animation (playing)."""
    import FreeCADGui as Gui

    from waferscan.gui.playback import run_scan
    from waferscan.gui.scanning import open_scenario

    Gui.activateWorkbench("WaferScanWorkbench")
    doc = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    return run_scan(doc, steps_per_frame=steps_per_frame)


def open_section(section):
    """Click a scan panel section's header open; returns whether its body shows."""
    import FreeCADGui as Gui

    section.toggle.click()
    Gui.updateGui()
    return section.body.isVisible()


def console_calls():
    """The lines of the Python console that call waferscan.gui.commands (the recorded actions),
    without the prompt."""
    import FreeCADGui as Gui

    consoles = [w for w in Gui.getMainWindow().findChildren(QtGui.QPlainTextEdit)
                if w.objectName() == "Python console"]
    return [line.strip().lstrip(">").strip() for line in consoles[0].toPlainText().splitlines()
            if "waferscan.gui.commands." in line] if consoles else None


def replay(what, then, until_ended=True):
    """Click the scan panel's Replay; ``then`` once the new panel is there (and, with
    ``until_ended``, its animation has ended)."""
    old = task_panel()
    old.replay_button.click()
    wait_for(what, lambda: task_panel() is not old and
             (not until_ended or task_panel().animation.ended), then)


def scan_settings():
    """The active document's ScanSettings object (the one with the recipe's properties)."""
    import FreeCAD as App

    return next(o for o in App.ActiveDocument.Objects if "ThicknessMin" in o.PropertiesList)
