"""What the scan panel's collapsible sections of ScanSettings values have in common (the
"Sensor and slow scan" section of issues 14 and 17, the "Recipe" of SPEC §11): a toggle that
shows the fields, an Apply button and a message line. Apply writes the fields to the document's
ScanSettings in one undo step and reads the document back through the scan's own readers, so a
value they refuse is refused here in their words and nothing is written; the next Run scan or
Replay uses what was written."""

from __future__ import annotations

from PySide import QtCore, QtGui

from ..cad.reader import DocumentScene
from ..cad.roles import role_holder
from ..core.errors import InputError


def settings_object(doc):
    """The document's one ScanSettings object (the one holding the properties), or None."""
    scene = DocumentScene.of(doc)
    if len(scene.settings) != 1:
        return None
    return role_holder(scene.settings[0].obj)


class SettingsSection:
    """A section's widgets; ``box`` goes into the panel. ``check(doc)`` is the readers' check
    (raises InputError for a value they refuse); ``transaction(doc, name)`` the context of one
    undo step (session.transaction, which aborts when its block raises); ``applied`` is called
    after a change is written.

    A section names its ``title``, ``tip``, ``apply_tip``, ``undo_name``, ``missing`` (the
    message when the document has no ScanSettings with its ``properties``) and ``written`` (what
    the next scan does with the values), and fills in ``build(form)``, ``fill(obj)``,
    ``values()`` and ``current(obj, prop)``."""

    title = tip = apply_tip = undo_name = missing = written = ""
    properties = ()
    followed = ()  # more properties whose change the fields follow (the recipe's "...Set" boxes)

    def __init__(self, doc, check, transaction, applied=None):
        self.doc, self.check, self.transaction, self.applied = doc, check, transaction, applied
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
        """Write the fields to ScanSettings in one undo step, checked by the scan's readers;
        a refused value: the message says why and the document is left as it was. True when
        written."""
        obj = settings_object(self.doc)
        try:
            values = self.values()
        except ValueError as exc:
            return self._refused(str(exc))
        current = {prop: self.current(obj, prop) for prop in values}
        if current == values:
            self.message.setText("No change.")
            return False
        self._applying = True
        try:
            with self.transaction(self.doc, self.undo_name):
                for prop, value in values.items():
                    setattr(obj, prop, value)
                self.check(self.doc)  # the readers' own checks; raising aborts the transaction
        except InputError as exc:
            return self._refused(exc.message)  # the fields keep the typed text, to correct
        finally:
            self._applying = False
        changed = ", ".join(p for p in values if values[p] != current[p])
        self.message.setStyleSheet("")
        self.message.setText(f"Written: {changed}. {self.written}")
        if self.applied is not None:
            self.applied()
        return True

    def follow(self, obj, prop):
        """The document's ``obj.prop`` changed. One of this section's properties of ScanSettings
        changed by something other than Apply (an Undo or Redo, the property editor): the
        fields show the document's values again, and the message says so."""
        if self._applying or prop not in self.properties + self.followed:
            return
        holder = settings_object(self.doc)
        if holder is None or holder.Name != obj.Name:
            return
        self.load()
        self.message.setStyleSheet("")
        self.message.setText("Changed in the document (Undo, Redo or the property editor): "
                             "the fields show its values.")

    def _refused(self, why):
        self.message.setStyleSheet("color: #c01010;")
        self.message.setText(f"Not written: {why}")
        return False
