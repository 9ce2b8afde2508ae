"""Differences between the Qt bindings FreeCAD ships, handled once: FreeCAD 0.20 has PySide2,
FreeCAD 1.x may have PySide6 (``from PySide import ...`` works with both); and the task-panel
interface the workbench's panels share."""

import FreeCADGui as Gui
from PySide import QtGui

try:
    from shiboken2 import isValid as _is_valid
except ImportError:  # PySide6 builds
    from shiboken6 import isValid as _is_valid


def alive(widget):
    """Whether the C++ side of ``widget`` still exists: FreeCAD deletes the widgets of a task
    panel it closes while the Python object lives on."""
    return widget is not None and _is_valid(widget)


class ClosableTaskPanel:
    """FreeCAD's task-panel interface for a panel with one Close button. A subclass sets
    ``self.form`` and ``self.leaf`` (a widget whose life tells whether the panel is shown) and
    says in ``shut_down`` what closing stops."""

    leaf = None

    def getStandardButtons(self):  # noqa: N802 (FreeCAD's names)
        return int(QtGui.QDialogButtonBox.Close)

    def is_open(self):
        """Whether FreeCAD still shows this panel."""
        return alive(self.leaf)

    def shut_down(self):
        raise NotImplementedError

    def reject(self):
        self.shut_down()
        Gui.Control.closeDialog()
        return True

    def accept(self):
        return self.reject()
