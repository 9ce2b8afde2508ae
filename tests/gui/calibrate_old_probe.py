# Run by FreeCAD's GUI (tests/gui/test_gui_calibrate_old.py): "Apply to document" of the
# calibration dialog on a document saved by an earlier version, its recipe limits bare floats in
# mm (-1: not set), then Undo. Apply turns those limits into today's properties (a length and a
# "...Set" box) as it writes the calibrated recipe; Undo must give the document back as it was:
# every property of ScanSettings (its type and value) and the carrier's seat and pitch.
import os
import sys
import tempfile

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, message_texts, result, start  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402


def settings_of(doc):
    return next(o for o in doc.Objects if "ThicknessCorrection" in o.PropertiesList)


def state(doc):
    """The document as Apply writes it: ScanSettings' properties (type, value) and the
    carrier's seat and pitch; the recipe as the reader takes it."""
    from waferscan.cad.reader import read_layout

    settings = settings_of(doc)
    carrier = doc.getObject("LP1")
    mapping = read_layout(doc).mapping
    return {"settings": {p: [settings.getTypeIdOfProperty(p), str(getattr(settings, p))]
                         for p in sorted(settings.PropertiesList)},
            "carrier": [str(carrier.Pitch), str(carrier.SlotOrigin)],
            "recipe": [mapping.thickness_min, mapping.thickness_max, mapping.double_threshold,
                       mapping.position_below, mapping.position_above]}


def begin():
    from waferscan.cad.recipe_properties import LIMITS, holds_old_limits
    from waferscan.gui.scanning import open_scenario
    from waferscan.gui.session import session

    Gui.activateWorkbench("WaferScanWorkbench")
    built = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    settings = settings_of(built)
    for prop in LIMITS:  # as an earlier version saved them
        tip = settings.getDocumentationOfProperty(prop)
        settings.removeProperty(prop)
        settings.removeProperty(prop + "Set")
        settings.addProperty("App::PropertyFloat", prop, "WaferScan", tip)
        setattr(settings, prop, -1.0)
    settings.ThicknessMin = 0.6
    path = os.path.join(tempfile.mkdtemp(), "old_recipe.FCStd")
    built.saveAs(path)
    App.closeDocument(built.Name)
    doc = App.openDocument(path)
    Gui.updateGui()
    result["old_before"] = holds_old_limits(settings_of(doc))
    result["before"] = state(doc)
    result["undo_before"] = list(doc.UndoNames)
    Gui.runCommand("WaferScan_Calibrate")
    Gui.updateGui()
    dialog = session.dialogs[0]
    dialog.findChild(QtGui.QPushButton, "apply").click()
    Gui.updateGui()
    result["messages"] = message_texts()
    result["applied"] = state(doc)
    result["old_applied"] = holds_old_limits(settings_of(doc))
    result["undo_applied"] = list(doc.UndoNames)
    Gui.runCommand("Std_Undo")
    Gui.updateGui()
    result["undone"] = state(doc)
    result["old_undone"] = holds_old_limits(settings_of(doc))
    result["undo_undone"] = list(doc.UndoNames)
    Gui.runCommand("Std_Redo")
    Gui.updateGui()
    result["redone"] = state(doc)
    dialog.close()
    App.closeDocument(doc.Name)
    finish()


start(begin)
