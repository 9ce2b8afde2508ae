"""Lengths shown and typed as FreeCAD users expect: in the length unit of the user's unit schema
(Preferences → General → Units), with enough digits to read a tolerance (0.125 mm is
"0.00492126 in" in inches, not "0.00 in"), and typed in any unit ("0.02 in", "350 um").

FreeCAD's own Gui::QuantitySpinBox is not used for values the user may leave alone: it shows
the user's number of decimals (2 by default) and reads its value back from that text, so 0.125
mm became 0.13 mm, and 0 in the inch schema, when a dialog was merely accepted. A field here
keeps the exact value it was given until the user edits its text. The same holds for the other
quantities the panels take (accelerations, angles; times in s, ms or µs, as FreeCAD 0.20 has no
time unit to show them in), and typed text may use the locale's decimal comma ("0,5 mm").
"""

from __future__ import annotations

import re

import FreeCAD as App
from PySide import QtCore, QtGui

from ..core.errors import InputError

SIGNIFICANT_DIGITS = 6  # 0.775 mm, 0.00492126 in, 202.5 mm: a tolerance is readable in any unit

# What a field holds: (FreeCAD unit, the internal unit its values are in, its name in messages,
# a typical size for picking the user's unit: 1 mm, 1000 mm/s², 1°).
KINDS = {"length": (App.Units.Length, "mm", "length", 1.0),
         "acceleration": (App.Units.Acceleration, "mm/s^2", "acceleration", 1000.0),
         "angle": (App.Units.Angle, "deg", "angle", 1.0)}
# Times: FreeCAD 0.20 has no time property and its parser knows s but not ms, so a time is a
# number of seconds, shown and typed in s, ms or µs.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}


def normalise(text):
    """Typed text as FreeCAD's parser reads it: the locale's decimal comma ("0,5" in German) and
    the typographic minus ("−1 mm") accepted."""
    text = text.strip().replace("\u2212", "-").replace("²", "^2").replace("³", "^3")
    if QtCore.QLocale().decimalPoint() == "," and "." not in text:
        text = text.replace(",", ".")
    return text


def localised(text):
    """A number's text with the locale's decimal point ("0,5 mm" in German)."""
    point = QtCore.QLocale().decimalPoint()
    return text if point == "." else text.replace(".", point)


def user_unit(kind="length"):
    """(unit text, internal units per unit) of the user's unit schema for values of ``kind``:
    ("mm", 1.0) for lengths in the standard schema, ("in", 25.4) in the inch schemas."""
    unit, _, _, typical = KINDS[kind]
    _, factor, text = App.Units.Quantity(typical, unit).getUserPreferred()
    return text, float(factor)


def length_unit():
    return user_unit("length")


def _number_text(number, digits):
    text = f"{number:.{digits}g}"
    if "e" in text:  # tiny or huge: plain decimals read better in a field
        text = f"{number:.{digits + 4}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def format_quantity(value, kind="length", digits=SIGNIFICANT_DIGITS):
    """A value (in mm, mm/s², degrees) in the user's unit, e.g. "0.775 mm", "0.0305118 in"."""
    unit, factor = user_unit(kind)
    return localised(f"{_number_text(value / factor, digits)} {unit}")


def format_length(value_mm, digits=SIGNIFICANT_DIGITS):
    """A length in the user's unit with ``digits`` significant digits, e.g. "0.775 mm"."""
    return format_quantity(value_mm, "length", digits)


def parse_quantity(text, kind="length"):
    """Typed text -> the value in the internal unit (mm, mm/s², degrees). A bare number is in
    the user's unit; ValueError when it is not a ``kind``."""
    shown = text.strip()
    text = normalise(text)
    if not text:
        raise ValueError("empty")
    unit, internal, name, _ = KINDS[kind]
    _, factor = user_unit(kind)
    try:
        return float(text) * factor
    except ValueError:
        pass
    try:
        quantity = App.Units.Quantity(text)
    except Exception:  # FreeCAD raises its own types for text it cannot parse
        raise ValueError(f"{shown!r} is not {_article(name)} {name}") from None
    if quantity.Unit != App.Units.Unit(unit):
        raise ValueError(f"{shown!r} is not {_article(name)} {name} (give a unit such as "
                         f"{user_unit(kind)[0]})")
    return float(quantity.getValueAs(internal))


def parse_length(text):
    """Typed text -> mm. A bare number is in the user's unit; ValueError when it is not a
    length."""
    return parse_quantity(text, "length")


def parse_time(text):
    """Typed text -> seconds: "0.25 ms", "0,5 s", "250 us" or a bare number of seconds."""
    shown = text.strip()
    match = re.fullmatch(r"([-+0-9.eE]+)\s*(s|ms|us|µs)?", normalise(text))
    try:
        if match is None:
            raise ValueError
        return float(match.group(1)) * TIME_UNITS[match.group(2) or "s"]
    except ValueError:
        raise ValueError(f"{shown!r} is not a time (give s, ms or µs)") from None


