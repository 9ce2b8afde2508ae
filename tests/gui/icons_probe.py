# Run by FreeCAD's GUI (tests/gui/test_gui_icons.py): a layout built and saved headless, opened in
# the GUI: WaferScan's objects get their roles' view providers and icons; a layout built in the
# GUI has them from the start.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, start, window_shot  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402


def same_image(icon, path):
    """Whether the view object's icon draws something, as the SVG file does, at the tree's
    16 px (the tree may grey it or add overlays: no pixel-exact comparison)."""
    return not icon.isNull() and not QtGui.QIcon(path).pixmap(16, 16).isNull()


def views(doc):
    found = {}
    for obj in doc.Objects:
        role = getattr(obj, "WaferScanRole", "")
        if role not in ("Carrier", "Scanner", "ScanSettings"):
            continue
        proxy = obj.ViewObject.Proxy
        icon = proxy.getIcon() if hasattr(proxy, "getIcon") else ""
        found[role] = [type(proxy).__name__, os.path.basename(icon),
                       bool(icon) and same_image(obj.ViewObject.Icon, icon),
                       obj.ViewObject.Visibility, bool(obj.ViewObject.DisplayMode), obj.Visibility]
    return found


def begin():
    doc = App.openDocument(os.environ["WAFERSCAN_GUI_LAYOUT"])  # before the workbench is used
    Gui.SendMsgToActiveView("ViewFit")
    result["headless_built"] = views(doc)
    result["headless_shown"] = {o.Label: [o.Visibility, o.ViewObject.Visibility]
                                for o in doc.Objects if o.TypeId in ("App::Part", "Part::Cylinder")
                                and o.Label in ("LP1 assembly", "Robot", "LP1_W01", "LP1_W02")}
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    result["gui_built"] = views(App.ActiveDocument)
    for tree in Gui.getMainWindow().findChildren(QtGui.QTreeWidget):  # the tree, opened
        tree.expandAll()
    window_shot("gui-role-icons.png")
    finish()


start(begin)
