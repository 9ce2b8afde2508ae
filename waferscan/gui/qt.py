"""Differences between the Qt bindings FreeCAD ships, handled once: FreeCAD 0.20 has PySide2,
FreeCAD 1.x may have PySide6 (``from PySide import ...`` works with both); and the task-panel
interface the workbench's panels share."""

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

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
    ``self.form`` and ``self.alive_while_shown`` (a widget whose life tells whether the panel is
    shown) and says in ``shut_down`` what closing stops."""

    alive_while_shown = None
    _observer = None

    def getStandardButtons(self):  # noqa: N802 (FreeCAD's names)
        return int(QtGui.QDialogButtonBox.Close)

    # Our panels stay open for long (a scan's results, an MCS link watched for hours): while
    # they are, FreeCAD's commands and ours stay usable (File → New, Edit → Delete, Results
    # table…). FreeCAD greys out every command that alters the document, the view or the
    # selection unless the open panel allows it (Command::testActive).
    def isAllowedAlterDocument(self):  # noqa: N802
        return True

    def isAllowedAlterView(self):  # noqa: N802
        return True

    def isAllowedAlterSelection(self):  # noqa: N802
        return True

    def follow_document(self, doc):
        """Shut the panel down and close it when the user closes ``doc``; a panel that defines
        ``object_changed(obj, prop)`` is told of each change of the document's objects (an
        Undo, a Redo, the property editor) while it is open."""
        changed = getattr(self, "object_changed", None)
        self._observer = _DocumentClosed(doc.Name, self._document_closed,
                                         changed and self._object_changed)
        App.addDocumentObserver(self._observer)

    def _object_changed(self, obj, prop):
        if not self.is_open():  # closed by FreeCAD (another panel shown): no one to tell
            # Later: FreeCAD is calling this very observer now (removing it deletes it).
            QtCore.QTimer.singleShot(0, self._forget_document)
            return
        self.object_changed(obj, prop)

    def _document_closed(self):
        self._forget_document()
        self.shut_down()
        if self.is_open():
            # Closed once FreeCAD has finished closing the document.
            QtCore.QTimer.singleShot(0, self._close_if_open)

    def _close_if_open(self):
        if self.is_open():
            Gui.Control.closeDialog()

    def _forget_document(self):
        if self._observer is not None:
            App.removeDocumentObserver(self._observer)
            self._observer = None

    def is_open(self):
        """Whether FreeCAD still shows this panel."""
        return alive(self.alive_while_shown)

    def shut_down(self):
        raise NotImplementedError

    def reject(self):
        self._forget_document()
        self.shut_down()
        Gui.Control.closeDialog()
        return True

    def accept(self):
        return self.reject()


class _DocumentClosed:
    """A FreeCAD document observer that calls ``then()`` when the document named ``name`` is
    being closed (it can still be read then), and ``changed(obj, prop)`` (when given) when one
    of its objects' properties changes."""

    def __init__(self, name, then, changed=None):
        self.name, self.then, self.changed = name, then, changed

    def slotDeletedDocument(self, doc):  # noqa: N802 (FreeCAD's name)
        if doc.Name == self.name:
            self.then()

    def slotChangedObject(self, obj, prop):  # noqa: N802 (FreeCAD's name)
        if self.changed is not None and obj.Document.Name == self.name:
            self.changed(obj, prop)


class GuiDocumentClosing:
    """Calls ``then()`` when the GUI side of the document named ``name`` is about to go (its
    view providers, scene-graph nodes and 3D views still there), however it is closed: a tab,
    Ctrl+W, File → Close, ``App.closeDocument`` or FreeCAD closing, the main window's Quit or
    ``QApplication.quit()`` (as a script or a macro may) included. An App document observer is
    told only after FreeCAD's GUI has deleted them (touching them then crashed FreeCAD); on
    ``QApplication.quit()`` even the GUI document's deletion comes after the main window's, so
    the application's ``aboutToQuit`` is the last moment. ``close()`` stops watching."""

    def __init__(self, name, then):
        self.name, self.then = name, then
        self._added = True  # watching (close() not called yet)
        self._observing = True  # still registered with FreeCAD
        Gui.addDocumentObserver(self)
        self._quitting = QtGui.QApplication.instance().aboutToQuit
        self._quitting.connect(self._quit)

    def slotDeletedDocument(self, gui_doc):  # noqa: N802 (FreeCAD's name)
        if self._added and gui_doc.Document.Name == self.name:
            self.then()

    def _quit(self):
        """FreeCAD is quitting: end now, and stop watching at once (no event loop is left for
        ``close``'s later removal)."""
        if self._added:
            self.then()  # which may call close()
        self._added = False
        self._disconnect()
        self._remove()

    def _remove(self):
        if self._observing:
            self._observing = False
            Gui.removeDocumentObserver(self)

    def _disconnect(self):
        try:
            self._quitting.disconnect(self._quit)
        except (RuntimeError, TypeError):  # already disconnected
            pass

    def close(self):
        if self._added:
            self._added = False
            # Later: FreeCAD may be calling this very observer now (removing it deletes it).
            # Not disconnected from aboutToQuit before then: a quit in between removes it.
            QtCore.QTimer.singleShot(0, self._closed)

    def _closed(self):
        self._disconnect()
        self._remove()


def fitted_size(width, height, margin=(40, 80)):
    """(width, height) no larger than the screen FreeCAD's main window is on (1024×700
    included), less ``margin`` for the window's frame and the desktop's panels."""
    app = QtGui.QApplication.instance()
    if hasattr(app, "desktop"):  # Qt 5
        screen = app.desktop().availableGeometry(Gui.getMainWindow())
    else:  # Qt 6: the main window's screen
        screen = Gui.getMainWindow().screen().availableGeometry()
    return min(width, screen.width() - margin[0]), min(height, screen.height() - margin[1])


def main_window_alive():
    """Whether FreeCAD's main window still exists (not while FreeCAD quits)."""
    return alive(Gui.getMainWindow())


def set_progress(bar, value):
    """``bar.setValue(value)`` painted with the next frame instead of at once. QProgressBar
    repaints itself synchronously whenever its text or bar changes; next to FreeCAD's OpenGL
    3D view each synchronous repaint composes the whole main window again (~2.5 ms each with
    software rendering), at every frame of an animated scan. With updates held off for the
    call, the bar is only marked for the next paint, which Qt does with the rest."""
    if bar.value() == value:
        return
    bar.setUpdatesEnabled(False)
    try:
        bar.setValue(value)
    finally:
        bar.setUpdatesEnabled(True)  # schedules the bar's paint (update(), not repaint())
