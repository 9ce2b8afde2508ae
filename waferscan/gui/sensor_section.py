"""The scan panel's collapsible "Sensor and slow scan" section (issues 14 and 17): the
document's ScanSettings values of the beam spot, the amplifier's thresholds, the latch, the
jab and the sweep, shown and edited where the scan is run. Apply writes them to the ScanSettings
object's properties in one undo step and reads the document back through the scan's own
readers, so a value they refuse is refused here the same way (nothing written); the next Run
scan or Replay scans with them."""

from __future__ import annotations

from PySide import QtGui

from ..core.sensor.motion import LATCHES
from .inputs import QuantityField, normalise
from .settings_section import SettingsSection, settings_object

# (property, label, kind): the lengths, the acceleration and the sweep's angle are quantities in
# the user's unit schema (typed in any unit), the read period a time in s, ms or µs (FreeCAD 0.20
# has no time unit), the thresholds bare fractions. The slit's sizes, the stroke's acceleration
# (0: full speed at once) and the read period (needed by latch = sampled) complete SPEC §10's
# settings.
FIELDS = (("SpotDiameter", "Spot ⌀", "length"), ("SpotWidth", "Slit width", "length"),
          ("SpotHeight", "Slit height", "length"), ("ThresholdOn", "On at", "number"),
          ("ThresholdOff", "Off at", "number"), ("Acceleration", "Acceleration", "acceleration"),
          ("SamplePeriod", "Sample period", "time"), ("Jab", "Jab", "length"),
          ("Sweep", "Sweep", "angle"))


def _number(value):
    return float(getattr(value, "Value", value))


class SensorSection(SettingsSection):
    """The section's widgets (``settings_section.SettingsSection``)."""

    title = "Sensor and slow scan"
    tip = ("Show the beam spot, thresholds, latch, jab and sweep of the document's ScanSettings "
           "(SPEC §10, §13)")
    apply_tip = ("Write these values to the document's ScanSettings (one undo step); the next "
                 "Run scan or Replay uses them")
    undo_name = "WaferScan sensor and slow scan"
    missing = "No ScanSettings with these properties: Run scan adds them."
    written = "Run scan or Replay to scan with them."
    properties = tuple(p for p, _, _ in FIELDS)

    def build(self, form):
        self.fields = {}
        obj = settings_object(self.doc)
        for prop, label, kind in FIELDS:
            tip = obj.getDocumentationOfProperty(prop) if obj is not None and \
                prop in obj.PropertiesList else prop
            if kind == "number":
                field = QtGui.QLineEdit()
                field.setToolTip(tip)
            else:
                field = QuantityField(kind, 0.0, tip, maximum=float("inf"))
            self.fields[prop] = field
            form.addRow(label, field)
        self.latch = QtGui.QComboBox()
        self.latch.addItems(list(LATCHES))
        self.latch.setToolTip("Where an edge is latched: step, encoder or sampled")
        form.addRow("Latch", self.latch)

    def fill(self, obj):
        for prop, _, kind in FIELDS:
            value = _number(getattr(obj, prop))
            if kind == "number":
                self.fields[prop].setText(f"{value:g}")
            else:
                self.fields[prop].set_value(value)
        self.latch.setCurrentIndex(self.latch.findText(str(obj.Latch)))

    def values(self):
        """{property: value} typed in the fields (mm, mm/s², degrees, s); ValueError naming the
        field when one is not a number (a quantity of its kind for the quantity fields)."""
        values = {}
        for prop, label, kind in FIELDS:
            field = self.fields[prop]
            try:
                values[prop] = float(normalise(field.text())) if kind == "number" else \
                    field.value()
            except ValueError as exc:
                why = f"{field.text()!r} is not a number" if kind == "number" else str(exc)
                raise ValueError(f"{label}: {why}") from None
        values["Latch"] = self.latch.currentText()
        return values

    def current(self, obj, prop):
        return str(obj.Latch) if prop == "Latch" else _number(getattr(obj, prop))
