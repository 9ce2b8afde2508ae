# Run by FreeCAD's GUI (tests/gui/test_gui_back_faces.py): play Run scan's animation on the
# layout in WAFERSCAN_GUI_LAYOUT with three shapes added beside it that must keep both sides
# drawn (an open shell, a see-through box, a solid turned inside out); pause mid-scan and
# report which objects' shape hints cull back faces, and the 3D view's pixels with the back
# faces culled, drawn again, and with a wafer hidden (so that the comparison can tell).
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import artifact, finish, result, start, wait_for  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

state = {}


def hints_of(obj):
    """[(vertex ordering, shape type)] of every shape-hints node in ``obj``'s view."""
    from pivy import coin

    search = coin.SoSearchAction()
    search.setType(coin.SoShapeHints.getClassTypeId())
    search.setInterest(coin.SoSearchAction.ALL)
    search.setSearchingAll(True)
    search.apply(obj.ViewObject.RootNode)
    paths = search.getPaths()
    return [(paths[i].getTail().vertexOrdering.getValue(),
             paths[i].getTail().shapeType.getValue()) for i in range(paths.getLength())]


def culled(doc):
    from pivy import coin

    solid = (coin.SoShapeHints.COUNTERCLOCKWISE, coin.SoShapeHints.SOLID)
    return sorted(o.Name for o in doc.Objects if getattr(o, "ViewObject", None) is not None
                  and hints_of(o) and all(h == solid for h in hints_of(o)))


def screen(view, name):
    """The 3D view's pixels as the screen shows them (drawn and composed), saved as ``name``:
    grabbed until two grabs in a row are the same picture, so that a view still settling (a
    camera moved by ViewSelection, a frame not yet composed on a loaded machine, where one such
    grab once differed from the next in 12 pixels) is not compared."""
    import time

    viewport = view.graphicsView().viewport()
    corner = viewport.mapToGlobal(QtCore.QPoint(0, 0))

    def grab():
        for _ in range(3):
            view.redraw()
            Gui.updateGui()
        image = QtGui.QApplication.primaryScreen().grabWindow(
            0, corner.x(), corner.y(), viewport.width(), viewport.height()).toImage()
        return image.convertToFormat(QtGui.QImage.Format_RGB32)

    image = grab()
    for _ in range(20):
        time.sleep(0.05)
        again = grab()
        if differing_pixels(image, again) == 0:
            break
        image = again
    else:
        raise RuntimeError(f"{name}: the 3D view did not settle in 20 grabs")
    image.save(artifact(name))
    return image


def _pixels(image):
    import numpy as np

    bits = image.constBits()
    data = np.frombuffer(bytes(bits), dtype=np.uint32)
    return data.reshape(image.height(), image.bytesPerLine() // 4)[:, :image.width()]


def differing_pixels(a, b):
    import numpy as np

    return int(np.count_nonzero(_pixels(a) != _pixels(b)))


def differing_box(a, b):
    """[left, top, right, bottom] of the pixels that differ (None: none do)."""
    import numpy as np

    rows, columns = np.nonzero(_pixels(a) != _pixels(b))
    if not len(rows):
        return None
    return [int(columns.min()), int(rows.min()), int(columns.max()), int(rows.max())]


def begin():
    import Part

    from waferscan.cad.document_scan import scan_document
    from waferscan.gui.playback import play_scan

    # The pictures compared must not depend on where the pointer rests: with it over the 3D view,
    # FreeCAD highlights what lies under it once the camera moves there (when, depends on the
    # machine's load), so it goes to the screen's corner and preselection is off.
    QtGui.QCursor.setPos(0, 0)
    App.ParamGet("User parameter:BaseApp/Preferences/View").SetBool("EnablePreselection", False)
    doc = App.openDocument(os.environ["WAFERSCAN_GUI_LAYOUT"])
    far = App.Vector(-2000, 0, 0)
    box = Part.makeBox(100, 100, 100, far)
    shell = Part.Shell(box.Faces[:5])  # a box without its lid
    Part.show(shell, "OpenShell")
    Part.show(box.reversed(), "InsideOut")
    clear = doc.addObject("Part::Box", "SeeThrough")
    clear.Placement.Base = far + App.Vector(0, 300, 0)
    # A user's PartDesign Body (a shape and a container) whose feature they made see-through:
    # the Body's view holds the feature's, which must keep both sides.
    body = doc.addObject("PartDesign::Body", "Body")
    feature = doc.addObject("PartDesign::AdditiveBox", "PDBox")
    body.addObject(feature)
    body.Placement.Base = far + App.Vector(0, -300, 0)
    doc.recompute()
    clear.ViewObject.Transparency = 50
    feature.ViewObject.Transparency = 60
    state["doc"] = doc
    state["before"] = {o.Name: hints_of(o) for o in doc.Objects if o.ViewObject is not None}
    result["culled_before"] = culled(doc)
    animation = play_scan(doc, scan_document(doc, "analytic"), steps_per_frame=10,
                                   show_results=False, panel=True)
    state["animation"] = animation
    view = Gui.getDocument(doc.Name).ActiveView
    view.viewIsometric()
    view.fitAll()
    state["view"] = view
    wait_for("frames mid-scan", lambda: animation.k > 1500, paused)


def paused():
    animation, doc, view = state["animation"], state["doc"], state["view"]
    animation.pause()
    result["culled_during"] = culled(doc)
    result["wafers"] = sorted(animation.appearance.wafers)
    result["see_through"] = sorted(view.Object.Name for view, prop, _ in
                                   animation.appearance.saved_properties if prop == "Transparency")
    from waferscan.gui.scan_appearance import BackFaces, opaque_closed_solids

    with_culling = screen(view, "back-faces-culled.png")
    animation.appearance.back_faces.restore()
    result["culled_restored"] = culled(doc)
    both_sides = screen(view, "both-sides.png")
    # And close up: the carrier and its wafers filling the view, culled as the animation does.
    Gui.Selection.addSelection(doc.getObject("LP1"))
    Gui.SendMsgToActiveView("ViewSelection")
    Gui.Selection.clearSelection()
    again = BackFaces.culled(opaque_closed_solids(doc))
    close_culled = screen(view, "close-up-culled.png")
    again.restore()
    close_both = screen(view, "close-up-both-sides.png")
    result["differ_close_up"] = differing_pixels(close_culled, close_both)
    result["differ_close_up_box"] = differing_box(close_culled, close_both)
    wafer = doc.getObject(result["wafers"][-1])
    wafer.ViewObject.Visibility = False
    one_less = screen(view, "one-wafer-hidden.png")
    wafer.ViewObject.Visibility = True
    result["differ_hidden"] = differing_pixels(one_less, close_both)
    result["pixels"] = with_culling.width() * with_culling.height()
    result["differ_culled"] = differing_pixels(with_culling, both_sides)
    animation.stop()
    Gui.updateGui()
    result["hints_kept"] = {o.Name: hints_of(o) == state["before"][o.Name]
                            for o in doc.Objects if o.Name in state["before"]}
    result["fault"] = animation.fault
    finish()


start(begin)
