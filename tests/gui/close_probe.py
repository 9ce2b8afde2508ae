# Run by FreeCAD's GUI (tests/gui/test_gui_close.py): the scenario WAFERSCAN_GUI_SCENARIO built
# and scanned with Run scan, and its document closed while the animation plays, each way a user
# closes one: the tab's close button, Ctrl+W, File → Close (each answered Discard), and
# App.closeDocument; then, with a scan playing again, FreeCAD itself is closed (Discard). What
# each close left is written to the result before FreeCAD goes.
import json
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, later, result, start, wait_for, window_shot  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

WAYS = ["tab", "ctrl_w", "file_close", "api"]
SHOT = os.environ.get("WAFERSCAN_GUI_SHOT", "")
state = {}
result["closes"] = {}


def click_discard():
    """Answer FreeCAD's "save the document?" question with Discard, once it is asked."""
    box = QtGui.QApplication.activeModalWidget()
    if box is None:
        QtCore.QTimer.singleShot(50, click_discard)
        return
    for button in box.findChildren(QtGui.QAbstractButton):
        text = button.text().replace("&", "").lower()
        if "discard" in text or "don't save" in text:
            button.click()
            return


def scan():
    from waferscan.gui.playback import run_scan
    from waferscan.gui.scanning import open_scenario
    from waferscan.gui.session import session

    Gui.activateWorkbench("WaferScanWorkbench")
    doc = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    animation = run_scan(doc, duration_s=60.0)
    state.update(doc=doc.Name, animation=animation, panel=session.task_panel)


def close_next():
    if not WAYS:
        later(close_freecad)
        return
    way = WAYS.pop(0)
    state["way"] = way
    scan()
    later(lambda: close(way), 1500)


def close(way):
    animation = state["animation"]
    state["running"] = animation.running and not animation.ended
    if way == "tab" and SHOT:
        window_shot(SHOT)
    name = state["doc"]
    if way == "api":
        App.closeDocument(name)
    else:
        QtCore.QTimer.singleShot(100, click_discard)
        if way == "tab":  # the close button of the document's tab closes its window
            area = Gui.getMainWindow().findChild(QtGui.QMdiArea)
            area.activeSubWindow().close()
        elif way == "ctrl_w":  # the action Ctrl+W is bound to (a key event sent by a
            # script does not reach Qt's shortcuts)
            ctrl_w = QtGui.QKeySequence("Ctrl+W")
            action = next(a for a in Gui.getMainWindow().findChildren(QtGui.QAction)
                          if a.shortcut() == ctrl_w and a.isEnabled())
            action.trigger()
        else:
            menu = next(a.menu() for a in Gui.getMainWindow().menuBar().actions()
                        if a.text().replace("&", "") == "File")
            action = next(a for a in menu.actions() if a.text().replace("&", "") == "Close")
            action.trigger()
    wait_for(f"{name} closed by {way}", lambda: name not in App.listDocuments(),
             lambda: later(lambda: closed(way), 300), timeout_s=30)


def closed(way):
    from waferscan.gui.session import session

    animation = state["animation"]
    if way == "tab" and SHOT:
        window_shot(SHOT.replace(".png", "-closed.png"))
    result["closes"][way] = {
        "was_running": state["running"],
        "ended": animation.ended, "closed": animation.closed,
        "timer_active": animation.timer.isActive(),
        "panel_open": state["panel"].is_open(),
        "task_dialog": bool(Gui.Control.activeDialog()),
        "same_panel": session.task_panel is state["panel"],
    }
    later(close_next)


def close_freecad():
    """A scan playing again and FreeCAD closed: the result is written first (FreeCAD quits)."""
    scan()

    def close_window():
        result["quit_running"] = state["animation"].running
        result["ok"] = True
        with open(os.environ["WAFERSCAN_GUI_RESULT"], "w", encoding="utf-8") as handle:
            json.dump(result, handle, default=str)
        QtCore.QTimer.singleShot(100, click_discard)
        Gui.getMainWindow().close()

    later(close_window, 1500)


start(close_next)
