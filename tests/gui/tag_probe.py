# Run by FreeCAD's GUI (tests/gui/test_gui_tag.py): an engineer's own solids made into a layout.
# Set the preferences on their page; model a carrier, two wafers and a sensor from Part
# primitives; tag them with the workbench's commands (a box refused as a wafer, the document
# left as it was; undo and redo); scan with the command; save the document for the test.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, finish, message_texts, result, start, wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

state = {}


def preferences_page():
    from waferscan.gui import preferences
    page = preferences.PreferencesPage()
    page.loadSettings()
    result["defaults"] = [page.half_thickness.isChecked(), page.position.value_mm(),
                          page.protrusion.value_mm(), page.folder.text(),
                          page.speed.value()]
    page.half_thickness.setChecked(False)
    page.thickness.setText("0.25 mm")
    page.position.setText("0.016 in")  # a user may type other units
    page.protrusion.setText("1500 um")
    page.folder.setText(os.environ["WAFERSCAN_GUI_MCS"])
    page.speed.setValue(4.5)  # seconds for a whole scan's animation
    page.form.resize(520, 420)
    page.form.grab().save(artifact("gui-preferences.png"))
    page.saveSettings()
    group = App.ParamGet(preferences.PARAMETERS)
    result["stored"] = [group.GetFloat("ThicknessTolerance"), group.GetFloat("PositionTolerance"),
                        group.GetFloat("ProtrusionLimit"), group.GetString("McsFolder"),
                        group.GetFloat("PlaybackSeconds")]
    again = preferences.PreferencesPage()
    again.loadSettings()
    result["reloaded"] = [again.half_thickness.isChecked(), again.thickness.value_mm(),
                          again.speed.value()]


def model():
    doc = App.newDocument("OwnSolids")
    foup = doc.addObject("Part::Box", "Foup")
    foup.Length, foup.Width, foup.Height = 340, 360, 70
    foup.Placement.Base = App.Vector(-10, 30, -5)  # the carrier's origin is its corner
    wafers = []
    for name, z in (("Wafer1", 10.0), ("Wafer3", 30.0)):
        wafer = doc.addObject("Part::Cylinder", name)
        wafer.Radius, wafer.Height = 150, 0.775
        wafer.Placement.Base = App.Vector(160, 200, z)
        wafers.append(wafer)
    bracket = doc.addObject("Part::Box", "Bracket")  # not a disc
    bracket.Length = bracket.Width = bracket.Height = 20
    sensor = doc.addObject("Part::Box", "Sensor")
    sensor.Length, sensor.Width, sensor.Height = 160, 4, 4
    sensor.Placement.Base = App.Vector(80, 66.6, 0)  # the beam 16.6 mm into the wafers
    doc.recompute()
    Gui.SendMsgToActiveView("ViewFit")
    return doc, foup, wafers, bracket, sensor


def role(obj):
    return getattr(obj, "WaferScanRole", None)


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    preferences_page()
    doc, foup, wafers, bracket, sensor = model()
    undo_before = list(doc.UndoNames)
    # A wafer and a box tagged together: the box is refused and the wafer stays untagged.
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(wafers[0])
    Gui.Selection.addSelection(bracket)
    Gui.runCommand("WaferScan_TagWafer")
    from waferscan.gui.session import session
    refusals = message_texts()
    result["refusal"] = refusals[-1] if refusals else None
    result["after_refusal"] = [role(wafers[0]), role(bracket)]
    result["undo_after_refusal"] = list(doc.UndoNames) == undo_before
    # Tag for real, one undo step each.
    Gui.Selection.clearSelection()
    for wafer in wafers:
        Gui.Selection.addSelection(wafer)
    Gui.runCommand("WaferScan_TagWafer")
    result["tagged_wafers"] = [role(w) for w in wafers]
    doc.undo()
    result["after_undo"] = [role(w) for w in wafers]
    doc.redo()
    result["after_redo"] = [role(w) for w in wafers]
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(foup)
    Gui.runCommand("WaferScan_TagCarrier")
    foup.SlotCount = 5
    foup.WaferThickness = 0.775
    foup.SlotOrigin = App.Placement(App.Vector(170, 170, 15), App.Rotation())  # slot 1's seat
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(sensor)
    Gui.runCommand("WaferScan_TagScanner")
    sensor.Emitter = App.Vector(0, 2, 2)
    sensor.Receiver = App.Vector(160, 2, 2)
    sensor.Placement.Base = App.Vector(80, 64.6, -2)  # the emitter at Z 0
    doc.recompute()
    result["tag_messages"] = message_texts()  # what to set next, for the carrier and scanner
    result["undo_names"] = list(doc.UndoNames)
    Gui.Selection.clearSelection()
    Gui.runCommand("WaferScan_RunScan")
    state["doc"] = doc
    panel = session.task_panel
    result["speed_from_preferences"] = panel.speed.value()
    wait_for("the animation's end", lambda: panel.animation.ended, scanned)


