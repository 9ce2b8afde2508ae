# Run by FreeCAD's GUI (tests/gui/test_gui_units.py): issue 27 item 13 as a user meets it under
# the "Imperial decimal" unit schema. Scan the paper's layout; read what the Recipe and the
# "Sensor and slow scan" sections and the results table show; type a thickness min in inches,
# "−1 mm" (refused: must be positive) and, with a German locale, "1,05 mm" and "0,5 ms"; apply.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, finish, open_section, result, scan_paper_layout, scan_settings, start, task_panel,
    wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore  # noqa: E402

UNITS = "User parameter:BaseApp/Preferences/Units"
IMPERIAL_DECIMAL = 3


def number(value):
    return float(getattr(value, "Value", value))


def begin():
    App.ParamGet(UNITS).SetInt("UserSchema", IMPERIAL_DECIMAL)
    App.Units.setSchema(IMPERIAL_DECIMAL)
    result["schema"] = App.Units.listSchemas(IMPERIAL_DECIMAL)
    first = scan_paper_layout()
    first.speed.setValue(1.0)
    wait_for("the first scan's end", lambda: first.animation.ended, read_panel)


def read_panel():
    panel = task_panel()
    recipe, sensor = panel.recipe_section, panel.sensor
    open_section(recipe)
    open_section(sensor)
    result["recipe_labels"] = [recipe.body.layout().labelForField(f).text()
                               for f in recipe.fields.values()]
    result["recipe_placeholders"] = {p: f.placeholderText() for p, f in recipe.fields.items()}
    result["sensor_labels"] = {p: sensor.body.layout().labelForField(f).text()
                               for p, f in sensor.fields.items()}
    result["sensor_texts"] = {p: f.text() for p, f in sensor.fields.items()}
    from waferscan.gui.results_view import ResultsTable
    table = ResultsTable(panel.animation.result, App.ActiveDocument)
    result["headers"] = [table.table.horizontalHeaderItem(c).text()
                         for c in range(table.table.columnCount())]
    result["first_row"] = table.rows()[0]
    table.resize(760, 420)
    table.show()
    Gui.updateGui()
    table.grab().save(artifact("gui-units-inch-results.png"))
    exported = artifact("units-inch-results.csv")
    table.export_csv(exported)  # Export CSV… without its file dialog
    with open(exported, encoding="utf-8") as handle:
        result["csv_lines"] = handle.read().splitlines()[:2]
    os.remove(exported)
    table.close()
    window_shot("gui-units-inch-sections.png")

    undo_before = App.ActiveDocument.UndoCount
    recipe.fields["ThicknessMin"].setText("0.026 in")
    recipe.fields["ThicknessMax"].setText("\u22121 mm")
    result["negative_applied"] = recipe.apply()
    result["negative_message"] = recipe.message.text()
    result["after_negative"] = [getattr(scan_settings(), "ThicknessMinSet", None),
                                App.ActiveDocument.UndoCount - undo_before]
    QtCore.QLocale.setDefault(QtCore.QLocale(QtCore.QLocale.German))
    recipe.fields["ThicknessMax"].setText("1,05 mm")
    result["good_applied"] = recipe.apply()
    result["good_message"] = recipe.message.text()
    stored = scan_settings()
    result["after_good"] = [number(stored.ThicknessMin), getattr(stored, "ThicknessMinSet", None),
                            number(stored.ThicknessMax), getattr(stored, "ThicknessMaxSet", None),
                            getattr(stored, "DoubleThresholdSet", None),
                            App.ActiveDocument.UndoCount - undo_before,
                            App.ActiveDocument.UndoNames[0]]
    recipe.load()  # as an Undo or Redo refills the fields from the document
    result["recipe_reloaded"] = {p: f.text() for p, f in recipe.fields.items()}
    sensor.latch.setCurrentIndex(sensor.latch.findText("sampled"))
    sensor.fields["SamplePeriodMs"].setText("0,5 ms")
    sensor.fields["Acceleration"].setText("2 m/s^2")
    result["sensor_applied"] = sensor.apply()
    result["sensor_message"] = sensor.message.text()
    result["after_sensor"] = [number(stored.SamplePeriodMs), number(stored.Acceleration),
                              str(stored.Latch)]
    sensor.load()
    result["sensor_reloaded"] = {p: sensor.fields[p].text()
                                 for p in ("SamplePeriodMs", "Acceleration")}
    window_shot("gui-units-inch-applied.png")
    panel.animation.stop()
    Gui.Control.closeDialog()
    Gui.updateGui()
    old_document()


