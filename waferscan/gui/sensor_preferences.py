"""The sensor defaults on the workbench's preferences page (SPEC §10): the beam spot, the
amplifier's thresholds, the latch, the stroke's acceleration, the controller's read period and
the sensor's response time that a NEW scan-settings object gets when the workbench makes one (a
new layout, a scenario that does not set them, Run scan on a document without ScanSettings). A
document that already has its settings keeps them. Unset, they are the paper's ideal sensor, so
nothing changes for a user who never touches them. Stored in FreeCAD's parameters beside the
other preferences (``Mod/WaferScan``); headless runs (the command line) do not read them, as
they do not read the preferred tolerances.
"""

from __future__ import annotations

import FreeCAD as App
from PySide import QtGui

from ..core import schema
from ..core.sensor import settings as sensor_settings
from ..core.sensor.motion import LATCHES, SAMPLED, STEP
from .inputs import QuantityField, mark, marked_row, normalise

PARAMETERS = "User parameter:BaseApp/Preferences/Mod/WaferScan"
SHAPES = ("line", "round", "slit")  # the ideal line, spot_diameter, spot_width x spot_height
# The parameters' names and their values when unset (the ideal sensor). Acceleration 0 means
# infinite (full speed at once), as on the ScanSettings object; times are stored in s.
STORED = {"SpotDiameter": 0.0, "SpotWidth": 0.0, "SpotHeight": 0.0, "ThresholdOn": 0.5,
          "ThresholdOff": 0.5, "Acceleration": 0.0, "SamplePeriod": 0.0,
          "SensorResponse": 0.0}
KEYS = {"SpotDiameter": "spot_diameter", "SpotWidth": "spot_width", "SpotHeight": "spot_height",
        "ThresholdOn": "threshold_on", "ThresholdOff": "threshold_off",
        "Acceleration": "acceleration", "SamplePeriod": "sample_period",
        "SensorResponse": "sensor_response"}


def _group():
    return App.ParamGet(PARAMETERS)


def stored_values():
    """The sensor preferences as stored: {parameter name: value}, SpotShape and Latch as text."""
    group = _group()
    values = {name: group.GetFloat(name, default) for name, default in STORED.items()}
    values["SpotShape"] = group.GetString("SpotShape", "line")
    values["Latch"] = group.GetString("Latch", STEP)
    return values


def defaults_from(stored):
    """Stored preferences -> the §10 values (and sensor_response) that differ from the ideal
    sensor, keyed as in ``core.sensor.settings``; ValueError naming the preference when one is
    refused, alone or with the others."""
    values = {}
    shape = stored["SpotShape"]
    if shape not in SHAPES:
        raise ValueError(f"spot shape {shape!r} is not one of {', '.join(SHAPES)}")
    spot = {"line": (), "round": ("SpotDiameter",), "slit": ("SpotWidth", "SpotHeight")}[shape]
    for name in spot:
        values[KEYS[name]] = _checked(name, stored[name], schema.positive)
    on = _checked("ThresholdOn", stored["ThresholdOn"], sensor_settings.fraction)
    off = _checked("ThresholdOff", stored["ThresholdOff"], sensor_settings.fraction)
    if off > on:
        raise ValueError(f"threshold OFF {off:g} must not exceed threshold ON {on:g}")
    if on != 0.5 or off != on:
        values["threshold_on"] = on
        if off != on:
            values["threshold_off"] = off
    latch = stored["Latch"]
    if latch not in LATCHES:
        raise ValueError(f"latch {latch!r} is not one of {', '.join(LATCHES)}")
    if latch != STEP:
        values["latch"] = latch
    if latch == SAMPLED:
        values["sample_period"] = _checked("SamplePeriod", stored["SamplePeriod"],
                                           schema.positive)
    if stored["Acceleration"] != 0.0:
        values["acceleration"] = _checked("Acceleration", stored["Acceleration"],
                                          schema.positive)
    if stored["SensorResponse"] != 0.0:
        values["sensor_response"] = _checked("SensorResponse", stored["SensorResponse"],
                                             schema.non_negative)
    return values


