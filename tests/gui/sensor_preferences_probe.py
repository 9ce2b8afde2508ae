# Run by FreeCAD's GUI (tests/gui/test_gui_sensor_preferences.py): the sensor defaults on the
# WaferScan preferences page, set as a user sets them (the dialog's fields, OK), then a new
# paper layout and Run scan's new ScanSettings on a document without one get them, while a
# document built before keeps its own values; defaults that do not fit together grey OK out.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    accept_preferences, artifact, finish, later, result, start)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

PARAMETERS = "User parameter:BaseApp/Preferences/Mod/WaferScan"
NAMES = ("SpotDiameter", "SpotWidth", "SpotHeight", "ThresholdOn", "ThresholdOff",
         "Acceleration", "SamplePeriod", "SensorResponse")
# What the user types (text), by field name; SpotShape and Latch are combo boxes.
TYPED = {"SpotDiameter": "1 mm", "ThresholdOn": "0.6", "ThresholdOff": "0.4",
         "Acceleration": "2000 mm/s²", "SensorResponse": "0.25 ms"}


def settings_values(doc):
    """The ScanSettings object's §10 properties and SensorResponse, as numbers and text, by
    the preferences' names and in their units (the document's times are in ms, named so)."""
    from waferscan.cad.role_properties import PLAIN_NAMES, from_property
    obj = doc.getObject("ScanSettings")
    values = {}
    for name in NAMES:
        prop = next((p for p, plain in PLAIN_NAMES.items() if plain == name), name)
        if prop in obj.PropertiesList:
            values[name] = from_property(prop, getattr(obj, prop))
    values["Latch"] = str(obj.Latch) if "Latch" in obj.PropertiesList else None
    return values


def read_back(doc):
    """What the scan's reader makes of the document: spot, thresholds, latch, response."""
    from waferscan.cad.reader import read_layout
    layout = read_layout(doc)
    spot = layout.spot
    return {"spot": None if spot is None else [spot.diameter, spot.width, spot.height],
            "amplifier": None if layout.amplifier is None else
            [layout.amplifier.threshold_on, layout.amplifier.threshold_off],
            "latch": layout.scan.latch, "acceleration": layout.scan.acceleration,
            "sensor_response": layout.scan.sensor_response}


def stored():
    group = App.ParamGet(PARAMETERS)
    values = {name: group.GetFloat(name) for name in NAMES}
    values.update(SpotShape=group.GetString("SpotShape"), Latch=group.GetString("Latch"))
    return values


def open_preferences(key, edit, then):
    """Open the preferences with the workbench's command; on the WaferScan page record the
    sensor fields' texts, set ``edit`` (None: leave the page alone) and click OK."""

    def on_page(dialog):
        shape = dialog.findChild(QtGui.QComboBox, "SpotShape")
        latch = dialog.findChild(QtGui.QComboBox, "Latch")
        fields = {name: dialog.findChild(QtGui.QLineEdit, name) for name in NAMES}
        frame = dialog.frameGeometry()
        screen = QtGui.QApplication.desktop().availableGeometry(dialog)
        result[key] = {"texts": {name: f.text() for name, f in fields.items()},
                       "shape": shape.currentText(), "latch": latch.currentText(),
                       "diameter_enabled": fields["SpotDiameter"].isEnabled(),
                       "fits": screen.contains(frame)}
        if edit == "bad":  # OFF above ON: refused in place (OK greyed), so the user cancels
            fields["ThresholdOff"].setText("0.9")
            fields["SpotDiameter"].setText("3 mm")
            QtGui.QApplication.processEvents()
            ok = [b for b in dialog.findChildren(QtGui.QPushButton)
                  if b.text().replace("&", "") in ("OK", "Cancel")]
            result[key]["ok_enabled"] = [b.isEnabled() for b in ok if "OK" in b.text()]
            next(b for b in ok if "Cancel" in b.text()).click()
        elif edit:
            shape.setCurrentIndex(1)  # round spot
            latch.setCurrentIndex(latch.findText("encoder"))
            result[key]["diameter_enabled_after"] = fields["SpotDiameter"].isEnabled()
            for name, text in TYPED.items():
                fields[name].setText(text)
            QtGui.QApplication.processEvents()
            page = shape.parentWidget()
            page.grab().save(artifact("gui-preferences-sensor.png"))

    accept_preferences(on_page)
    result[key]["stored"] = stored()
    later(then, 50)


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    result["existing_name"] = App.ActiveDocument.Name
    result["existing_before"] = settings_values(App.ActiveDocument)
    open_preferences("first", edit=True, then=new_layout)


def new_layout():
    Gui.runCommand("WaferScan_NewPaperLayout")
    doc = App.ActiveDocument
    result["new_name"] = doc.Name
    result["new"] = settings_values(doc)
    result["new_read"] = read_back(doc)
    existing = App.getDocument(result["existing_name"])
    result["existing_after"] = settings_values(existing)
    result["existing_read"] = read_back(existing)
    # A document of its own without ScanSettings (tagged solids, say): Run scan adds one.
    from waferscan.gui.scanning import ensure_settings
    bare = App.getDocument(result["existing_name"])
    bare.removeObject("ScanSettings")
    ensure_settings(bare)
    result["added"] = settings_values(bare)
    result["added_read"] = read_back(bare)
    open_preferences("untouched", edit=False, then=refused)


def refused():
    open_preferences("refused", edit="bad", then=by_hand)


def by_hand():
    """A value set by hand in the parameter editor that the page would refuse."""
    from waferscan.gui import preferences
    result["defaults_before"] = preferences.sensor_defaults()
    App.ParamGet(PARAMETERS).SetFloat("ThresholdOn", 2.0)
    result["defaults_by_hand"] = preferences.sensor_defaults()
    finish()


start(begin)