def scanned():
    from waferscan.gui.session import last_result
    doc = state["doc"]
    result["code"] = last_result(doc).code
    settings = [o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "ScanSettings"][0]
    result["settings"] = [settings.ThicknessTolerance.Value, settings.PositionTolerance.Value,
                          settings.ProtrusionLimit.Value, settings.ThicknessToleranceSet]
    result["undo_names_after_scan"] = list(doc.UndoNames)
    window_shot("gui-own-solids.png")
    doc.saveAs(os.path.join(os.environ["WAFERSCAN_GUI_MCS"], "own-solids.FCStd"))
    Gui.Control.closeDialog()
    edits(doc, settings)


class ForeignPanel:
    """Another tool's task panel (as a sketch in edit would be)."""

    def __init__(self):
        self.form = QtGui.QLabel("someone else's task")


def edits(doc, settings):
    from waferscan.gui.session import session
    # A range typed wrong in the property editor: a message, no traceback, no animation.
    settings.FinalZ = -5.0
    Gui.runCommand("WaferScan_RunScan")
    result["bad_range_messages"] = message_texts()
    result["bad_range_panel"] = bool(Gui.Control.activeDialog())
    settings.FinalZ = 60.0
    # Another tool's task panel is open: ours waits for it.
    Gui.Control.showDialog(ForeignPanel())
    Gui.runCommand("WaferScan_RunScan")
    result["foreign_messages"] = message_texts()
    Gui.Control.closeDialog()
    # Exact edges, scanned downwards: the animation runs top to bottom.
    settings.ZStep = 0.0
    settings.Direction = "down"
    Gui.runCommand("WaferScan_RunScan")
    panel = session.task_panel
    result["exact_about"] = panel.form.findChildren(QtGui.QLabel)[0].text()
    result["exact_first_z"] = None
    panel.animation.moved.connect(
        lambda k, z: result["exact_first_z"] is None and result.__setitem__("exact_first_z", z))
    state["exact"] = panel
    wait_for("the exact animation's end", lambda: panel.animation.ended,
             lambda: after_exact(doc))


def after_exact(doc):
    from waferscan.gui.session import last_result, session
    panel = state["exact"]
    result["exact_completed"] = panel.animation.completed
    result["exact_code"] = last_result(doc).code
    Gui.Control.closeDialog()
    for dialog in session.dialogs:
        dialog.close()
    # A wafer deleted after the scan: the results table and the cross-check see the document
    # as it is now.
    doc.removeObject("Wafer3")
    doc.recompute()
    Gui.runCommand("WaferScan_Results")
    table = session.dialogs[0]
    result["rows_after_delete"] = table.rows()
    Gui.runCommand("WaferScan_CrossCheck")
    result["crosscheck_after_delete"] = session.dialogs[0].text()
    QtGui.QApplication.clipboard().clear()
    finish()


start(begin)
