"""Length inputs as FreeCAD's own: a Gui::QuantitySpinBox in millimetres, which shows the unit
and accepts what a user types in other units ("0.02 in", "350 um")."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui


def length_input(value_mm, tooltip="", minimum=0.0, maximum=1e6):
    """A length field holding ``value_mm``."""
    box = Gui.UiLoader().createWidget("Gui::QuantitySpinBox")
    box.setProperty("unit", "mm")
    box.setProperty("minimum", minimum)
    box.setProperty("maximum", maximum)
    set_length(box, value_mm)
    if tooltip:
        box.setToolTip(tooltip)
    return box


def set_length(box, value_mm):
    box.setProperty("value", App.Units.Quantity(float(value_mm), App.Units.Length))


def length_value(box):
    """The field's value in mm."""
    return float(App.Units.Quantity(box.property("value")).getValueAs("mm"))
