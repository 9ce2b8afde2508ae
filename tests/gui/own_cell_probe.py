# Run by FreeCAD's GUI (tests/gui/test_gui_own_cell.py): an engineer's own cell, as a new user
# brings it. Model a cell of App::Parts (a FOUP with two wafers, a sensor), export it as STEP
# with FreeCAD, import it again with FreeCAD's default import settings ("merge compound" on: one
# compound), split and tag it with the workbench's commands, scan it; import it once more with
# merge off and "Use LinkGroup" on, tag and scan that; check the commands stay enabled while the
# scan panel is open, running, done and stopped; close the document during a scan.
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
STEP_FILE = os.path.join(FOLDER, "own-cell.step")
state = {}
# Slot 1's seat at Z 10, pitch 10, 5 slots; wafers seated in slots 1 and 3 (and one thin).
SEATS = {"W1": 10.0, "W3": 30.0}
COMMANDS = ("WaferScan_Results", "WaferScan_SlotCode", "WaferScan_CrossCheck",
            "WaferScan_Preferences", "WaferScan_RunScan", "WaferScan_McsLink",
            "WaferScan_NewPaperLayout", "Std_New")


def record_enabled(key, then, extra=()):
    """Record which commands a user can click now (their actions' enabled state, which FreeCAD
    updates on a timer, so after a pause), then go on with ``then``."""

    def read():
        found = {}
        for name in COMMANDS + tuple(extra):
            actions = Gui.Command.get(name).getAction()
            found[name] = bool(actions) and all(a.isEnabled() for a in actions)
        result[key] = found
        then()

    later(read, 800)


def global_frame(obj):
    """The object's placement as the 3D view shows it (through App::Parts and link groups)."""
    from waferscan.cad.scene import scene_instances
    return next(i for i in scene_instances(obj.Document) if i.obj is obj).placement()


def model():
    doc = App.newDocument("OwnCell")
    cell = doc.addObject("App::Part", "MyCell")
    foup = doc.addObject("App::Part", "FOUP")
    cell.addObject(foup)
    foup.Placement.Base = App.Vector(-10, 30, -5)
    for name, size, base in (("Base", (340, 360, 5), (0, 0, 0)), ("Left", (10, 360, 70), (0, 0, 0)),
                             ("Right", (10, 360, 70), (330, 0, 0))):
        wall = doc.addObject("Part::Box", name)
        wall.Length, wall.Width, wall.Height = size
        wall.Placement.Base = App.Vector(*base)
        foup.addObject(wall)
    for name, z in SEATS.items():
        wafer = doc.addObject("Part::Cylinder", name)
        wafer.Radius, wafer.Height = 150, 0.775
        wafer.Placement.Base = App.Vector(170, 170, z + 5)  # in the FOUP's frame
        foup.addObject(wafer)
    sensor = doc.addObject("Part::Box", "Sensor")
    sensor.Length, sensor.Width, sensor.Height = 160, 4, 4
    sensor.Placement.Base = App.Vector(80, 64.6, 150)  # far above: the range is the slots'
    cell.addObject(sensor)
    doc.recompute()
    import ImportGui
    ImportGui.export([cell], STEP_FILE)
    App.closeDocument(doc.Name)


def solid_at(doc, x, y, z):
    """The visible, untagged solid whose bounding box holds (x, y, z) and is the smallest."""
    found = []
    for obj in doc.Objects:
        shape = getattr(obj, "Shape", None)
        if shape is None or shape.isNull() or len(shape.Solids) != 1 or not obj.Visibility:
            continue
        box = shape.BoundBox
        if box.isInside(App.Vector(x, y, z)):
            found.append((box.DiagonalLength, obj))
    return min(found, key=lambda pair: pair[0])[1]


def tag(objects, command):
    Gui.Selection.clearSelection()
    for obj in objects:
        Gui.Selection.addSelection(obj)
    Gui.runCommand(command)


def set_carrier(obj):
    """Slot 1's seat at global (160, 200, 10), pitch 10, 5 slots, in the object's own frame."""
    obj.SlotCount = 5
    obj.Pitch = 10.0
    seat = App.Placement(App.Vector(160, 200, 10), App.Rotation())
    obj.SlotOrigin = global_frame(obj).inverse().multiply(seat)


def set_scanner(obj):
    inverse = global_frame(obj).inverse()
    obj.Emitter = inverse.multVec(App.Vector(70, 66.6, 152))
    obj.Receiver = inverse.multVec(App.Vector(250, 66.6, 152))


def sensor_view(doc):
    return {o.Label: o for o in doc.Objects}["Sensor"].ViewObject


