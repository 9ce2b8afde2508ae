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