def old_document():
    """The Recipe section on a ScanSettings saved by an earlier version (the limits bare floats
    in mm, -1 for "not set"): shown in inches, and written back in that convention."""
    from waferscan.cad.reader import read_layout
    from waferscan.gui.recipe_section import RecipeSection

    doc = App.ActiveDocument
    obj = scan_settings()
    for prop in ("ThicknessMin", "ThicknessMax", "DoubleThreshold", "PositionBelow",
                 "PositionAbove"):
        tip = obj.getDocumentationOfProperty(prop)
        obj.removeProperty(prop)
        obj.removeProperty(prop + "Set")
        obj.addProperty("App::PropertyFloat", prop, "WaferScan", tip)
        setattr(obj, prop, -1.0)
    obj.ThicknessMin = 0.66
    section = RecipeSection(doc)
    result["old_shown"] = {p: f.text() for p, f in section.fields.items()}
    undo_before = doc.UndoCount
    section.fields["ThicknessMax"].setText("1,1 mm")
    result["old_applied"] = section.apply()
    result["old_message"] = section.message.text()
    result["old_after"] = [obj.getTypeIdOfProperty("ThicknessMax"), obj.ThicknessMin,
                           obj.ThicknessMax, obj.DoubleThreshold, doc.UndoCount - undo_before]
    mapping = read_layout(doc).mapping
    result["old_read"] = [mapping.thickness_min, mapping.thickness_max, mapping.double_threshold]
    version1_document()


# The properties of issue 27 item 13's leftovers, as the property editor shows them.
EDITOR = ("SensorResponseMs", "SamplePeriodMs", "WristSpeedDegPerS", "WristAccelerationDegPerS2",
          "ThicknessTolerance", "ThicknessToleranceSet", "PositionTolerance")


def editor_texts():
    """{property: (its name as the Data tab shows it, the value's text)} of the selected
    object, read from FreeCAD's property editor (every tree view of two columns)."""
    from PySide import QtGui

    texts = {}
    for view in Gui.getMainWindow().findChildren(QtGui.QTreeView):
        model = view.model()
        if model is None or model.columnCount() != 2:
            continue
        pending = [QtCore.QModelIndex()]
        while pending:
            parent = pending.pop()
            for row in range(model.rowCount(parent)):
                name = model.index(row, 0, parent)
                pending.append(name)
                shown = str(model.data(name, QtCore.Qt.DisplayRole) or "")
                key = shown.replace(" ", "")
                if key in EDITOR and key not in texts:
                    value = model.index(row, 1, parent)
                    texts[key] = [shown, str(model.data(value, QtCore.Qt.DisplayRole))]
    return texts


def version1_document():
    """A document saved by the code before (ScanSettings version 1: times in s, the thickness
    tolerance a float) opened in the GUI: migrated, its ScanSettings shown in the property
    editor under the inch schema."""
    import shutil

    source = os.path.join(os.path.dirname(os.environ["WAFERSCAN_GUI_PROBES"]), "data",
                          "documents", "explicit.FCStd")
    path = artifact("version1-explicit.FCStd")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    shutil.copy(source, path)
    doc = App.openDocument(path)
    state["doc"] = doc
    obj = doc.getObject("ScanSettings")
    result["version1"] = [obj.WaferScanVersion, obj.SensorResponseMs, obj.SamplePeriodMs,
                          obj.ThicknessTolerance.Value, obj.ThicknessToleranceSet]
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(obj)
    wait_for("the property editor", lambda: len(editor_texts()) == len(EDITOR), shown)


def shown():
    result["editor"] = editor_texts()
    window_shot("gui-units-inch-property-editor.png")
    App.closeDocument(state["doc"].Name)
    finish()


state = {}


start(begin)