def format_time(seconds, digits=SIGNIFICANT_DIGITS):
    """Seconds as they read best: "0.25 ms", "5 ms", "1.5 s", "0 s"."""
    unit = "s" if seconds == 0.0 or abs(seconds) >= 0.1 else \
        "ms" if abs(seconds) >= 1e-4 else "µs"
    return localised(f"{_number_text(seconds / TIME_UNITS[unit], digits)} {unit}")


def _article(name):
    return "an" if name[0] in "aeiou" else "a"


def range_problem(value, minimum, maximum, strict=False, show=format_length):
    """Why a value is outside [minimum, maximum] (``strict``: above minimum), or None."""
    if strict and value <= minimum or value < minimum:
        if minimum == 0.0:
            return "must be positive" if strict else "must be positive or 0"
        return f"must be at least {show(minimum)}"
    if value > maximum:
        return f"must be at most {show(maximum)}"
    return None


class QuantityField(QtGui.QLineEdit):
    """A value in the user's unit (a length, an acceleration, an angle) or a time in s/ms/µs.
    ``value()`` is the exact value last set while the text is the one shown for it; once the
    user edits the text, what the text says."""

    def __init__(self, kind="length", value=0.0, tooltip="", minimum=0.0, maximum=1e6,
                 strict=False, parent=None):
        super().__init__(parent)
        self.kind, self.minimum, self.maximum, self.strict = kind, minimum, maximum, strict
        self._exact, self._text_shown = None, None
        if tooltip:
            example = "0.5 ms, 0.002 s" if kind == "time" else \
                "0.02 in, 350 um" if kind == "length" else \
                "2 m/s^2, 40 in/s^2" if kind == "acceleration" else "0.5 deg"
            self.setToolTip(f"{tooltip} ({'a time' if kind == 'time' else _article(kind)} "
                            f"{'' if kind == 'time' else kind}; type a unit for another one: "
                            f"{example})".replace("  ", " ").replace(" ;", ";"))
        self.set_value(value)

    def _format(self, value):
        return format_time(value) if self.kind == "time" else format_quantity(value, self.kind)

    def set_value(self, value):
        self._exact = float(value)
        self._text_shown = self._format(self._exact)
        self.setText(self._text_shown)

    def edited(self):
        return self.text() != self._text_shown

    def value(self):
        """The value (mm, mm/s², degrees, s); ValueError for text that is not one in range."""
        if not self.edited():
            return self._exact
        value = parse_time(self.text()) if self.kind == "time" else \
            parse_quantity(self.text(), self.kind)
        problem = range_problem(value, self.minimum, self.maximum, self.strict, self._format)
        if problem:
            raise ValueError(f"{self.text().strip()!r} {problem}")
        return value

    # the length field's names, kept for its callers
    set_mm = set_value
    value_mm = value




def length_input(value_mm, tooltip="", minimum=0.0, maximum=1e6):
    """A length field holding ``value_mm``."""
    return QuantityField("length", value_mm, tooltip, minimum, maximum)


def set_length(box, value_mm):
    box.set_value(value_mm)


def length_value(box):
    """The field's value in mm (ValueError when the typed text is not a length)."""
    return box.value()


REFUSED_STYLE = "QLineEdit { border: 1px solid #c01010; background: #fdecec; }"


def marked_row(field, reasons):
    """``field`` with a red label beside it that says why its text is refused (hidden while
    it is fine), as one row; the label is kept in ``reasons[field]`` (see ``mark``)."""
    row = QtGui.QWidget()
    layout = QtGui.QHBoxLayout(row)
    layout.setContentsMargins(0, 0, 0, 0)
    layout.addWidget(field, 1)
    reason = QtGui.QLabel()
    reason.setStyleSheet("color: #c01010;")
    reason.setWordWrap(True)
    reason.hide()
    layout.addWidget(reason, 1)
    reasons[field] = reason
    return row


def mark(field, reason, why):
    """Mark ``field`` refused with ``why`` shown in its ``reason`` label (None: fine)."""
    field.setStyleSheet(REFUSED_STYLE if why else "")
    field.setProperty("refused", why or "")
    reason.setText(why or "")
    reason.setVisible(bool(why))


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


def value_in(value, unit, name):
    """A value given to a recorded function (a FreeCAD quantity, its text such as "0.6 mm", or
    a bare number, taken in ``unit``) as a float in ``unit``; InputError naming ``name`` when it
    is not one of ``unit``'s kind."""
    if isinstance(value, str):
        try:
            value = App.Units.Quantity(value)
        except Exception:  # FreeCAD raises its own types for text it cannot parse
            raise InputError(name, None, f"{value!r} is not a quantity") from None
    if hasattr(value, "getValueAs"):
        wanted = App.Units.Quantity(f"1 {unit}").Unit if unit else App.Units.Quantity(1.0).Unit
        if value.Unit != wanted:
            raise InputError(name, None, f"{value.UserString} is not in units of "
                                         f"{unit or 'a bare number'}")
        return float(value.getValueAs(unit)) if unit else float(value.Value)
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InputError(name, None, f"{value!r} is not a number") from None
