# Run by FreeCAD's GUI (tests/gui/test_gui_frames.py): the paper's cell turned 90 degrees about
# Z (WAFERSCAN_GUI_SCENARIO, no robot: its sensor lifts along Z) built, its solids exported as
# plain solids in frames of their own as STEP with FreeCAD and imported again with "merge" off
# (FreeCAD's LinkGroup tree), tagged with the
# workbench's commands, then set up WITHOUT TYPING A COORDINATE: "Set up carrier and sensor",
# slot 1's seat picked on slot 1's wafer, the derived slot count and pitch accepted, the
# beam's ends picked in the 3D view, OK; then undone, replayed from the recorded line, scanned.
import os
import re
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    answer_next_question, console_calls, finish, later, message_texts, result, start, wait_for,
    window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

FOLDER = os.environ["WAFERSCAN_GUI_MCS"]
STEP_FILE = os.path.join(FOLDER, "turned-cell.step")
# The turned paper cell's beam: emitter (-266.6, -80, 280), along +Y, 160 mm; its heads are
# spheres of 3 mm radius: a click on the top of a head is 3 mm above the beam's end.
EMITTER_CLICK = (-266.6, -80.0, 283.0)
RECEIVER_CLICK = (-266.6, 80.0, 283.0)
state = {}


def imported(doc, name):
    """The object the STEP import made of the product ``name``: 0.20.2 labels the product's
    compound ``name``; 1.0 makes an App::Part labelled ``name`` and a number and gives ``name``
    to the first solid in it. The one holding the most solids is the product."""
    import Part
    import re as _re

    found = [o for o in doc.Objects if _re.fullmatch(_re.escape(name) + r"\d*", o.Label)]
    return max(found, key=lambda o: len(Part.getShape(o).Solids))


def instance(doc, label):
    from waferscan.cad.scene import scene_instances
    return next(i for i in scene_instances(doc) if i.obj.Label == label)


def click(doc, label, element, point):
    """What a click on ``element`` of the object labelled ``label`` at ``point`` (global) in the
    3D view does: it selects that sub-element with the point clicked."""
    found = instance(doc, label)
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, found.root.Name, found.sub + element, *point)


def texts(fields):
    return [f.text() for f in fields.fields]


# The frames the cell's objects get in the STEP file (their own, as a CAD user left them).
CARRIER_FRAME = App.Placement(App.Vector(-250, 100, 50), App.Rotation(App.Vector(0, 0, 1), -90))
SENSOR_FRAME = App.Placement(App.Vector(10, 20, 30), App.Rotation(App.Vector(0, 0, 1), 180))


def plain_copy(doc, shown, name, frame=App.Placement()):
    """A Part::Feature of the shape ``shown`` (global), its own frame at ``frame``."""
    local = shown.copy()
    local.Placement = App.Placement()
    local.transformShape(frame.inverse().multiply(shown.Placement).toMatrix(), True)
    copy = doc.addObject("Part::Feature", name)
    copy.Shape = local
    copy.Placement = frame
    return copy