def _checked(name, value, check):
    try:
        return check(value)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None


def sensor_defaults():
    """The preferred §10 defaults for a new scan-settings object (empty: the ideal sensor). A
    preference refused (set by hand in the parameter editor) is reported in the report view and
    the ideal sensor used instead."""
    try:
        return defaults_from(stored_values())
    except ValueError as exc:
        App.Console.PrintWarning(f"WaferScan preferences: sensor defaults not used: {exc}\n")
        return {}


def store(values):
    """Store sensor preferences given as {parameter name: value} (SpotShape, Latch as text)."""
    group = _group()
    for name, value in values.items():
        if name in ("SpotShape", "Latch"):
            group.SetString(name, str(value))
        else:
            group.SetFloat(name, float(value))


class UnitField(QtGui.QLineEdit):
    """A number in a fixed unit (a threshold's fraction "of the spot"), shown as "0.5 of the
    spot" and typed with or without the unit. Like inputs.QuantityField it keeps the exact value
    it was given until the user edits the text (a dialog merely accepted changes nothing)."""

    def __init__(self, unit, scale=1.0, tooltip=""):
        super().__init__()
        self.unit, self.scale = unit, scale  # the stored value is the shown number x scale
        self._exact, self._text_shown = 0.0, None
        if tooltip:
            self.setToolTip(tooltip)

    def set_value(self, value):
        self._exact = float(value)
        number = f"{self._exact / self.scale:.6g}"
        self._text_shown = f"{number} {self.unit}".strip()
        self.setText(self._text_shown)

    def value(self):
        """The stored value; ValueError when the typed text is not a number in this unit."""
        if self.text() == self._text_shown:
            return self._exact
        text = normalise(self.text())
        if self.unit and text.endswith(self.unit):
            text = text[:-len(self.unit)].strip()
        try:
            number = float(text)
        except ValueError:
            raise ValueError(f"{self.text().strip()!r} is not a number"
                             + (f" in {self.unit}" if self.unit else "")) from None
        return number * self.scale


