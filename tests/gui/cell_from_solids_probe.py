# Run by FreeCAD's GUI (tests/gui/test_gui_cell_from_solids.py): issue 27's engineer's cell, a
# STEP file imported as one compound of 19 solids (ten 0.7 mm wafers, a carrier's three walls,
# the robot's column, a collar, a housing, two 0.8 x 160 mm rods, the sensor). Tag as wafer
# splits it and tags only the wafers; Untag; a carrier made of the loose walls; its wafer size
# taken from the wafers; the scan range follows the carrier until the user sets it.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    answer_next_question, artifact, console_calls, finish, later, message_texts, result, start,
    wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

state = {}
CENTRE = (170.0, 180.0)  # the wafers' centre; slot 1's seat at Z 10, pitch 10
WAFER_SLOTS = range(1, 11)


def compound_shape():
    import Part
    V = App.Vector
    solids = [Part.makeCylinder(150, 0.7, V(*CENTRE, 10.0 * slot)) for slot in WAFER_SLOTS]
    solids += [Part.makeBox(10, 360, 270, V(0, 0, 0)), Part.makeBox(10, 360, 270, V(330, 0, 0)),
               Part.makeBox(340, 360, 5, V(0, 0, -5))]  # the carrier: two walls and a base
    solids += [Part.makeCylinder(60, 300, V(700, 0, 0)),  # the robot's column
               Part.makeCylinder(80, 20, V(700, 0, 300)),  # a collar
               Part.makeCylinder(100, 50, V(700, 0, 320)),  # a housing
               Part.makeCylinder(0.4, 160, V(90, 40, 152), V(1, 0, 0)),  # two rods
               Part.makeCylinder(0.4, 160, V(90, 53, 152), V(1, 0, 0))]
    solids.append(Part.makeBox(160, 4, 4, V(90, 44.6, 300)))  # the sensor, far above
    return Part.makeCompound(solids)


def role(obj):
    return getattr(obj, "WaferScanRole", None)


def tree_texts():
    """{label: description} of the objects in the tree (its two columns)."""
    found = {}
    for tree in Gui.getMainWindow().findChildren(QtGui.QTreeWidget):
        items = QtGui.QTreeWidgetItemIterator(tree)
        while items.value():
            item = items.value()
            if tree.columnCount() > 1:
                found[item.text(0)] = item.text(1)
            items += 1
    return found


def tree_columns():
    trees = Gui.getMainWindow().findChildren(QtGui.QTreeWidget)
    return [[t.headerItem().text(i) for i in range(t.columnCount()) if not t.isColumnHidden(i)]
            for t in trees]


def run(command):
    """Gui.runCommand, a command missing noted (so that each test says what it lacks)."""
    try:
        Gui.runCommand(command)
    except Exception as exc:  # noqa: BLE001 (FreeCAD's error for an unknown command)
        result.setdefault("missing_commands", []).append(f"{command}: {exc}")


def select(objects):
    Gui.Selection.clearSelection()
    for obj in objects:
        Gui.Selection.addSelection(obj)


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    doc = App.newDocument("ToolCell")
    tool = doc.addObject("Part::Feature", "Tool")
    tool.Shape = compound_shape()
    doc.recompute()
    Gui.SendMsgToActiveView("ViewFit")
    state["doc"] = doc
    questions = []
    answer_next_question("Split into solids", questions)
    select([tool])
    Gui.runCommand("WaferScan_TagWafer")
    solids = [o for o in doc.Objects if o is not tool]
    by_z = {round(o.Shape.BoundBox.ZMin, 3): o for o in solids
            if o.Shape.BoundBox.XMin < 400 and o.Shape.BoundBox.ZLength < 1}
    state["wafers"] = [by_z[10.0 * slot] for slot in WAFER_SLOTS]
    state["solids"] = solids
    wafers = [o for o in solids if role(o) == "Wafer"]
    result["split"] = {"solids": len(solids), "tagged": len(wafers),
                       "tagged_are_the_wafers": sorted(o.Name for o in wafers) ==
                       sorted(o.Name for o in state["wafers"]),
                       "undo": list(doc.UndoNames)}
    from waferscan.gui.session import session
    boxes = [b for b in session.message_boxes if b.isVisible()]
    if boxes:  # the message the user reads, as a picture
        boxes[-1].grab().save(artifact("gui-split-skipped.png"))
    result["split_message"] = " ".join(message_texts())
    result["selected_after"] = sorted(o.Label for o in Gui.Selection.getSelection())
    later(split_tree, 300)


