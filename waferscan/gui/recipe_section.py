"""The scan panel's collapsible "Recipe" section (SPEC §11): the document's ScanSettings recipe
(rule set, thickness and position windows, double threshold, thickness correction), shown and
edited where the scan is run. As the "Sensor and slow scan" section does, Apply writes the
properties in one undo step and reads the document back through the scan's readers, so a recipe
they refuse (a window whose min is not below its max) is refused here with their words and
nothing is written; Replay then scans with it. A limit left blank is not set: SPEC §4's rule
from t, Δt and Δp (shown greyed in the empty field)."""

from __future__ import annotations

from PySide import QtGui

from ..cad.recipe_properties import NOT_SET
from ..core.mapping import RULE_SETS
from .settings_section import SettingsSection

# (property, label): lengths in mm as the properties hold them; blank means not set.
LIMITS = (("ThicknessMin", "Thickness min (mm)"), ("ThicknessMax", "Thickness max (mm)"),
          ("DoubleThreshold", "Cross beyond (mm)"), ("PositionBelow", "Below seat (mm)"),
          ("PositionAbove", "Above seat (mm)"))
PROPERTIES = tuple(p for p, _ in LIMITS) + ("ThicknessCorrection", "Rules")


class RecipeSection(SettingsSection):
    """The section's widgets (``settings_section.SettingsSection``); ``plan`` is the SlotPlan
    of the scan shown, whose resolved limits the blank fields show greyed."""

    title = "Recipe"
    tip = "Show and edit the mapping recipe of the document's ScanSettings (SPEC §11)"
    apply_tip = ("Write the recipe to the document's ScanSettings (one undo step); the next "
                 "Run scan or Replay judges by it")
    undo_name = "WaferScan recipe"
    missing = "No ScanSettings with a recipe: Run scan adds one."
    written = "Run scan or Replay to judge by them."
    properties = PROPERTIES

    def __init__(self, doc, check, transaction, applied=None, plan=None):
        self.plan = plan
        super().__init__(doc, check, transaction, applied)

    def build(self, form):
        self.rules = QtGui.QComboBox()
        self.rules.addItems(list(RULE_SETS))
        self.rules.setToolTip("waferscan: a run by its bottom edge (SPEC §4); boundary: by its "
                              "centre and the slot boundaries (SPEC §11)")
        form.addRow("Rules", self.rules)
        defaults = {}
        if self.plan is not None:
            plan = self.plan
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

    def fill(self, obj):
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

    def current(self, obj, prop):
        return str(obj.Rules) if prop == "Rules" else float(getattr(obj, prop))
