"""The scan panel's collapsible "Recipe" section (SPEC §11): the document's ScanSettings recipe
(rule set, thickness and position windows, double threshold, thickness correction), shown and
edited where the scan is run. As the "Sensor and slow scan" section does, Apply writes the
properties in one undo step and reads the document back through the scan's readers, so a recipe
they refuse (a window whose min is not below its max) is refused here with their words and
nothing is written; Replay then scans with it. A limit left blank is not set: SPEC §4's rule
from t, Δt and Δp (shown greyed in the empty field)."""

from __future__ import annotations

from PySide import QtCore, QtGui

from ..cad.recipe_properties import NOT_SET
from ..core.errors import InputError
from ..core.mapping import RULE_SETS
from .sensor_section import settings_object

# (property, label): lengths in mm as the properties hold them; blank means not set.
LIMITS = (("ThicknessMin", "Thickness min (mm)"), ("ThicknessMax", "Thickness max (mm)"),
          ("DoubleThreshold", "Cross beyond (mm)"), ("PositionBelow", "Below seat (mm)"),
          ("PositionAbove", "Above seat (mm)"))
PROPERTIES = tuple(p for p, _ in LIMITS) + ("ThicknessCorrection", "Rules")


class RecipeSection:
    """The section's widgets; ``box`` goes into the panel. ``check(doc)`` is the readers' check
    (raises InputError); ``transaction(doc, name)`` one undo step that aborts when its block
    raises; ``applied`` is called after a change is written; ``plan`` the SlotPlan of the scan
    shown, whose resolved limits the blank fields show greyed."""

    def __init__(self, doc, check, transaction, applied=None, plan=None):
        self.doc, self.check, self.transaction, self.applied = doc, check, transaction, applied
        self.box = QtGui.QWidget()
        self.toggle = QtGui.QToolButton()
        self.toggle.setText("Recipe")
        self.toggle.setToolButtonStyle(QtCore.Qt.ToolButtonTextBesideIcon)
        self.toggle.setCheckable(True)
        self.toggle.setAutoRaise(True)
        self.toggle.setToolTip("Show and edit the mapping recipe of the document's ScanSettings "
                               "(SPEC §11)")
        self.body = QtGui.QWidget()
        form = QtGui.QFormLayout(self.body)
        form.setContentsMargins(0, 0, 0, 0)
        self.rules = QtGui.QComboBox()
        self.rules.addItems(list(RULE_SETS))
        self.rules.setToolTip("waferscan: a run by its bottom edge (SPEC §4); boundary: by its "
                              "centre and the slot boundaries (SPEC §11)")
        form.addRow("Rules", self.rules)
        defaults = {}
        if plan is not None:
            (low, high), (below, above) = plan.thickness_window(), plan.position_window()
            defaults = {"ThicknessMin": low, "ThicknessMax": high,
                        "DoubleThreshold": plan.double_limit(), "PositionBelow": below,
                        "PositionAbove": above}
        self.fields = {}
        for prop, label in LIMITS:
            field = QtGui.QLineEdit()
            if prop in defaults:
                field.setPlaceholderText(f"{defaults[prop]:g}")
            field.setToolTip(f"{label}; blank: SPEC §4's rule")
            self.fields[prop] = field
            form.addRow(label, field)
        self.correction = QtGui.QLineEdit()
        self.correction.setToolTip("Measured diffs are divided by this (a calibration's)")
        form.addRow("Thickness correction", self.correction)
        self.apply_button = QtGui.QPushButton("Apply")
        self.apply_button.setToolTip("Write the recipe to the document's ScanSettings (one undo "
                                     "step); the next Run scan or Replay judges by it")
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
        """Fill the fields from the ScanSettings object (without the recipe: disabled)."""
        obj = settings_object(self.doc)
        usable = obj is not None and all(p in obj.PropertiesList for p in PROPERTIES)
        self.body.setEnabled(usable)
        if not usable:
            self.message.setText("No ScanSettings with a recipe: Run scan adds one.")
            return
        for prop, _ in LIMITS:
            value = float(getattr(obj, prop))
            self.fields[prop].setText("" if value < 0.0 else f"{value:g}")
        self.correction.setText(f"{float(obj.ThicknessCorrection):g}")
        self.rules.setCurrentIndex(self.rules.findText(str(obj.Rules)))

    def values(self):
        """{property: value} as typed; ValueError naming the field when one is not a number."""
        values = {}
        for prop, label in LIMITS + (("ThicknessCorrection", "Thickness correction"),):
            field = self.fields.get(prop, self.correction)
            text = field.text().strip()
            if not text and prop != "ThicknessCorrection":
                values[prop] = NOT_SET
                continue
            try:
                values[prop] = float(text)
            except ValueError:
                raise ValueError(f"{label}: {text!r} is not a number") from None
        values["Rules"] = self.rules.currentText()
        return values

    def apply(self):
        """Write the fields to ScanSettings in one undo step, checked by the scan's readers;
        a refused recipe: the message says why and the document is left as it was. True when
        written."""
        obj = settings_object(self.doc)
        try:
            values = self.values()
        except ValueError as exc:
            return self._refused(str(exc))
        current = {prop: (str(obj.Rules) if prop == "Rules" else float(getattr(obj, prop)))
                   for prop in values}
        if current == values:
            self.message.setText("No change.")
            return False
        try:
            with self.transaction(self.doc, "WaferScan recipe"):
                for prop, value in values.items():
                    setattr(obj, prop, value)
                self.check(self.doc)  # the readers' own checks; raising aborts the transaction
        except InputError as exc:
            return self._refused(exc.message)
        changed = ", ".join(p for p in values if values[p] != current[p])
        self.message.setStyleSheet("")
        self.message.setText(f"Written: {changed}. Run scan or Replay to judge by them.")
        if self.applied is not None:
            self.applied()
        return True

    def _refused(self, why):
        self.message.setStyleSheet("color: #c01010;")
        self.message.setText(f"Not written: {why}")
        return False
