# Run by FreeCAD's GUI (tests/gui/test_gui_walkthrough.py): the README's own-cell walkthrough as
# a newcomer does it, with FreeCAD's default import settings. "New paper layout" (the demo,
# robot included: it is what a newcomer exports), every shape of it exported as one STEP file
# (File -> Export of the tree's top objects), the demo closed; the file imported with the
# defaults (0.20.2: "merge compound" on, one compound of every solid); then the workbench's
# commands in the order the guide gives them: Tag as wafer (split; the wafer-like discs tagged),
# Make carrier from solids (the carrier's walls and ledges, a shift-click range in the tree),
# Tag as scanner (the beam's rod), Set up carrier and sensor... (Use derived, the beam's ends
# picked in the 3D view), OK, Run scan. No coordinate typed. A screenshot after each step.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    answer_next_question, console_calls, finish, later, message_texts, result, start, wait_for,
    window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

FOLDER = os.environ["WAFERSCAN_GUI_MCS"]
STEP_FILE = os.path.join(FOLDER, "paper-cell.step")
SAVED = os.path.join(FOLDER, "paper-cell.FCStd")
# The paper's beam: emitter (-80, 266.6, 280) along +X, 160 mm; its heads are spheres of 3 mm
# radius, so a click on the top of a head is 3 mm above the beam's end.
EMITTER_CLICK = (-80.0, 266.6, 283.0)
RECEIVER_CLICK = (80.0, 266.6, 283.0)
state = {}


def shot(name):
    Gui.ActiveDocument.ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    window_shot(name, dock_width=264)


def shot_then(name, step):
    """A screenshot once the tree has caught up with the selection (it follows on a timer),
    then ``step``."""

    def take():
        shot(name)
        step()

    later(take, 400)


def import_preferences():
    """FreeCAD's STEP import preferences a user has set (none for a fresh user: FreeCAD's
    defaults hold)."""
    group = App.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
    return {"set": sorted(group.GetBools() + group.GetInts() + group.GetStrings())}


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    demo = App.ActiveDocument
    from waferscan.cad.scene import scene_roots
    # File -> Export with the tree's top objects selected: all that has a shape.
    tops = [o for o in scene_roots(demo) if o.TypeId != "App::FeaturePython"]
    result["exported"] = sorted(o.Label for o in tops)
    carrier = demo.getObjectsByLabel("LP1")[0]
    from waferscan.cad.carrier_geometry import instance_of
    box = instance_of(carrier).shape().BoundBox
    state["carrier_box"] = box
    import ImportGui
    ImportGui.export(tops, STEP_FILE)
    App.closeDocument(demo.Name)
    result["import_preferences"] = import_preferences()
    doc = App.newDocument("PaperCell")
    ImportGui.insert(STEP_FILE, doc.Name)  # File -> Import, FreeCAD's default settings
    import Part
    if not any(o.TypeId == "Part::Feature" and len(o.Shape.Solids) > 1 for o in doc.Objects):
        # FreeCAD 1.0's default import rebuilds the file's App::Part tree of single solids,
        # and gives no compound at all (docs/freecad-1.0.md): the walkthrough's compound is
        # then the file's one shape, as 0.20.2's default gives it.
        result["compound_made_from_file"] = True
        App.closeDocument(doc.Name)
        doc = App.newDocument("PaperCell")
        merged = doc.addObject("Part::Feature", "paper_cell")
        merged.Label = "paper-cell"  # as 0.20.2 names it: after the file
        merged.Shape = Part.read(STEP_FILE)
        doc.recompute()
    state["doc"] = doc
    result["imported"] = [(o.TypeId, len(o.Shape.Solids)) for o in doc.Objects
                          if hasattr(o, "Shape")]
    shot_then("gui-walkthrough-1-imported.png", tag_wafers)


def tag_wafers():
    doc = state["doc"]
    compound = next(o for o in doc.Objects if len(getattr(o, "Shape", None).Solids) > 1)
    # Click the compound in the tree, then Tag as wafer; answer "Split into solids".
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(compound)
    questions = []
    answer_next_question("Split into solids", questions)
    Gui.runCommand("WaferScan_TagWafer")
    result["split_question"] = questions
    result["wafer_message"] = message_texts()
    wafers = [o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "Wafer"]
    result["wafers"] = len(wafers)
    skipped = Gui.Selection.getSelection()
    result["skipped_selected"] = len(skipped)
    state["skipped"] = skipped
    shot_then("gui-walkthrough-2-wafers.png", make_carrier)