def split_tree():
    doc = state["doc"]
    texts = tree_texts()
    result["tree_columns"] = tree_columns()
    result["tree_wafer"] = texts.get(state["wafers"][0].Label)
    result["tree_rod"] = texts.get("Tool solid 17")
    result["label2"] = [state["wafers"][0].Label2, state["solids"][16].Label2]
    window_shot("gui-split-tagged.png", dock_width=420)
    # The tagging is its own undo step: undone, the split solids stay.
    doc.undo()
    result["after_one_undo"] = [len(doc.Objects),
                                sum(role(o) == "Wafer" for o in doc.Objects),
                                state["wafers"][0].Label2]
    doc.redo()
    result["after_redo"] = sum(role(o) == "Wafer" for o in doc.Objects)
    untag()


def untag():
    import Part
    doc = state["doc"]
    wafer = state["wafers"][0]
    plain = doc.addObject("Part::Feature", "Plain")  # what an untagged solid carries
    plain.Shape = Part.makeBox(1, 1, 1)
    state["plain_properties"] = sorted(plain.PropertiesList)
    doc.removeObject("Plain")
    select([wafer])
    run("WaferScan_Untag")
    result["untagged"] = {"role": role(wafer), "label2": wafer.Label2,
                          "properties_as_untagged": sorted(wafer.PropertiesList) ==
                          state["plain_properties"],
                          "undo": list(doc.UndoNames)[:2]}
    doc.undo()
    result["untag_undone"] = [role(wafer), wafer.Label2]
    doc.redo()
    result["untag_redone"] = [role(wafer), wafer.Label2]
    # Tagged again on its own; the collar tagged on its own: tagged, with a word.
    collar = state["solids"][14]
    select([wafer, collar])
    Gui.runCommand("WaferScan_TagWafer")
    result["explicit_collar"] = [role(wafer), role(collar), " ".join(message_texts())]
    select([collar])
    run("WaferScan_Untag")
    result["collar_after_untag"] = [role(collar), collar.Label2]
    # Untag on a solid without a role: a message, no traceback.
    select([collar])
    run("WaferScan_Untag")
    result["untag_nothing"] = message_texts()
    make_carrier()


def make_carrier():
    doc = state["doc"]
    walls = state["solids"][10:13]
    select(walls)
    run("WaferScan_MakeCarrier")
    carriers = [o for o in doc.Objects if role(o) == "Carrier"]
    result["carrier"] = {
        "count": len(carriers),
        "type": carriers[0].TypeId if carriers else None,
        "walls_inside": sorted(o.Name for o in carriers[0].Group) == sorted(w.Name for w in walls)
        if carriers else None,
        "size": [carriers[0].WaferDiameter.Value, carriers[0].WaferThickness.Value]
        if carriers else None,
        "label2": carriers[0].Label2 if carriers else None,
        "undo": list(doc.UndoNames)[:2],
        "message": " ".join(message_texts())}
    if carriers:
        carrier = carriers[0]
        doc.undo()
        result["carrier_undone"] = [len([o for o in doc.Objects if role(o) == "Carrier"]),
                                    [w.getParentGeoFeatureGroup() is None for w in walls]]
        doc.redo()
        carrier = doc.getObject(carrier.Name)
    else:  # no Make carrier from solids (before issue 27): the base is tagged instead
        select([walls[2]])
        Gui.runCommand("WaferScan_TagCarrier")
        carrier = walls[2]
        result["carrier"]["size"] = [carrier.WaferDiameter.Value, carrier.WaferThickness.Value]
    carrier.SlotOrigin = App.Placement(App.Vector(*CENTRE, 10), App.Rotation())  # slot 1's seat
    sensor = state["solids"][-1]
    select([sensor])
    Gui.runCommand("WaferScan_TagScanner")
    # A split solid's frame is the document's (its shape is where it was in the compound).
    sensor.Emitter, sensor.Receiver = App.Vector(90, 46.6, 302), App.Vector(250, 46.6, 302)
    doc.recompute()
    message_texts()
    state["carrier"] = carrier
    result["console_calls"] = console_calls()
    # The first Run scan: 25 slots by default.
    select([])
    Gui.runCommand("WaferScan_RunScan")
    from waferscan.gui.session import session
    panel = session.task_panel
    panel.speed.setValue(panel.speed.minimum())
    wait_for("the first scan", lambda: panel.animation.ended, first_scanned)


