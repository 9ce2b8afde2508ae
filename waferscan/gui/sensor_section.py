"""The scan panel's collapsible "Sensor and slow scan" section (issues 14 and 17): the
document's ScanSettings values of the beam spot, the amplifier's thresholds, the latch, the
jab and the sweep, shown and edited where the scan is run. Apply writes them to the ScanSettings
object's properties in one undo step and reads the document back through the scan's own
readers, so a value they refuse is refused here the same way (nothing written); the next Run
scan or Replay scans with them."""

from __future__ import annotations

from PySide import QtCore, QtGui

from ..cad.reader import DocumentScene
from ..cad.roles import role_holder
from ..core.errors import InputError
from ..core.motion import LATCHES
from .inputs import length_input

# (property, label, kind): "length" fields take a unit (the user's by default), "number"
# fields a bare number (the thresholds are fractions, the sweep is in degrees).
# The slit's sizes, the stroke's acceleration (mm/s², 0: full speed at once) and the read period
# (s, needed by latch = sampled) complete SPEC §10's settings.
FIELDS = (("SpotDiameter", "Spot ⌀", "length"), ("SpotWidth", "Slit width", "length"),
          ("SpotHeight", "Slit height", "length"), ("ThresholdOn", "On at", "number"),
          ("ThresholdOff", "Off at", "number"), ("Acceleration", "Acc. mm/s²", "number"),
          ("SamplePeriod", "Sample s", "number"), ("Jab", "Jab", "length"),
          ("Sweep", "Sweep °", "number"))


def settings_object(doc):
    """The document's one ScanSettings object (the one holding the properties), or None."""
    scene = DocumentScene.of(doc)
    if len(scene.settings) != 1:
        return None
    return role_holder(scene.settings[0].obj)


def _number(value):
    return float(getattr(value, "Value", value))


class SensorSection:
    """The section's widgets; ``box`` goes into the panel. ``check(doc)`` is the readers' check
    (raises InputError for a value they refuse); ``transaction(doc, name)`` the context of one
    undo step (commands.transaction, which aborts when its block raises); ``applied`` is called
    after a change is written."""

    def __init__(self, doc, check, transaction, applied=None):
        self.doc, self.check, self.applied = doc, check, applied
        self.transaction = transaction
        self.box = QtGui.QWidget()
        self.toggle = QtGui.QToolButton()
        self.toggle.setText("Sensor and slow scan")
        self.toggle.setToolButtonStyle(QtCore.Qt.ToolButtonTextBesideIcon)
        self.toggle.setCheckable(True)
        self.toggle.setAutoRaise(True)
        self.toggle.setToolTip("Show the beam spot, thresholds, latch, jab and sweep of the "
                               "document's ScanSettings (SPEC §10, §13)")
        self.body = QtGui.QWidget()
        form = QtGui.QFormLayout(self.body)
        form.setContentsMargins(0, 0, 0, 0)
        self.fields = {}
        obj = settings_object(doc)
        for prop, label, kind in FIELDS:
            tip = obj.getDocumentationOfProperty(prop) if obj is not None and \
                prop in obj.PropertiesList else prop
            field = length_input(0.0, tip) if kind == "length" else QtGui.QLineEdit()
            if kind != "length":
                field.setToolTip(tip)
            self.fields[prop] = field
            form.addRow(label, field)
        self.latch = QtGui.QComboBox()
        self.latch.addItems(list(LATCHES))
        self.latch.setToolTip("Where an edge is latched: step, encoder or sampled")
        form.addRow("Latch", self.latch)
        self.apply_button = QtGui.QPushButton("Apply")
        self.apply_button.setToolTip("Write these values to the document's ScanSettings (one "
                                     "undo step); the next Run scan or Replay uses them")
        form.addRow(self.apply_button)
        self.message = QtGui.QLabel("")
        self.message.setWordWrap(True)
        form.addRow(self.message)
        outer = QtGui.QVBoxLayout(self.box)
        outer.setContentsMargins(0, 0, 0, 0)
        outer.addWidget(self.toggle)
        outer.addWidget(self.body)
        self.toggle.toggled.connect(self._shown)
        self.apply_button.clicked.connect(self.apply)
        self.load()
        self._shown(False)

    def _shown(self, shown):
        self.body.setVisible(shown)
        self.toggle.setArrowType(QtCore.Qt.DownArrow if shown else QtCore.Qt.RightArrow)

    def load(self):
        """Fill the fields from the ScanSettings object (absent: the section is disabled)."""
        obj = settings_object(self.doc)
        usable = obj is not None and all(p in obj.PropertiesList for p, _, _ in FIELDS)
        self.body.setEnabled(usable)
        if not usable:
            self.message.setText("No ScanSettings with these properties: Run scan adds them.")
            return
        for prop, _, kind in FIELDS:
            value = _number(getattr(obj, prop))
            if kind == "length":
                self.fields[prop].set_mm(value)
            else:
                self.fields[prop].setText(f"{value:g}")
        self.latch.setCurrentIndex(self.latch.findText(str(obj.Latch)))

    def values(self):
        """{property: value} typed in the fields; ValueError naming the field when one is not a
        number (a length for the length fields)."""
        values = {}
        for prop, label, kind in FIELDS:
            field = self.fields[prop]
            try:
                values[prop] = field.value_mm() if kind == "length" else float(field.text())
            except ValueError:
                raise ValueError(f"{label.rstrip(' °')}: {field.text()!r} is not a "
                                 f"{'length' if kind == 'length' else 'number'}") from None
        values["Latch"] = self.latch.currentText()
        return values

    def apply(self):
        """Write the fields to ScanSettings in one undo step, checked by the scan's readers;
        a refused value: the message says why and the document is left as it was. True when
        written."""
        obj = settings_object(self.doc)
        try:
            values = self.values()
        except ValueError as exc:
            return self._refused(str(exc))
        current = {prop: (_number(getattr(obj, prop)) if prop != "Latch" else str(obj.Latch))
                   for prop in values}
        if current == values:
            self.message.setText("No change.")
            return False
        try:
            with self.transaction(self.doc, "WaferScan sensor and slow scan"):
                for prop, value in values.items():
                    setattr(obj, prop, value)
                self.check(self.doc)  # the readers' own checks; raising aborts the transaction
        except InputError as exc:
            return self._refused(exc.message)  # the fields keep the typed text, to correct
        changed = ", ".join(p for p in values if values[p] != current[p])
        self.message.setStyleSheet("")
        self.message.setText(f"Written: {changed}. Run scan or Replay to scan with them.")
        if self.applied is not None:
            self.applied()
        return True

    def _refused(self, why):
        self.message.setStyleSheet("color: #c01010;")
        self.message.setText(f"Not written: {why}")
        return False