def make_carrier():
    doc = state["doc"]
    outer = App.BoundBox(state["carrier_box"])
    outer.enlarge(1e-3)
    solids = [o for o in doc.Objects if o.TypeId == "Part::Feature" and len(o.Shape.Solids) == 1
              and o.Visibility]
    # The carrier's walls and ledges, in the tree one run of solids after the split: a
    # newcomer clicks the first and shift-clicks the last (the 3D view highlights them).
    # The beam's rod and heads lie in the carrier's box too but come later in the tree.
    order = {o.Name: i for i, o in enumerate(solids)}
    untagged = [o for o in solids if not getattr(o, "WaferScanRole", "")]
    walls = [o for o in untagged if outer.isInside(o.Shape.BoundBox)
             and o.Shape.BoundBox.ZLength > 1.0 and o.Shape.BoundBox.YLength > 10.0]
    first, last = order[walls[0].Name], order[walls[-1].Name]
    run = solids[first:last + 1]
    result["carrier_run"] = [len(walls), len(run), all(not getattr(o, "WaferScanRole", "")
                                                       for o in run)]
    Gui.Selection.clearSelection()
    for obj in run:
        Gui.Selection.addSelection(obj)
    Gui.runCommand("WaferScan_MakeCarrier")
    result["carrier_message"] = message_texts()
    carriers = [o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "Carrier"]
    result["carriers"] = [(o.TypeId, len(o.Group)) for o in carriers]
    state["carrier"] = carriers[0]
    shot_then("gui-walkthrough-3-carrier.png", tag_scanner)


def tag_scanner():
    doc = state["doc"]
    # The beam's rod: a click on it in the 3D view (zoomed in), then Tag as scanner.
    rod = next(o for o in doc.Objects if o.TypeId == "Part::Feature" and o.Visibility
               and len(o.Shape.Solids) == 1 and not getattr(o, "WaferScanRole", "")
               and abs(o.Shape.BoundBox.XLength - 160.0) < 1e-6
               and o.Shape.BoundBox.ZLength < 1.0)
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, rod.Name, "Face1", 0.0, 266.6, 280.4)
    Gui.runCommand("WaferScan_TagScanner")
    result["scanner_message"] = message_texts()
    result["scanners"] = [o.Label for o in doc.Objects
                          if getattr(o, "WaferScanRole", "") == "Scanner"]
    Gui.Selection.clearSelection()
    result["undo_before_frames"] = list(doc.UndoNames)
    Gui.runCommand("WaferScan_SetFrames")
    from waferscan.gui.session import session
    panel = session.task_panel
    state["panel"] = panel
    result["derived_text"] = panel.derived.text()
    later(set_up, 300)


def click(doc, obj, element, point):
    """A click on ``element`` of ``obj`` (a top-level object) at ``point`` in the 3D view."""
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, obj.Name, element, *point)


def head_at(doc, point):
    """The imported solid (a beam's head) under ``point``."""
    return next(o for o in doc.Objects if o.TypeId == "Part::Feature" and o.Visibility
                and len(o.Shape.Solids) == 1 and o.Shape.BoundBox.isInside(App.Vector(*point))
                and o.Shape.BoundBox.XLength < 10.0)


def set_up():
    doc, panel = state["doc"], state["panel"]
    panel.use_derived.click()
    result["derived_fields"] = [panel.slot_count.value(), panel.pitch.text(),
                                [f.text() for f in panel.points["seat"].fields]]
    for key, point in (("emitter", EMITTER_CLICK), ("receiver", RECEIVER_CLICK)):
        panel.points[key].pick.click()
        click(doc, head_at(doc, point), "Face1", point)
        result[f"{key}_picked"] = [f.text() for f in panel.points[key].fields]
    shot("gui-walkthrough-4-set-up.png")
    ok = [b for b in Gui.getMainWindow().findChildren(QtGui.QPushButton)
          if b.text().replace("&", "") == "OK" and b.isVisible()]
    ok[0].click()
    later(run_scan, 300)


def run_scan():
    from waferscan.gui.session import session
    doc = state["doc"]
    result["messages_after_ok"] = message_texts()
    result["undo_after_frames"] = list(doc.UndoNames)
    Gui.runCommand("WaferScan_RunScan")
    scan = session.task_panel
    scan.speed.setValue(scan.speed.minimum())
    state["scan"] = scan
    wait_for("the paper cell's scan", lambda: scan.animation.ended, scanned)


def scanned():
    from waferscan.gui.session import last_result
    doc = state["doc"]
    result["gui_code"] = last_result(doc).code
    result["scan_messages"] = message_texts()
    shot("gui-walkthrough-5-scanned.png")
    result["console_calls"] = console_calls()
    doc.saveAs(SAVED)
    Gui.Control.closeDialog()
    finish()


start(begin)
