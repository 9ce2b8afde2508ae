# Run by FreeCAD's GUI (tests/gui/test_gui_bowed.py): a layout with bowed wafers, built headless,
# opened in the GUI: what the 3D view draws for each wafer (the bounding box of its view
# provider's scene graph, in the wafer's carrier frame), and a front view rendered to a file.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, start  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def drawn_box(obj):
    """(zmin, zmax, xmin, xmax) of what Coin draws for the object, in its parent's frame."""
    from pivy import coin

    action = coin.SoGetBoundingBoxAction(coin.SbViewportRegion())
    action.apply(obj.ViewObject.RootNode)
    box = action.getBoundingBox()
    low, high = box.getMin().getValue(), box.getMax().getValue()
    return [low[2], high[2], low[0], high[0]]


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    doc = App.openDocument(os.environ["WAFERSCAN_GUI_LAYOUT"])
    Gui.updateGui()
    wafers = [o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "Wafer"]
    result["wafers"] = {
        o.Label: {"type": o.TypeId, "bow": float(o.Bow) if "Bow" in o.PropertiesList else 0.0,
                  "z": float(o.Placement.Base.z), "shown": bool(o.ViewObject.Visibility),
                  "drawn": drawn_box(o),
                  "icon": type(o.ViewObject.Proxy).__name__ if o.ViewObject.Proxy else None}
        for o in wafers}
    result["origins_shown"] = [o.Name for o in doc.Objects if o.TypeId in
                               ("App::Origin", "App::Line", "App::Plane")
                               and o.ViewObject.Visibility]
    for name in result["origins_shown"]:  # for the picture: the carrier part's axes hidden
        doc.getObject(name).ViewObject.Visibility = False
    view = Gui.getDocument(doc.Name).ActiveView
    view.viewFront()  # through the carrier's opening (-Y), the wafers edge-on: the bows show
    view.fitAll()
    Gui.updateGui()
    view.saveImage(os.environ["WAFERSCAN_GUI_SCREENSHOT"], 1200, 800, "White")
    finish()


start(begin)
