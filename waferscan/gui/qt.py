"""Differences between the Qt bindings FreeCAD ships, handled once: FreeCAD 0.20 has PySide2,
FreeCAD 1.x may have PySide6 (``from PySide import ...`` works with both)."""

try:
    from shiboken2 import isValid as _is_valid
except ImportError:  # PySide6 builds
    from shiboken6 import isValid as _is_valid


def alive(widget):
    """Whether the C++ side of ``widget`` still exists: FreeCAD deletes the widgets of a task
    panel it closes while the Python object lives on."""
    return widget is not None and _is_valid(widget)
