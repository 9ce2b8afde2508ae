"""The scan panel's collapsible "Sensor and slow scan" section (issues 14 and 17): the
document's ScanSettings values of the beam spot, the amplifier's thresholds, the latch, the
jab and the sweep, shown and edited where the scan is run. Apply writes those changed to the
ScanSettings object's properties in one undo step, as the recorded line
``apply_sensor_settings(App.getDocument('X'), threshold_on=0.7, jab=App.Units.Quantity('2.0 mm'))``
(what a macro replays), and reads the document back through the scan's own readers, so a value
they refuse is refused here the same way (nothing written); the next Run scan or Replay scans
with them."""

from __future__ import annotations

from PySide import QtGui

from ..cad.role_properties import PLAIN_NAMES, from_property, to_property
from ..core.errors import InputError
from ..core.sensor.motion import LATCHES
from .inputs import QuantityField, normalise, value_in
from .session import doc_ref
from .settings_section import (SettingsSection, keyword, quantity_ref, settings_object,
                               write_settings)

__all__ = ["SensorSection", "apply_sensor_settings"]

# (property, label, kind): the lengths, the acceleration and the sweep's angle are quantities in
# the user's unit schema (typed in any unit), the read period a time in s, ms or µs (FreeCAD 0.20
# has no time unit; the property, SamplePeriodMs, holds ms), the thresholds bare fractions. The slit's sizes, the stroke's acceleration
# (0: full speed at once) and the read period (needed by latch = sampled) complete SPEC §10's
# settings.
FIELDS = (("SpotDiameter", "Spot ⌀", "length"), ("SpotWidth", "Slit width", "length"),
          ("SpotHeight", "Slit height", "length"), ("ThresholdOn", "On at", "number"),
          ("ThresholdOff", "Off at", "number"), ("Acceleration", "Acceleration", "acceleration"),
          ("SamplePeriodMs", "Sample period", "time"), ("Jab", "Jab", "length"),
          ("Sweep", "Sweep", "angle"))
# Each kind's unit in a recorded line (the properties' own); thresholds are bare fractions.
UNITS = {"length": "mm", "acceleration": "mm/s^2", "time": "s", "angle": "deg", "number": ""}
# A property's keyword in a recorded line: its name without the unit (sample_period, in s).
KEYWORDS = {keyword(PLAIN_NAMES.get(prop, prop)): (prop, kind) for prop, _, kind in FIELDS}
UNDO_NAME = "WaferScan sensor and slow scan"
MISSING = "No ScanSettings with these properties: Run scan adds them."


def _number(value):
    return float(getattr(value, "Value", value))


def _shown(prop, value):
    """A field's value (a time in s) for a property's (SamplePeriodMs in ms)."""
    return from_property(prop, value)


class SensorSection(SettingsSection):
    """The section's widgets (``settings_section.SettingsSection``)."""

    title = "Sensor and slow scan"
    tip = ("Show the beam spot, thresholds, latch, jab and sweep of the document's ScanSettings "
           "(SPEC §10, §13)")
    apply_tip = ("Write these values to the document's ScanSettings (one undo step); the next "
                 "Run scan or Replay uses them")
    undo_name = UNDO_NAME
    missing = MISSING
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
            value = _shown(prop, getattr(obj, prop))
            if kind == "number":
                self.fields[prop].setText(f"{value:g}")
            else:
                self.fields[prop].set_value(value)
        self.latch.setCurrentIndex(self.latch.findText(str(obj.Latch)))

    def values(self):
        """{property: value} typed in the fields, in the properties' units (mm, mm/s², degrees,
        ms); ValueError naming the field when one is not a number (a quantity of its kind for the
        quantity fields)."""
        values = {}
        for prop, label, kind in FIELDS:
            field = self.fields[prop]
            try:
                values[prop] = float(normalise(field.text())) if kind == "number" else \
                    to_property(prop, field.value())
            except ValueError as exc:
                why = f"{field.text()!r} is not a number" if kind == "number" else str(exc)
                raise ValueError(f"{label}: {why}") from None
        values["Latch"] = self.latch.currentText()
        return values

    def current(self, obj, prop):
        return str(obj.Latch) if prop == "Latch" else _number(getattr(obj, prop))

    def call(self, values, changed):
        """The recorded line writing the ``changed`` properties of ``values``."""
        arguments = [doc_ref(self.doc)]
        kinds = {prop: kind for prop, _, kind in FIELDS}
        for prop in changed:
            kind = kinds.get(prop)
            value = values[prop] if kind is None else _shown(prop, values[prop])
            text = repr(value) if kind in (None, "number") else quantity_ref(value, UNITS[kind])
            arguments.append(f"{keyword(PLAIN_NAMES.get(prop, prop))}={text}")
        return f"apply_sensor_settings({', '.join(arguments)})"


def apply_sensor_settings(doc, **settings):
    """Write the sensor's and the slow scan's settings to the document's ScanSettings, as the
    scan panel's "Sensor and slow scan" section's Apply does (and records), in one undo step
    named "WaferScan sensor and slow scan"; the next Run scan or Replay scans with them. Only
    the settings given are written: ``spot_diameter``, ``spot_width``, ``spot_height``, ``jab``
    (lengths), ``acceleration``, ``sweep`` (an angle), ``sample_period`` (a time, in s) as
    FreeCAD quantities (``App.Units.Quantity('0.5 mm')``) or bare numbers in mm, mm/s², degrees
    and s; ``threshold_on``, ``threshold_off`` (blocked fractions) and ``latch`` ("step",
    "encoder" or "sampled"). A value the scan's readers refuse raises their InputError and
    nothing is written. Returns the properties changed."""
    values = {}
    for name, value in settings.items():
        if name == "latch":
            if value not in LATCHES:
                raise InputError("latch", None, f"{value!r} is not one of {', '.join(LATCHES)}")
            values["Latch"] = str(value)
            continue
        if name not in KEYWORDS:
            raise InputError(name, None, "not a setting of the sensor or the slow scan (one of "
                                         f"{', '.join([*KEYWORDS, 'latch'])})")
        prop, kind = KEYWORDS[name]
        values[prop] = to_property(prop, value_in(value, UNITS[kind], name))
    return write_settings(doc, values, UNDO_NAME, MISSING)
