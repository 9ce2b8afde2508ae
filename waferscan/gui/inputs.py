"""Lengths shown and typed as FreeCAD users expect: in the length unit of the user's unit schema
(Preferences → General → Units), with enough digits to read a tolerance (0.125 mm is
"0.00492126 in" in inches, not "0.00 in"), and typed in any unit ("0.02 in", "350 um").

FreeCAD's own Gui::QuantitySpinBox is not used for values the user may leave alone: it shows
the user's number of decimals (2 by default) and reads its value back from that text, so 0.125
mm became 0.13 mm, and 0 in the inch schema, when a dialog was merely accepted. A field here
keeps the exact value it was given until the user edits its text.
"""

from __future__ import annotations

import FreeCAD as App
from PySide import QtGui

SIGNIFICANT_DIGITS = 6  # 0.775 mm, 0.00492126 in, 202.5 mm: a tolerance is readable in any unit


def length_unit():
    """(unit text, mm per unit) of the user's unit schema for lengths of a millimetre or so:
    ("mm", 1.0) in the standard schema, ("in", 25.4) in the inch schemas."""
    _, factor, unit = App.Units.Quantity(1.0, App.Units.Length).getUserPreferred()
    return unit, float(factor)


def format_length(value_mm, digits=SIGNIFICANT_DIGITS):
    """A length in the user's unit with ``digits`` significant digits, e.g. "0.775 mm"."""
    unit, factor = length_unit()
    number = value_mm / factor
    text = f"{number:.{digits}g}"
    if "e" in text:  # tiny or huge: plain decimals read better in a field
        text = f"{number:.{digits + 4}f}".rstrip("0").rstrip(".")
    return f"{'0' if text in ('-0', '') else text} {unit}"


def parse_length(text):
    """Typed text -> mm. A bare number is in the user's unit; ValueError when it is not a
    length."""
    text = text.strip()
    if not text:
        raise ValueError("empty")
    unit, factor = length_unit()
    try:
        return float(text) * factor
    except ValueError:
        pass
    try:
        quantity = App.Units.Quantity(text)
    except Exception as exc:  # FreeCAD raises its own types for text it cannot parse
        raise ValueError(f"{text!r} is not a length: {exc}") from None
    if quantity.Unit != App.Units.Unit(App.Units.Length):
        raise ValueError(f"{text!r} is not a length (give a unit such as mm or in)")
    return float(quantity.getValueAs("mm"))


class LengthField(QtGui.QLineEdit):
    """A length in the user's unit. ``value_mm()`` is the exact value last set while the text
    is the one shown for it; once the user edits the text, what the text says."""

    def __init__(self, value_mm=0.0, tooltip="", minimum=0.0, maximum=1e6, parent=None):
        super().__init__(parent)
        self.minimum, self.maximum = minimum, maximum
        self._exact, self._text_shown = None, None
        if tooltip:
            self.setToolTip(f"{tooltip} (a length; type a unit for another one: 0.02 in, "
                            "350 um)")
        self.set_mm(value_mm)

    def set_mm(self, value_mm):
        self._exact = float(value_mm)
        self._text_shown = format_length(self._exact)
        self.setText(self._text_shown)

    def edited(self):
        return self.text() != self._text_shown

    def value_mm(self):
        """The value in mm; ValueError for text that is not a length in range."""
        if not self.edited():
            return self._exact
        value = parse_length(self.text())
        if not self.minimum <= value <= self.maximum:
            raise ValueError(f"{self.text()!r} is outside {format_length(self.minimum)} to "
                             f"{format_length(self.maximum)}")
        return value


def length_input(value_mm, tooltip="", minimum=0.0, maximum=1e6):
    """A length field holding ``value_mm``."""
    return LengthField(value_mm, tooltip, minimum, maximum)


def set_length(box, value_mm):
    box.set_mm(value_mm)


def length_value(box):
    """The field's value in mm (ValueError when the typed text is not a length)."""
    return box.value_mm()


def folder_row(field, parent, on_chosen, title="MCS folder", tooltip="Choose the MCS folder"):
    """A folder's line edit ``field`` with a Browse… button beside it, as one row (a layout).
    The button opens a folder dialog over ``parent`` at the folder typed, and hands the folder
    chosen to ``on_chosen(path)``; a cancelled dialog changes nothing."""
    browse = QtGui.QPushButton("Browse…")
    browse.setToolTip(tooltip)

    def choose():
        chosen = QtGui.QFileDialog.getExistingDirectory(parent, title, field.text())
        if chosen:
            on_chosen(chosen)

    browse.clicked.connect(choose)
    row = QtGui.QHBoxLayout()
    row.addWidget(field, 1)
    row.addWidget(browse)
    return row
