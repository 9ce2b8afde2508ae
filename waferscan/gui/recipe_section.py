"""The scan panel's collapsible "Recipe" section (SPEC §11): the document's ScanSettings recipe
(rule set, thickness and position windows, double threshold, thickness correction), shown and
edited where the scan is run. As the "Sensor and slow scan" section does, Apply writes the
properties changed in one undo step, as the recorded line
``apply_recipe(App.getDocument('X'), thickness_min=App.Units.Quantity('0.66 mm'), rules='boundary')``
(what a macro replays), and reads the document back through the scan's readers, so a recipe
they refuse (a window whose min is not below its max) is refused here with their words and
nothing is written; Replay then scans with it. The limits are lengths in the user's unit
schema (typed in any unit); a limit left blank is not set (its "...Set" box in the property
editor unticked): SPEC §4's rule from t, Δt and Δp, shown greyed in the empty field. A document
saved by an earlier version (limits as floats, negative: not set) is shown and written in its
own convention."""

from __future__ import annotations

from PySide import QtGui

from ..cad import recipe_properties
from ..cad.recipe_properties import OLD_NOT_SET, holds_old_limits, limit_value, set_flag
from ..core.errors import InputError
from ..core.mapping import RULE_SETS
from .inputs import QuantityField, format_length, normalise, value_in
from .session import doc_ref
from .settings_section import (SettingsSection, keyword, quantity_ref, settings_object,
                               write_settings)

__all__ = ["RecipeSection", "apply_recipe"]

# (property, label): lengths in the user's unit; blank means not set.
LABELS = {"ThicknessMin": "Thickness min", "ThicknessMax": "Thickness max",
          "DoubleThreshold": "Cross beyond", "PositionBelow": "Below seat",
          "PositionAbove": "Above seat"}
LIMITS = tuple((prop, LABELS[prop]) for prop in recipe_properties.LIMITS)
PROPERTIES = tuple(p for p, _ in LIMITS) + ("ThicknessCorrection", "Rules")
UNDO_NAME = "WaferScan recipe"
MISSING = "No ScanSettings with a recipe: Run scan adds one."


class RecipeSection(SettingsSection):
    """The section's widgets (``settings_section.SettingsSection``); ``plan`` is the SlotPlan
    of the scan shown, whose resolved limits the blank fields show greyed."""

    title = "Recipe"
    tip = "Show and edit the mapping recipe of the document's ScanSettings (SPEC §11)"
    apply_tip = ("Write the recipe to the document's ScanSettings (one undo step); the next "
                 "Run scan or Replay judges by it")
    undo_name = UNDO_NAME
    missing = MISSING
    written = "Run scan or Replay to judge by them."
    properties = PROPERTIES
    followed = tuple(set_flag(p) for p, _ in LIMITS)

    def __init__(self, doc, applied=None, plan=None):
        self.plan = plan
        super().__init__(doc, applied)

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
            field = QuantityField("length", 0.0, f"{label}; blank: not set, SPEC §4's rule")
            field.setText("")
            if prop in defaults:
                field.setPlaceholderText(format_length(defaults[prop]))
            self.fields[prop] = field
            form.addRow(label, field)
        self.correction = QtGui.QLineEdit()
        self.correction.setToolTip("Measured diffs are divided by this (a calibration's)")
        form.addRow("Thickness correction", self.correction)

    def fill(self, obj):
        for prop, _ in LIMITS:
            value = limit_value(obj, prop)
            if value is None:
                self.fields[prop].set_value(0.0)
                self.fields[prop].setText("")
            else:
                self.fields[prop].set_value(value)
        self.correction.setText(f"{float(obj.ThicknessCorrection):g}")
        self.rules.setCurrentIndex(self.rules.findText(str(obj.Rules)))

    def _old(self, obj):
        return holds_old_limits(obj)

    def values(self):
        """{property: value} as typed (limits in mm, each with its "...Set" box; in an earlier
        version's document the limit alone, -1 when blank); ValueError naming the field when
        one is not a length or not a number."""
        old = self._old(settings_object(self.doc))
        values = {}
        for prop, label in LIMITS:
            field = self.fields[prop]
            if not field.text().strip():
                values[prop if old else set_flag(prop)] = OLD_NOT_SET if old else False
                continue
            try:
                values[prop] = field.value()
            except ValueError as exc:
                raise ValueError(f"{label}: {exc}") from None
            if not old:
                values[set_flag(prop)] = True
        text = self.correction.text().strip()
        try:
            values["ThicknessCorrection"] = float(normalise(text))
        except ValueError:
            raise ValueError(f"Thickness correction: {text!r} is not a number") from None
        values["Rules"] = self.rules.currentText()
        return values

    def current(self, obj, prop):
        if prop == "Rules":
            return str(obj.Rules)
        value = getattr(obj, prop)
        return value if isinstance(value, bool) else float(getattr(value, "Value", value))

    def call(self, values, changed):
        """The recorded line writing the ``changed`` properties of ``values``: a limit as a
        quantity in mm, or None when not set."""
        arguments = [doc_ref(self.doc)]
        for prop, _ in LIMITS:
            if prop in changed or set_flag(prop) in changed:
                value = values.get(prop, OLD_NOT_SET)
                shown = values.get(set_flag(prop), value != OLD_NOT_SET)
                text = quantity_ref(value, "mm") if shown else "None"
                arguments.append(f"{keyword(prop)}={text}")
        for prop in ("ThicknessCorrection", "Rules"):
            if prop in changed:
                arguments.append(f"{keyword(prop)}={values[prop]!r}")
        return f"apply_recipe({', '.join(arguments)})"


def apply_recipe(doc, **recipe):
    """Write the mapping recipe (SPEC §11) to the document's ScanSettings, as the scan panel's
    "Recipe" section's Apply does (and records), in one undo step named "WaferScan recipe"; the
    next Run scan or Replay judges by it. Only the keys given are written: ``thickness_min``,
    ``thickness_max``, ``double_threshold``, ``position_below``, ``position_above`` (lengths:
    FreeCAD quantities such as ``App.Units.Quantity('0.6 mm')``, or bare numbers in mm; None:
    not set, SPEC §4's rule from t, Δt and Δp), ``thickness_correction`` (a number) and
    ``rules`` ("waferscan" or "boundary"). A recipe the scan's readers refuse raises their
    InputError and nothing is written. Returns the properties changed."""
    obj = settings_object(doc)
    old = holds_old_limits(obj)
    limits = {keyword(prop): prop for prop, _ in LIMITS}
    values = {}
    for name, value in recipe.items():
        if name in limits:
            prop = limits[name]
            mm = None if value is None else value_in(value, "mm", name)
            if old:
                values[prop] = OLD_NOT_SET if mm is None else mm
            else:
                values[set_flag(prop)] = mm is not None
                if mm is not None:
                    values[prop] = mm
        elif name == "thickness_correction":
            values["ThicknessCorrection"] = value_in(value, "", name)
        elif name == "rules":
            if value not in RULE_SETS:
                raise InputError("rules", None, f"{value!r} is not one of {', '.join(RULE_SETS)}")
            values["Rules"] = str(value)
        else:
            raise InputError(name, None, "not a key of the recipe (one of "
                                         f"{', '.join([*limits, 'thickness_correction', 'rules'])})")
    return write_settings(doc, values, UNDO_NAME, MISSING)