def look(doc, panel):
    """The walls' and wafers' transparency, and whether the beam is drawn over the sensor."""
    by_label = {o.Label: o for o in doc.Objects}
    overlay = panel.animation.appearance.overlay
    return [{label: by_label[label].ViewObject.Transparency
             for label in ("Base", "Left", "Right", "W1", "W3")},
            overlay is not None and
            overlay.node in list(sensor_view(doc).RootNode.getChildren())]


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    model()
    import ImportGui
    import Part
    doc = App.newDocument("MergedCell")
    ImportGui.insert(STEP_FILE, doc.Name)  # FreeCAD's default import settings
    if not any(len(getattr(o, "Shape", Part.Shape()).Solids) == 6 and o.TypeId == "Part::Feature"
               for o in doc.Objects):
        # FreeCAD 1.0's default rebuilds the App::Part tree of single solids instead of 0.20.2's
        # one merged compound, and neither merge=True nor Part.insert gives one compound
        # (docs/freecad-1.0.md): the compound this probe splits is then the file's one shape.
        App.closeDocument(doc.Name)
        doc = App.newDocument("MergedCell")
        doc.addObject("Part::Feature", "own_cell").Shape = Part.read(STEP_FILE)
        doc.recompute()
    Gui.SendMsgToActiveView("ViewFit")
    result["merged_objects"] = [(o.TypeId, len(o.Shape.Solids)) for o in doc.Objects
                                if hasattr(o, "Shape")]
    compound = doc.Objects[0]
    undo_before = list(doc.UndoNames)
    # Tag as wafer on the compound: refused as one wafer, offered the solids inside.
    questions = []
    answer_next_question("Cancel", questions)
    tag([compound], "WaferScan_TagWafer")
    result["cancelled_question"] = questions[-1] if questions else None
    result["after_cancel"] = [len(doc.Objects), list(doc.UndoNames) == undo_before]
    answer_next_question("Split into solids", questions)
    tag([compound], "WaferScan_TagWafer")
    wafers = [o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "Wafer"]
    result["split"] = {"objects": len(doc.Objects), "wafers": len(wafers),
                       "wafer_z": sorted(round(w.Shape.BoundBox.ZMin, 6) for w in wafers),
                       "compound_visible": compound.Visibility,
                       "undo": list(doc.UndoNames)}
    result["split_message"] = message_texts()
    doc.undo()  # the tagging
    result["after_one_undo"] = [len(doc.Objects), compound.Visibility,
                                len([o for o in doc.Objects
                                     if getattr(o, "WaferScanRole", "") == "Wafer"])]
    doc.undo()  # the split
    result["after_undo"] = [len(doc.Objects), compound.Visibility,
                            [getattr(o, "WaferScanRole", "") for o in doc.Objects]]
    doc.redo()
    doc.redo()
    result["after_redo"] = len([o for o in doc.Objects
                                if getattr(o, "WaferScanRole", "") == "Wafer"])
    # The carrier: clicking a wall first (a mistake), then the base; re-tagging a wafer asks.
    base = solid_at(doc, 100, 100, -3)
    wall = solid_at(doc, -5, 100, 30)
    wafer = solid_at(doc, 100, 200, 10.3)
    answer_next_question("Cancel", questions)
    tag([wafer], "WaferScan_TagCarrier")
    result["retag_question"] = questions[-1]
    result["retag_cancelled"] = getattr(wafer, "WaferScanRole", "")
    tag([base], "WaferScan_TagCarrier")
    tag([wall], "WaferScan_TagCarrier")
    set_carrier(base)
    set_carrier(wall)
    sensor = solid_at(doc, 100, 66.6, 152)
    tag([sensor], "WaferScan_TagScanner")
    set_scanner(sensor)
    doc.recompute()
    result["tag_messages"] = message_texts()
    # Run scan: two carriers, so it asks which to scan; the base is.
    answer_next_question(base.Label, questions)
    Gui.Selection.clearSelection()
    Gui.runCommand("WaferScan_RunScan")
    result["carrier_question"] = questions[-1]
    from waferscan.gui.session import session
    panel = session.task_panel
    state["doc"], state["panel"] = doc, panel
    result["merged_about"] = panel.form.findChildren(QtGui.QLabel)[0].text()
    panel.animation.pause()
    record_enabled("enabled_paused", lambda: play_merged(panel))


def play_merged(panel):
    panel.play()
    wait_for("the merged cell's scan", lambda: panel.animation.ended,
             lambda: record_enabled("enabled_done", merged_done))