def export_cell():
    """The turned paper cell as a CAD user would send it: a STEP file of plain solids (no
    WaferScan roles) in an App::Part, each in a frame of its own."""
    from waferscan.cad.scene import scene_instances
    from waferscan.gui.scanning import open_scenario
    demo = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    shown = {i.obj.Label: i.shape() for i in scene_instances(demo)
             if i.obj.Label in ("LP1", "Scanner") or i.obj.Label.startswith("LP1_W")}
    cell = demo.addObject("App::Part", "Cell")
    cell.addObject(plain_copy(demo, shown["LP1"], "Foup", CARRIER_FRAME))
    cell.addObject(plain_copy(demo, shown["Scanner"], "Sensor", SENSOR_FRAME))
    for label in sorted(shown):
        if label.startswith("LP1_W"):
            cell.addObject(plain_copy(demo, shown[label], label[4:]))
    demo.recompute()
    import ImportGui
    ImportGui.export([cell], STEP_FILE)
    App.closeDocument(demo.Name)


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    # Nothing tagged yet: the command says what to do first.
    empty = App.newDocument("Empty")
    Gui.runCommand("WaferScan_SetFrames")
    result["untagged_messages"] = message_texts()
    result["untagged_panel"] = bool(Gui.Control.activeDialog())
    App.closeDocument(empty.Name)
    export_cell()
    import ImportGui
    doc = App.newDocument("Cell")
    ImportGui.insert(STEP_FILE, doc.Name, merge=False)  # "Use LinkGroup" at its default
    Gui.SendMsgToActiveView("ViewFit")
    state["doc"] = doc
    by_label = {o.Label: o for o in doc.Objects}
    result["imported_labels"] = sorted(by_label)
    wafers = [o for label, o in by_label.items() if re.fullmatch(r"W\d\d", label)]
    state["carrier"], state["sensor"] = imported(doc, "Foup").Label, imported(doc, "Sensor").Label
    for objects, command in ((wafers, "WaferScan_TagWafer"), ([by_label[state["carrier"]]],
                             "WaferScan_TagCarrier"), ([by_label[state["sensor"]]],
                                                       "WaferScan_TagScanner")):
        Gui.Selection.clearSelection()
        for obj in objects:
            Gui.Selection.addSelection(obj)
        questions = []
        if command != "WaferScan_TagWafer":  # walls and ledges, rod and heads: compounds
            answer_next_question(f"Tag as one {command[len('WaferScan_Tag'):].lower()}",
                                 questions)
        Gui.runCommand(command)
        result.setdefault("questions", []).extend(questions)
    Gui.Selection.clearSelection()
    result["tag_messages"] = message_texts()
    carrier = instance(doc, state["carrier"])
    result["carrier_turned_deg"] = carrier.placement().Rotation.Angle * 180 / 3.141592653589793
    result["freecad_major"] = int(App.Version()[0])
    for key, label in (("carrier_placement", state["carrier"]), ("sensor_placement",
                                                                  state["sensor"])):
        placed = instance(doc, label).placement()
        result[key] = [list(placed.Base), list(placed.Rotation.Q)]
    result["undo_before"] = list(doc.UndoNames)
    Gui.runCommand("WaferScan_SetFrames")
    from waferscan.gui.session import session
    panel = session.task_panel
    state["panel"] = panel
    result["panel_title"] = panel.form.windowTitle()
    result["derived_text"] = panel.derived.text()
    result["seat_before"] = texts(panel.points["seat"])
    Gui.ActiveDocument.ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    later(pick, 300)  # the panel laid out at the dock's width, as a user sees it


