# Run by FreeCAD's GUI (tests/gui/test_gui_icons.py): a layout built and saved headless, opened in
# the GUI: WaferScan's objects get their roles' view providers and icons; a layout built in the
# GUI has them from the start.
import os
import sys
import time

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import artifact, finish, result, start, window_shot  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402


def same_image(icon, path):
    """Whether the view object's icon draws something, as the SVG file does, at the tree's
    16 px (the tree may grey it or add overlays: no pixel-exact comparison)."""
    return not icon.isNull() and not QtGui.QIcon(path).pixmap(16, 16).isNull()


def image_of(icon):
    """The icon drawn at the tree's 16 px, as 32-bit ARGB. FreeCAD 1.0's tree draws an item's
    status (its visibility's eye) left of its own icon, in one wider icon: the object's icon is
    then its rightmost 16 px square."""
    size = icon.actualSize(QtCore.QSize(256, 16))
    pixmap = icon.pixmap(size)
    if pixmap.width() > pixmap.height():
        pixmap = pixmap.copy(pixmap.width() - pixmap.height(), 0, pixmap.height(),
                             pixmap.height())
    return pixmap.scaled(16, 16).toImage().convertToFormat(QtGui.QImage.Format_ARGB32)


def difference(a, b):
    """The mean difference of two 16 px icons' colour channels, alpha-weighted, 0 to 255."""
    total = 0.0
    for y in range(16):
        for x in range(16):
            pa, pb = QtGui.QColor.fromRgba(a.pixel(x, y)), QtGui.QColor.fromRgba(b.pixel(x, y))
            total += sum(abs(ca * pa.alphaF() - cb * pb.alphaF()) for ca, cb in
                         ((pa.red(), pb.red()), (pa.green(), pb.green()), (pa.blue(), pb.blue())))
            total += abs(pa.alpha() - pb.alpha())
    return total / (16 * 16 * 4)


def tree_items(doc):
    """{label: the tree's item} of the document's objects."""
    found = {}
    for tree in Gui.getMainWindow().findChildren(QtGui.QTreeWidget):
        if tree.metaObject().className() != "Gui::TreeWidget":
            continue
        for item in tree.findItems("", QtCore.Qt.MatchContains | QtCore.Qt.MatchRecursive, 0):
            found[item.text(0)] = item
    return found


def tree_icons(doc, labels):
    """{label: [how far its tree item's icon is from the wafer's SVG, how far from the icon
    of a Part::Cylinder's tree item]} (mean channel difference, 0 to 255), the icons saved
    beside the screenshots to look at."""
    from waferscan.addon import icon_path
    wafer = image_of(QtGui.QIcon(icon_path("WaferScan_Wafer.svg")))
    probe = doc.addObject("Part::Cylinder", "IconProbeCylinder")
    probe.Label = "IconProbeCylinder"
    doc.recompute()
    deadline = time.monotonic() + 5.0  # the tree adds its items on a timer
    while "IconProbeCylinder" not in tree_items(doc) and time.monotonic() < deadline:
        QtGui.QApplication.processEvents()
        time.sleep(0.02)
    items = tree_items(doc)
    cylinder = image_of(items["IconProbeCylinder"].icon(0))
    cylinder.save(artifact("gui-icon-tree-cylinder.png"))
    found = {}
    for label in labels:
        drawn = image_of(items[label].icon(0))
        drawn.save(artifact(f"gui-icon-tree-{label}.png"))
        found[label] = [round(difference(drawn, wafer), 1), round(difference(drawn, cylinder), 1)]
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