class SensorDefaultsBox:
    """The preferences page's group of sensor defaults; ``box`` goes on the page."""

    def __init__(self):
        self.box = QtGui.QGroupBox("Sensor (new scan settings; a document keeps its own)")
        form = QtGui.QFormLayout(self.box)
        self.shape = QtGui.QComboBox()
        self.shape.addItems(["line (ideal beam)", "round spot", "slit spot"])
        self.shape.setToolTip("The beam's cross-section: the paper's ideal line, a round spot "
                              "(diameter) or a slit (width x height)")
        form.addRow("Beam spot", self.shape)
        self.diameter = QuantityField("length", 0.0, "Diameter of a round beam spot")
        self.width = QuantityField("length", 0.0, "Width of a slit beam spot")
        self.height = QuantityField("length", 0.0, "Height of a slit beam spot (along the lift)")
        self.on = UnitField("of the spot", tooltip="Blocked fraction of the spot at which the "
                            "amplifier's output turns ON (0.5: half the spot)")
        self.off = UnitField("of the spot", tooltip="Blocked fraction below which the output "
                             "turns OFF again; below ON: hysteresis")
        self.latch = QtGui.QComboBox()
        self.latch.addItems(list(LATCHES))
        self.latch.setToolTip("step: edges on the step grid (the paper); encoder: latched in "
                              "motion after the sensor's response; sampled: at the "
                              "controller's next read")
        self.acceleration = QuantityField("acceleration", 0.0, "Acceleration of the scan "
                                          "stroke (encoder and sampled latching); 0: full "
                                          "speed at once", maximum=float("inf"))
        self.sample_period = QuantityField("time", 0.0, "How often the controller reads the "
                                           "sensor (latch = sampled)", maximum=float("inf"))
        self.response = QuantityField("time", 0.0, "The sensor's response time: an edge is "
                                      "latched this late, at the scan speed",
                                      maximum=float("inf"))
        # Each field with the reason beside it when its text is refused (inputs.marked_row).
        self.reasons, self.labels = {}, {}
        for label, field in (("Spot diameter", self.diameter), ("Spot width", self.width),
                             ("Spot height", self.height), ("Threshold ON", self.on),
                             ("Threshold OFF", self.off), ("Latch", self.latch),
                             ("Acceleration", self.acceleration),
                             ("Sample period", self.sample_period),
                             ("Sensor response", self.response)):
            form.addRow(label, field if field is self.latch else marked_row(field, self.reasons))
            self.labels[field] = label
        self.fields = {"SpotDiameter": self.diameter, "SpotWidth": self.width,
                       "SpotHeight": self.height, "ThresholdOn": self.on,
                       "ThresholdOff": self.off, "Acceleration": self.acceleration,
                       "SamplePeriod": self.sample_period, "SensorResponse": self.response}
        for name, widget in {**self.fields, "SpotShape": self.shape, "Latch": self.latch}.items():
            widget.setObjectName(name)  # for scripts and tests
        self.shape.currentIndexChanged.connect(self._enable)
        self.latch.currentIndexChanged.connect(self._enable)

    def _enable(self, *_):
        shape = SHAPES[self.shape.currentIndex()]
        self.diameter.setEnabled(shape == "round")
        self.width.setEnabled(shape == "slit")
        self.height.setEnabled(shape == "slit")
        self.sample_period.setEnabled(self.latch.currentText() == SAMPLED)

    def load(self):
        stored = stored_values()
        shape = stored["SpotShape"]
        self.shape.setCurrentIndex(SHAPES.index(shape) if shape in SHAPES else 0)
        latch = self.latch.findText(stored["Latch"])
        self.latch.setCurrentIndex(max(latch, 0))
        for name, field in self.fields.items():
            field.set_value(stored[name])
        self._enable()

    def shown(self):
        """{parameter name: value} as the fields show them; ValueError naming the field."""
        values = {"SpotShape": SHAPES[self.shape.currentIndex()],
                  "Latch": self.latch.currentText()}
        for name, field in self.fields.items():
            try:
                values[name] = field.value()
            except ValueError as exc:
                raise ValueError(f"{self.labels[field]}: {exc}") from None
        return values

    def problems(self):
        """{field: why} for each field whose text is refused, alone or with the others (OFF
        above ON, a round spot of no size...); the fields are marked with their reasons."""
        problems = {}
        values = stored_values()  # a refused field's stored value, to check the others with
        values.update(SpotShape=SHAPES[self.shape.currentIndex()],
                      Latch=self.latch.currentText())
        for name, field in self.fields.items():
            try:
                values[name] = field.value()
            except ValueError as exc:
                problems[field] = str(exc)
        try:
            defaults_from(values)
        except ValueError as exc:
            field = self._field_of(str(exc))
            if field not in problems:
                problems[field] = str(exc).partition(": ")[2] \
                    if str(exc).split(":")[0] in self.fields else str(exc)
        for field, reason in self.reasons.items():
            mark(field, reason, problems.get(field))
        return problems

    def _field_of(self, message):
        """The field a refusal of ``defaults_from`` is about."""
        name = message.split(":")[0]
        if name in self.fields:
            return self.fields[name]
        return self.off if message.startswith("threshold OFF") else self.on

    def changed(self):
        """{parameter name: value} of the fields that differ from what is stored (a field left
        alone holds exactly what was loaded, so it is not among them)."""
        stored = stored_values()
        return {name: value for name, value in self.shown().items() if value != stored[name]}

    def save(self):
        """Store the fields that changed, when the sensor defaults they make are sound (the page
        keeps OK from being pressed otherwise); False when refused."""
        if self.problems():
            return False
        store(self.changed())
        return True