def pick():
    doc, panel = state["doc"], state["panel"]
    window_shot("gui-frames-derived.png", dock_width=264)
    # Slot 1's seat: pick, then click slot 1's wafer on its top face (0.7 mm above its seat).
    panel.points["seat"].pick.click()
    result["seat_hint"] = panel.status.text()
    result["seat_status_bar"] = Gui.getMainWindow().statusBar().currentMessage()
    click(doc, "W01", "Face2", (-395.0, 10.0, 294.64))
    result["seat_picked"] = texts(panel.points["seat"])
    result["seat_status"] = panel.status.text()
    # A click while not picking changes nothing.
    click(doc, "W02", "Face2", (-395.0, 10.0, 304.64))
    result["seat_after_stray_click"] = texts(panel.points["seat"])
    panel.use_derived.click()
    result["slots_pitch"] = [panel.slot_count.value(), panel.pitch.text()]
    result["seat_derived"] = texts(panel.points["seat"])
    for key, point in (("emitter", EMITTER_CLICK), ("receiver", RECEIVER_CLICK)):
        panel.points[key].pick.click()
        if key == "emitter":  # a click in the tree first: no point, the pick waits
            before = texts(panel.points[key])
            Gui.Selection.clearSelection()
            Gui.Selection.addSelection(doc.Name, instance(doc, state["sensor"]).root.Name)
            result["tree_click"] = {"unchanged": texts(panel.points[key]) == before,
                                    "still_picking": panel.picking == key,
                                    "status": panel.status.text()}
            Gui.Selection.clearSelection()
        click(doc, "Sensor", "Face1", point)
        result[f"{key}_picked"] = texts(panel.points[key])
    window_shot("gui-frames-picked.png", dock_width=264)
    result["status_after_picks"] = panel.status.text()
    result["status_bar_after_picks"] = Gui.getMainWindow().statusBar().currentMessage()
    # Every label shows all its lines (a wrapped label squeezed in a task box loses its last).
    result["clipped_labels"] = [label.text() for label in panel.form.findChildren(QtGui.QLabel)
                                if label.wordWrap() and label.text() and
                                label.height() < label.heightForWidth(label.width())]
    ok = [b for b in Gui.getMainWindow().findChildren(QtGui.QPushButton)
          if b.text().replace("&", "") == "OK" and b.isVisible()]
    result["ok_buttons"] = len(ok)
    # A mistake first: a pitch that is not a length. OK says so and changes nothing.
    panel.pitch.setText("ten")
    ok[0].click()
    Gui.updateGui()
    result["bad_pitch_messages"] = message_texts()
    result["bad_pitch_open"] = panel.is_open()
    result["bad_pitch_undo"] = list(doc.UndoNames)
    panel.pitch.setText("10 mm")
    ok[0].click()
    later(after_ok, 300)


def own(obj, name):
    from waferscan.cad import roles
    value = getattr(roles.role_holder(obj), name)
    if hasattr(value, "Base"):
        return [list(value.Base), list(value.Rotation.Q)]
    return list(value) if hasattr(value, "x") else getattr(value, "Value", value)


def document_values(doc):
    by_label = {o.Label: o for o in doc.Objects}
    carrier, scanner = by_label[state["carrier"]], by_label[state["sensor"]]
    return {"SlotCount": own(carrier, "SlotCount"), "Pitch": own(carrier, "Pitch"),
            "SlotOrigin": own(carrier, "SlotOrigin"), "Emitter": own(scanner, "Emitter"),
            "Receiver": own(scanner, "Receiver")}


def global_values(doc):
    from waferscan.cad.reader import read_layout
    layout = read_layout(doc)
    carrier = layout.scanned_carrier
    return {"first_slot_z": carrier.first_slot_z, "center": list(carrier.center),
            "front": list(carrier.front), "slots": carrier.slot_count, "pitch": carrier.pitch,
            "emitter": list(layout.beam.emitter), "direction": list(layout.beam.direction),
            "length": layout.beam.length}


def after_ok():
    from waferscan.gui.session import session
    doc, panel = state["doc"], state["panel"]
    result["panel_open_after_ok"] = panel.is_open()
    result["messages_after_ok"] = message_texts()
    result["undo_after"] = list(doc.UndoNames)
    result["own_frame"] = document_values(doc)
    result["global"] = global_values(doc)
    result["console_calls"] = calls = console_calls()
    # Undo: the document as it was; the recorded line replayed: as OK left it, with no question.
    doc.undo()
    result["own_frame_undone"] = document_values(doc)
    line = next(c for c in calls if c.startswith("waferscan.gui.commands.set_frames("))
    Gui.doCommand(line)
    result["own_frame_replayed"] = document_values(doc)
    result["messages_after_replay"] = message_texts()
    doc.saveAs(os.path.join(FOLDER, "turned-cell.FCStd"))
    result["task_panel_is_frames"] = session.task_panel is panel
    Gui.runCommand("WaferScan_RunScan")
    scan = session.task_panel
    scan.speed.setValue(scan.speed.minimum())
    state["scan"] = scan
    wait_for("the turned cell's scan", lambda: scan.animation.ended, scanned)


def scanned():
    from waferscan.gui.session import last_result
    result["gui_code"] = last_result(state["doc"]).code
    result["scan_messages"] = message_texts()
    Gui.Control.closeDialog()
    finish()


start(begin)