def settings_of(doc):
    return [o for o in doc.Objects if role(o) == "ScanSettings"][0]


def first_scanned():
    from waferscan.gui.session import last_result, session
    doc = state["doc"]
    settings = settings_of(doc)
    scanned = last_result(doc)
    result["first"] = {"range": [scanned.layout.scan.start_z, scanned.layout.scan.final_z],
                       "code": scanned.code, "warnings": list(scanned.warnings),
                       "wafers": len(scanned.layout.wafers),
                       "stored": [settings.StartZ.Value, settings.FinalZ.Value],
                       "follows": getattr(settings, "RangeFromCarrier", None)}
    doc.saveAs(os.path.join(os.environ["WAFERSCAN_GUI_MCS"], "tool-cell.FCStd"))
    Gui.Control.closeDialog()
    for dialog in session.dialogs:
        dialog.close()
    message_texts()
    # The carrier's slots described: the range follows.
    state["carrier"].SlotCount = 10
    doc.recompute()
    from waferscan.gui.scanning import result_now, scan_and_store
    # What only reads the document (Results table, Slot code, Cross-check) leaves it as it is.
    undo_before = list(doc.UndoNames)
    seen = result_now(doc)
    result["read_only"] = {"range": [seen.layout.scan.start_z, seen.layout.scan.final_z],
                           "stored": [settings.StartZ.Value, settings.FinalZ.Value],
                           "undo_same": list(doc.UndoNames) == undo_before}
    _, second = scan_and_store(doc)
    result["second"] = {"range": [second.layout.scan.start_z, second.layout.scan.final_z],
                        "code": second.code,
                        "stored": [settings.StartZ.Value, settings.FinalZ.Value],
                        "follows": getattr(settings, "RangeFromCarrier", None),
                        "undo": list(doc.UndoNames)[:3]}
    # The user sets the range: it stays as set.
    settings.FinalZ = App.Units.Quantity("60 mm")
    state["carrier"].SlotCount = 12
    doc.recompute()
    _, third = scan_and_store(doc)
    result["third"] = {"range": [third.layout.scan.start_z, third.layout.scan.final_z],
                       "follows": getattr(settings, "RangeFromCarrier", None)}
    # A wafer tagged after its carrier, of another thickness: the carrier is not changed, and
    # the user is told.
    thin = doc.addObject("Part::Cylinder", "Thin")
    thin.Radius, thin.Height = 150, 0.5
    thin.Placement.Base = App.Vector(*CENTRE, 200)
    doc.recompute()
    select([thin])
    Gui.runCommand("WaferScan_TagWafer")
    result["thin"] = [role(thin), state["carrier"].WaferThickness.Value,
                      " ".join(message_texts())]
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(settings)
    later(final_shot, 300)


def final_shot():
    window_shot("gui-range-follows.png", dock_width=420)
    nested()


def nested():
    """Solids inside a placed App::Part: the carrier is made in that part and nothing moves;
    solids of two containers are refused with a message."""
    doc = App.newDocument("Nested")
    cell = doc.addObject("App::Part", "Cell")
    cell.Placement.Base = App.Vector(0, 0, 100)
    walls = []
    for name, x in (("LeftWall", 0), ("RightWall", 330)):
        wall = doc.addObject("Part::Box", name)
        wall.Length, wall.Width, wall.Height = 10, 360, 270
        wall.Placement.Base = App.Vector(x, 0, 0)
        cell.addObject(wall)
        walls.append(wall)
    loose = doc.addObject("Part::Box", "Loose")
    doc.recompute()
    before = [tuple(w.getGlobalPlacement().Base) for w in walls]
    select(walls)
    run("WaferScan_MakeCarrier")
    carrier = [o for o in doc.Objects if role(o) == "Carrier"]
    result["nested"] = {
        "parent": carrier[0].getParentGeoFeatureGroup().Name if carrier else None,
        "moved": [tuple(w.getGlobalPlacement().Base) for w in walls] != before,
        "inside": [w.getParentGeoFeatureGroup().Name for w in walls],
        "message": " ".join(message_texts())}
    select([cell.Group[-1].Group[0] if carrier else walls[0], loose])
    undo_before = list(doc.UndoNames)
    run("WaferScan_MakeCarrier")
    result["two_containers"] = [message_texts(), list(doc.UndoNames) == undo_before]
    finish()


start(begin)
