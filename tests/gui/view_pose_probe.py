# Run by FreeCAD's GUI (tests/gui/test_gui_view_pose.py): play Run scan's animation on the layout
# in WAFERSCAN_GUI_LAYOUT, pause it mid-scan, and report where the 3D view draws each moved
# object (its view's transform node), where the document places it, and where the document
# would place it (the mover, through the document, as before); then stop and report again.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, start, wait_for  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore  # noqa: E402

state = {}


def drawn(obj):
    """(x, y, z, qx, qy, qz, qw) of the transform node the 3D view draws ``obj`` with."""
    node = obj.ViewObject.RootNode.getChild(0)
    return list(node.translation.getValue()) + list(node.rotation.getValue().getValue())


def placed(placement):
    base = placement.Base
    return [base.x, base.y, base.z] + list(placement.Rotation.Q)


def touched(doc):
    return sorted(o.Name for o in doc.Objects if "Touched" in o.State)


def begin():
    from waferscan.cad.document_scan import scan_document
    from waferscan.gui.playback import play_scan

    doc = App.openDocument(os.environ["WAFERSCAN_GUI_LAYOUT"])
    doc.recompute()
    state["doc"] = doc
    result["touched_before"] = touched(doc)
    animation = play_scan(doc, scan_document(doc, "analytic"), steps_per_frame=10,
                                   show_results=False, panel=True)
    state["animation"] = animation
    result["view_pose"] = animation.pose is not None
    result["timer_precise"] = animation.timer.timerType() == QtCore.Qt.PreciseTimer
    moved = [obj for obj, _ in animation.mover.placements_at(animation.scan.start_z)]
    state["moved"] = moved
    result["moved"] = [o.Name for o in moved]
    result["document_start"] = {o.Name: placed(o.Placement) for o in moved}
    result["drawn_start"] = {o.Name: drawn(o) for o in moved}
    wait_for("frames mid-scan", lambda: animation.k > 1000, paused)


def paused():
    animation, doc = state["animation"], state["doc"]
    animation.pause()
    Gui.updateGui()
    moved = state["moved"]
    result["z"], result["start_z"] = animation.z, animation.scan.start_z
    result["touched_during"] = touched(doc)
    result["document_during"] = {o.Name: placed(o.Placement) for o in moved}
    result["drawn_during"] = {o.Name: drawn(o) for o in moved}
    # Where the document path (the mover, as the animation moved things before) puts them.
    animation.mover.move_to(animation.z)
    result["document_path"] = {o.Name: placed(o.Placement) for o in moved}
    animation.mover.restore()
    animation.stop()
    Gui.updateGui()
    result["drawn_after"] = {o.Name: drawn(o) for o in moved}
    result["document_after"] = {o.Name: placed(o.Placement) for o in moved}
    result["fault"] = animation.fault
    finish()


start(begin)
