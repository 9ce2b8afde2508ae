# Run by FreeCAD's GUI (tests/gui/test_gui_layout.py): open the layout in WAFERSCAN_GUI_LAYOUT,
# report which objects the 3D view shows, render the view to WAFERSCAN_GUI_SCREENSHOT, quit.
import json
import os
import traceback

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui


def probe():
    result = {"ok": False}
    try:
        report = Gui.getMainWindow().findChild(QtGui.QTextEdit, "Report view")
        before = report.toPlainText() if report is not None else ""
        doc = App.openDocument(os.environ["WAFERSCAN_GUI_LAYOUT"])
        Gui.updateGui()
        # What opening the file wrote to the report view (an error there pops the view up)
        result["report"] = (report.toPlainText()[len(before):] if report is not None
                            else None)
        result["shown"] = {o.Label: bool(o.ViewObject.Visibility) for o in doc.Objects
                           if o.ViewObject is not None and o.TypeId not in
                           ("App::Origin", "App::Line", "App::Plane")}
        # The Parts' origins (axes, planes): the GUI hides them in a Part it makes.
        result["origins_shown"] = {o.Name: bool(o.ViewObject.Visibility) for o in doc.Objects
                                   if o.ViewObject is not None and o.TypeId in
                                   ("App::Origin", "App::Line", "App::Plane")}
        view = Gui.getDocument(doc.Name).ActiveView
        view.viewIsometric()
        view.fitAll()
        Gui.updateGui()
        view.saveImage(os.environ["WAFERSCAN_GUI_SCREENSHOT"], 1200, 800, "White")
        image = QtGui.QImage(os.environ["WAFERSCAN_GUI_SCREENSHOT"])
        samples = [image.pixel(x, y) & 0xFFFFFF for x in range(0, image.width(), 4)
                   for y in range(0, image.height(), 4)]
        result["drawn_fraction"] = sum(1 for p in samples if p != 0xFFFFFF) / len(samples)
        result["ok"] = True
    except Exception:
        result["error"] = traceback.format_exc()
    finally:
        with open(os.environ["WAFERSCAN_GUI_RESULT"], "w", encoding="utf-8") as handle:
            json.dump(result, handle)
        QtGui.QApplication.quit()


QtCore.QTimer.singleShot(1000, probe)
