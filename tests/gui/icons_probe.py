# Run by FreeCAD's GUI (tests/gui/test_gui_icons.py): a layout built and saved headless, opened in
# the GUI: WaferScan's objects get their roles' view providers and icons; a layout built in the
# GUI has them from the start.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, start, window_shot  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402


def same_image(icon, path):
    """Whether the view object's icon draws something, as the SVG file does, at the tree's
    16 px (the tree may grey it or add overlays: no pixel-exact comparison)."""
    return not icon.isNull() and not QtGui.QIcon(path).pixmap(16, 16).isNull()


def image_bytes(icon):
    """The icon drawn at the tree's 16 px, as bytes to compare."""
    image = icon.pixmap(16, 16).toImage().convertToFormat(QtGui.QImage.Format_ARGB32)
    return bytes(image.constBits()) if hasattr(image, "constBits") else image.bits().tobytes()


def tree_icons(doc, labels):
    """{label: [whether its tree item draws its view object's icon, whether it draws Part's
    cylinder icon]}, pixel for pixel (a Part::Cylinder's icon taken from one made for it)."""
    probe = doc.addObject("Part::Cylinder", "IconProbeCylinder")
    doc.recompute()
    Gui.updateGui()
    cylinder = image_bytes(probe.ViewObject.Icon)
    found = {}
    for tree in Gui.getMainWindow().findChildren(QtGui.QTreeWidget):
        if tree.metaObject().className() != "Gui::TreeWidget":
            continue
        items = tree.findItems("", QtCore.Qt.MatchContains | QtCore.Qt.MatchRecursive, 0)
        for item in items:
            if item.text(0) in labels:
                drawn = image_bytes(item.icon(0))
                own = image_bytes(doc.getObjectsByLabel(item.text(0))[0].ViewObject.Icon)
                found[item.text(0)] = [drawn == own, drawn == cylinder]
    doc.removeObject(probe.Name)
    return found


def views(doc):
    found = {}
    for obj in doc.Objects:
        role = getattr(obj, "WaferScanRole", "")
        if role not in ("Carrier", "Scanner", "ScanSettings", "Wafer"):
            continue
        proxy = getattr(obj.ViewObject, "Proxy", None)  # a C++ view provider has none
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
                                for o in doc.Objects if o.Label in ("LP1 assembly", "Robot", "LP1_W01", "LP1_W02")}
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    result["gui_built"] = views(App.ActiveDocument)
    Gui.updateGui()
    result["tree_icons"] = tree_icons(App.ActiveDocument, ("LP1_W01", "LP1_W04"))
    for tree in Gui.getMainWindow().findChildren(QtGui.QTreeWidget):  # the tree, opened
        tree.expandAll()
    window_shot("gui-role-icons.png")
    finish()


start(begin)