def merged_done():
    from waferscan.gui.session import last_result, session
    doc, panel = state["doc"], state["panel"]
    result["merged_code"] = last_result(doc).code
    result["merged_messages"] = message_texts()
    result["merged_range"] = [last_result(doc).layout.scan.start_z,
                              last_result(doc).layout.scan.final_z]
    Gui.runCommand("WaferScan_Results")  # opens while the panel is open
    result["results_opened_with_panel"] = [d.windowTitle() for d in session.dialogs]
    Gui.ActiveDocument.ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    window_shot("gui-own-cell.png", dock_width=264)
    for dialog in session.dialogs:
        dialog.close()
    doc.saveAs(os.path.join(FOLDER, "merged-cell.FCStd"))
    Gui.Control.closeDialog()
    later(link_group, 100)


def link_group():
    import ImportGui
    doc = App.newDocument("LinkCell")
    ImportGui.insert(STEP_FILE, doc.Name, merge=False)  # "Use LinkGroup" left at its default
    result["link_types"] = sorted({o.TypeId for o in doc.Objects})
    by_label = {o.Label: o for o in doc.Objects}
    tag([by_label["W1"], by_label["W3"]], "WaferScan_TagWafer")
    tag([by_label["FOUP"]], "WaferScan_TagCarrier")
    set_carrier(by_label["FOUP"])
    tag([by_label["Sensor"]], "WaferScan_TagScanner")
    set_scanner(by_label["Sensor"])
    doc.recompute()
    message_texts()
    from waferscan.cad.reader import DocumentScene
    scene = DocumentScene.of(doc)
    result["link_scene"] = {"wafers": [i.path for i in scene.wafers],
                            "carriers": [i.path for i in scene.carriers],
                            "scanners": [i.path for i in scene.scanners]}
    colour = tuple(sensor_view(doc).ShapeColor)
    Gui.runCommand("WaferScan_RunScan")
    result["link_errors"] = message_texts()
    from waferscan.gui.session import session
    panel = session.task_panel
    state["sensor_colour"] = colour
    result["link_running_look"] = look(doc, panel) + [tuple(sensor_view(doc).ShapeColor) == colour]
    state["doc"], state["panel"] = doc, panel
    panel.speed.setValue(panel.speed.minimum())  # seconds: fast
    wait_for("the link cell's scan", lambda: panel.animation.ended, link_done)


def link_done():
    from waferscan.gui.session import last_result, session
    doc = state["doc"]
    result["link_code"] = last_result(doc).code
    # The Python console shows the calls the commands made, as a script would make them.
    result["console_calls"] = console_calls()
    result["link_after_look"] = look(doc, session.task_panel) + [
        tuple(sensor_view(doc).ShapeColor) == state["sensor_colour"]]
    doc.saveAs(os.path.join(FOLDER, "link-cell.FCStd"))
    Gui.Control.closeDialog()
    for dialog in session.dialogs:
        dialog.close()
    # Stopped: the commands stay enabled.
    Gui.runCommand("WaferScan_RunScan")
    panel = session.task_panel
    panel.speed.setValue(600.0)  # seconds: slow
    panel.stop_button.click()
    result["stopped_status"] = panel.status.text()
    record_enabled("enabled_stopped", after_stop)


def after_stop():
    from waferscan.gui.session import session
    Gui.runCommand("WaferScan_Results")
    result["results_after_stop"] = len(session.dialogs)
    for dialog in session.dialogs:
        dialog.close()
    # The MCS link panel, open for hours: the commands stay enabled too.
    Gui.Control.closeDialog()
    Gui.runCommand("WaferScan_McsLink")
    # Edit → Delete too, with something selected to delete.
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection({o.Label: o for o in state["doc"].Objects}["Base"])
    record_enabled("enabled_mcs", close_mcs, extra=("Std_Delete",))


def close_mcs():
    from waferscan.gui.session import session
    Gui.Selection.clearSelection()
    Gui.Control.closeDialog()
    # The document closed while its scan runs: the panel ends and closes, without errors; its
    # results table too.
    Gui.runCommand("WaferScan_Results")
    state["table"] = session.dialogs[0]
    Gui.runCommand("WaferScan_RunScan")
    panel = session.task_panel
    panel.speed.setValue(600.0)  # seconds: slow
    state["closing"] = panel
    wait_for("a few frames", lambda: panel.animation.k > 5, close_during_scan)


def close_during_scan():
    panel = state["closing"]
    App.closeDocument(state["doc"].Name)
    later(lambda: after_close(panel), 300)


def after_close(panel):
    from waferscan.gui.qt import alive
    result["after_close"] = {"dialog_open": bool(Gui.Control.activeDialog()),
                             "panel_open": panel.is_open(),
                             "animation_ended": panel.animation.ended,
                             "running": panel.animation.running,
                             "results_table_open": alive(state["table"])}
    finish()


start(begin)
