"""Run by the FreeCAD GUI (`freecad workbench_probe.py`) for test_gui_workbench.py.

Activates the WaferScan workbench, checks pinocchio, saves a screenshot, writes a JSON result
and quits. FreeCAD swallows a script's exception (the GUI just keeps running), so every failure
is caught and written into the result. Paths come from the environment: arguments after the
script would be opened by FreeCAD as documents.
"""

import json
import os
import traceback

import FreeCADGui as Gui
from PySide import QtCore, QtGui

RESULT = os.environ["WAFERSCAN_GUI_RESULT"]
SCREENSHOT = os.environ["WAFERSCAN_GUI_SCREENSHOT"]


def _drawn(icon):
    """The fraction of an icon's 24 px rendering that is not transparent."""
    image = icon.pixmap(24, 24).toImage()
    pixels = [image.pixelColor(x, y).alpha() for x in range(image.width())
              for y in range(image.height())]
    return sum(1 for a in pixels if a > 0) / max(1, len(pixels))


preferences = {}


def _look_at_preferences():
    dialog = QtGui.QApplication.activeModalWidget()
    if dialog is None:
        return
    # The groups through the views' models: a QListWidget in FreeCAD 0.20, a tree view of
    # groups and their pages in 1.0 (whose icon list's items have no text).
    entries = []

    def walk(view, model, parent):
        for row in range(model.rowCount(parent)):
            index = model.index(row, 0, parent)
            text = model.data(index)
            entries.append((view, index, text if isinstance(text, str) else ""))
            walk(view, model, index)

    for view in dialog.findChildren(QtGui.QAbstractItemView):
        if view.model() is not None:
            walk(view, view.model(), QtCore.QModelIndex())
    preferences["groups"] = [text for _, _, text in entries]
    for view, index, text in entries:
        if text == "WaferScan":
            view.setCurrentIndex(index)
            break
    QtGui.QApplication.processEvents()
    preferences["shot"] = dialog.grab().save(SCREENSHOT.replace(".png", "-preferences.png"))
    dialog.reject()


def probe():
    result = {"ok": False}
    try:
        Gui.activateWorkbench("WaferScanWorkbench")
        Gui.updateGui()
        workbench = Gui.activeWorkbench()
        result["workbench_name"] = workbench.name()
        result["menu_text"] = workbench.MenuText
        result["icon"] = workbench.Icon

        import numpy
        import pinocchio
        result["pinocchio_version"] = pinocchio.__version__
        result["numpy_file"] = numpy.__file__

        # The toolbar and the menu as a user sees them: every action's text, tooltip and icon.
        window = Gui.getMainWindow()
        toolbar = [t for t in window.findChildren(QtGui.QToolBar) if t.windowTitle() == "WaferScan"]
        result["toolbar"] = [(a.text(), a.toolTip(), not a.icon().isNull(),
                              _drawn(a.icon()))
                             for a in toolbar[0].actions()] if toolbar else None
        menus = [m for m in window.menuBar().findChildren(QtGui.QMenu)
                 if m.title().replace("&", "") == "WaferScan"]
        result["menu"] = [a.text() for a in menus[0].actions() if not a.isSeparator()] \
            if menus else None
        from waferscan.gui import commands
        result["pixmaps"] = {name: command.GetResources()["Pixmap"]
                             for name, command in {**commands.COMMANDS,
                                                   **commands.TAG_COMMANDS}.items()}
        # The screenshots' folder first: the preferences' grab is saved into it too.
        os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
        # The preferences page, opened with its command (a modal dialog: looked at, then closed).
        QtCore.QTimer.singleShot(700, _look_at_preferences)
        Gui.runCommand("WaferScan_Preferences")
        result["screenshot_saved"] = window.grab().save(SCREENSHOT)
        result["preferences"] = preferences
        result["ok"] = True
    except Exception:
        result["error"] = traceback.format_exc()
    finally:
        with open(RESULT, "w", encoding="utf-8") as out:
            json.dump(result, out)
        QtGui.QApplication.quit()


# Start once the main window is up and the event loop runs.
QtCore.QTimer.singleShot(1000, probe)
