"""What the scan panel's collapsible sections of ScanSettings values have in common (the
"Sensor and slow scan" section of issues 14 and 17, the "Recipe" of SPEC §11): a toggle that
shows the fields, an Apply button and a message line. Apply runs a recorded line
(``apply_sensor_settings(...)``, ``apply_recipe(...)``: the Python console shows it, a macro
replays it) that writes the values changed to the document's ScanSettings in one undo step
(``write_settings``) and reads the document back through the scan's own readers, so a value they
refuse is refused here in their words and nothing is written; the next Run scan or Replay uses
what was written."""

from __future__ import annotations

import re

from PySide import QtCore, QtGui

from ..cad.reader import DocumentScene, read_layout
from ..cad.roles import role_holder
from ..core.errors import InputError
from .session import record, transaction


def settings_object(doc):
    """The document's one ScanSettings object (the one holding the properties), or None."""
    scene = DocumentScene.of(doc)
    if len(scene.settings) != 1:
        return None
    return role_holder(scene.settings[0].obj)


def keyword(prop):
    """A property's keyword in a recorded line: "ThicknessMin" -> "thickness_min"."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", prop).lower()


def quantity_ref(value, unit):
    """The Python text of a value in ``unit`` as a FreeCAD quantity, for a recorded line:
    ``App.Units.Quantity('0.6 mm')``."""
    return f"App.Units.Quantity('{float(value)!r} {unit}')"


def _current(obj, prop):
    value = getattr(obj, prop)
    if isinstance(value, (bool, str)):
        return value
    return float(getattr(value, "Value", value))


def write_settings(doc, values, undo_name, missing):
    """Write ``values`` ({property: value}) to the document's ScanSettings in one undo step
    named ``undo_name``, then read the document through the scan's readers: a value they refuse
    raises their InputError and nothing is written (the step aborted). ``missing``: the message
    when the document has no ScanSettings with these properties. Returns the properties whose
    value changed (none: no undo step)."""
    obj = settings_object(doc)
    if obj is None or any(p not in obj.PropertiesList for p in values):
        raise InputError(doc.Label, None, missing)
    changed = [p for p, value in values.items() if _current(obj, p) != value]
    if not changed:
        return []
    with transaction(doc, undo_name):
        for prop in changed:
            setattr(obj, prop, values[prop])
        read_layout(doc, DocumentScene.of(doc))  # the readers' own checks; raising aborts
    return changed


class SettingsSection:
    """A section's widgets; ``box`` goes into the panel. ``applied`` is called after a change
    is written.

    A section names its ``title``, ``tip``, ``apply_tip``, ``undo_name``, ``missing`` (the
    message when the document has no ScanSettings with its ``properties``) and ``written`` (what
    the next scan does with the values), and fills in ``build(form)``, ``fill(obj)``,
    ``values()``, ``current(obj, prop)`` and ``call(values, changed)`` (the recorded line that
    writes the ``changed`` properties of ``values``)."""

    title = tip = apply_tip = undo_name = missing = written = ""
    properties = ()
    followed = ()  # more properties whose change the fields follow (the recipe's "...Set" boxes)

    def __init__(self, doc, applied=None):
        self.doc, self.applied = doc, applied
        self._applying = False  # Apply is writing: the changes are the fields' own
        self.box = QtGui.QWidget()
        self.toggle = QtGui.QToolButton()
        self.toggle.setText(self.title)
        self.toggle.setToolButtonStyle(QtCore.Qt.ToolButtonTextBesideIcon)
        self.toggle.setCheckable(True)
        self.toggle.setAutoRaise(True)
        self.toggle.setToolTip(self.tip)
        self.body = QtGui.QWidget()
        form = QtGui.QFormLayout(self.body)
        form.setContentsMargins(0, 0, 0, 0)
        self.build(form)
        self.apply_button = QtGui.QPushButton("Apply")
        self.apply_button.setToolTip(self.apply_tip)
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
        """Fill the fields from the ScanSettings object (without the properties: disabled)."""
        obj = settings_object(self.doc)
        usable = obj is not None and all(p in obj.PropertiesList for p in self.properties)
        self.body.setEnabled(usable)
        if not usable:
            self.message.setText(self.missing)
            return
        self.fill(obj)

    def apply(self):
        """Write the fields changed to ScanSettings in one undo step, checked by the scan's
        readers, as a recorded line (``call``); a refused value: the message says why and the
        document is left as it was. True when written."""
        obj = settings_object(self.doc)
        try:
            values = self.values()
        except ValueError as exc:
            return self._refused(str(exc))
        current = {prop: self.current(obj, prop) for prop in values}
        if current == values:
            self.message.setText("No change.")
            return False
        changed = [p for p in values if values[p] != current[p]]
        self._applying = True
        try:
            record(self.call(values, changed))
        except InputError as exc:
            return self._refused(exc.message)  # the fields keep the typed text, to correct
        finally:
            self._applying = False
        changed = ", ".join(changed)
        self.message.setStyleSheet("")
        self.message.setText(f"Written: {changed}. {self.written}")
        if self.applied is not None:
            self.applied()
        return True

    def follow(self, obj, prop):
        """The document's ``obj.prop`` changed. One of this section's properties of ScanSettings
        changed by something other than Apply (an Undo or Redo, the property editor, a macro):
        the fields show the document's values again, and the message says so."""
        if self._applying or prop not in self.properties + self.followed:
            return
        holder = settings_object(self.doc)
        if holder is None or holder.Name != obj.Name:
            return
        self.load()
        self.message.setStyleSheet("")
        self.message.setText("Changed in the document (Undo, Redo, the property editor or a "
                             "macro): the fields show its values.")

    def _refused(self, why):
        self.message.setStyleSheet("color: #c01010;")
        self.message.setText(f"Not written: {why}")
        return False
