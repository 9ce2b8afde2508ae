"""The workbench's session: what it keeps between commands while FreeCAD runs (``session``), and
how it speaks to the user: ``report`` (the report view and a message box that does not block),
``ask`` (a question that must be answered), ``record`` (an action as a replayable line), ``transaction`` (one undo step), and one task panel
at a time (``check_no_other_task_panel``, ``show_task_panel``)."""

from __future__ import annotations

from contextlib import contextmanager

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..core.errors import InputError
from .qt import alive

__all__ = ["WorkbenchSession", "session", "last_result", "doc_ref", "record", "report", "ask",
           "transaction", "check_no_other_task_panel", "show_task_panel"]


class WorkbenchSession:
    """What the workbench keeps between commands while FreeCAD runs (one of it: ``session``).
    Every attribute is here from the start; nothing else holds state between commands."""

    def __init__(self):
        self.results = {}  # document Name -> the ScanResult of its last Run scan
        self.animation = None  # the ScanAnimation playing, or played last
        self.task_panel = None  # our task panel shown last (the scan's or the MCS link's)
        self.dialogs = []  # what the last results or cross-check command opened
        self.message_boxes = []  # non-blocking message boxes (errors, hints) not yet closed
        self.results_windows = {}  # document Name -> {"table" | "code": its results dialog}
        self.close_watcher = None  # the document observer that closes a closed one's dialogs
        self.pocket_animation = None  # a slow scan's jabs and sweeps playing (SPEC §13), or None
        self.tolerance_study = None  # the "Tolerance study…" dialog shown last (SPEC §12)

    def keep_message_box(self, box):
        """Keep a non-blocking box alive (Qt would delete it with its last Python reference)."""
        self.message_boxes = [m for m in self.message_boxes if alive(m)] + [box]


session = WorkbenchSession()


def last_result(doc=None):
    """The ScanResult of the document's last Run scan (the active document's), or None."""
    doc = doc or App.ActiveDocument
    return None if doc is None else session.results.get(doc.Name)


def doc_ref(doc):
    """The Python expression of ``doc`` in a recorded line."""
    return f"App.getDocument({doc.Name!r})"


def record(call):
    """Run ``call``, a line of Python on ``waferscan.gui.commands``' functions, as FreeCAD's own
    commands do: through ``Gui.doCommand``, so that the Python console shows it and macro
    recording keeps it, the call a script would make (``commands`` names every function such a
    line calls)."""
    Gui.addModule("waferscan.gui.commands")
    Gui.doCommand(f"waferscan.gui.commands.{call}")


def report(message, error=False, title="WaferScan"):
    """Tell the user ``message`` in the report view and in a message box that does not block (a
    fresh FreeCAD keeps the report view hidden). ``error``: a user's mistake (printed as an
    error, a warning box); else what the user should know or do next. Returns the box."""
    if error:
        App.Console.PrintError(f"WaferScan: {message}\n")
    else:
        App.Console.PrintMessage(f"WaferScan: {message}\n")
    icon = QtGui.QMessageBox.Warning if error else QtGui.QMessageBox.Information
    box = QtGui.QMessageBox(icon, title, str(message), QtGui.QMessageBox.Ok, Gui.getMainWindow())
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    session.keep_message_box(box)
    return box


def ask(question, choices, title="WaferScan"):
    """A question the user must answer before going on: ``choices`` are (button text, Qt
    button role) pairs; returns the text of the button clicked, None when the box was closed."""
    box = QtGui.QMessageBox(QtGui.QMessageBox.Question, title, question,
                            QtGui.QMessageBox.NoButton, Gui.getMainWindow())
    buttons = [(box.addButton(text, button_role), text) for text, button_role in choices]
    box.exec_()
    clicked = box.clickedButton()
    return next((text for button, text in buttons if button is clicked), None)


@contextmanager
def transaction(doc, name):
    """One undo step named ``name`` around the block: committed when it ends, aborted (the
    document left as it was) when it raises."""
    doc.openTransaction(name)
    try:
        yield
    except BaseException:
        doc.abortTransaction()
        raise
    doc.commitTransaction()


def _ours_open():
    panel = session.task_panel
    return panel is not None and panel.is_open()


def check_no_other_task_panel():
    """One task panel at a time, as in FreeCAD: another tool's open panel (a sketch being
    edited, say) is the user's to close, not ours."""
    if Gui.Control.activeDialog() and not _ours_open():
        raise InputError("task panel", None, "another task panel is open: close it first")


def show_task_panel(panel):
    """Show our panel; ours that is open is shut down first (its animation stopped, its
    watching ended). Returns the panel."""
    previous = session.task_panel
    if previous is not None:
        previous.shut_down()
    if Gui.Control.activeDialog():
        Gui.Control.closeDialog()
    Gui.Control.showDialog(panel)
    session.task_panel = panel
    return panel
