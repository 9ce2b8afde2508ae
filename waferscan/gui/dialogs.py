"""The windows the commands open, each from the layout as it is now: the results table and the
slot code (one of each per document, closed with it), the B-rep cross-check, the calibration
(SPEC §11) and the tolerance study (SPEC §12) (the MCS link's task panel: ``mcs_script``). Everything shown comes
from ``cad`` and ``core``; nothing is computed here."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..core.errors import InputError, WaferScanError
from .qt import alive, fitted_size
from .scanning import result_now
from .session import report, session, transaction

__all__ = ["show_results_dialogs", "fit_screen", "cross_check", "calibrate_layout",
           "apply_calibration", "save_calibration_recipe", "open_tolerance_study"]

DIALOG_TITLES = {"table": "WaferScan results", "code": "WaferScan slot code"}


def show_results_dialogs(doc=None, which=("table", "code"), result=None):
    """The results table and/or the slot-code dialog of ``result``, by default of the document
    as it is now. One of each per document: a later scan's replaces the earlier one in the
    same place, so that dialogs do not pile up; titles name the document."""
    from .results_view import ResultsTable, SlotCodeDialog

    doc = doc or App.ActiveDocument
    result = result or result_now(doc)
    if session.close_watcher is None:
        session.close_watcher = _ClosedDocuments()
        App.addDocumentObserver(session.close_watcher)
    views = session.results_windows.setdefault(doc.Name, {})
    dialogs = []
    for kind in which:
        dialog = (ResultsTable(result, doc) if kind == "table"
                  else SlotCodeDialog(result, doc=doc))
        dialog.setWindowTitle(f"{DIALOG_TITLES[kind]}: {doc.Label}")
        dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        if kind == "code":  # room for the side view, on screens that have it
            dialog.resize(max(dialog.width(), 760), max(dialog.height(), 600))
        old = views.get(kind)
        if alive(old) and old.isVisible():
            dialog.setGeometry(old.geometry())
            old.close()
        else:
            fit_screen(dialog)
        views[kind] = dialog
        dialog.show()
        dialog.raise_()
        dialogs.append(dialog)
    session.dialogs = dialogs
    return dialogs


class _ClosedDocuments:
    """A document closed: its results dialogs close too (they would point at nothing)."""

    def slotDeletedDocument(self, doc):  # noqa: N802 (FreeCAD's name)
        for dialog in session.results_windows.pop(doc.Name, {}).values():
            if alive(dialog):
                dialog.close()
        session.results.pop(doc.Name, None)


def fit_screen(dialog, margin=(40, 80)):
    """Shrink a dialog to the screen the main window is on (1024×700 included), less a
    margin for the window frame and the desktop's panels."""
    size = dialog.size()
    dialog.resize(*fitted_size(size.width(), size.height(), margin))


def cross_check(doc):
    """The B-rep cross-check of the document's last scan, reported in the report view and a
    dialog."""
    from ..cad.crosscheck import crosscheck
    from ..core.files.report import format_crosscheck

    result = result_now(doc)
    QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
    Gui.getMainWindow().statusBar().showMessage("WaferScan: cross-checking with OpenCASCADE…")
    try:
        check = crosscheck(doc, result)
    finally:
        QtGui.QApplication.restoreOverrideCursor()
        Gui.getMainWindow().statusBar().clearMessage()
    text = format_crosscheck(check)
    motions = ""
    if check.clearance is not None:  # SPEC §15: each motion's least distance, coal vs B-rep
        from ..cad.clearance_brep import format_clearance

        *lines, verdict = text.split("\n")
        text = "\n".join([*lines, format_clearance(check.clearance), "", verdict])
        count = len(check.clearance.checks)
        motions = f" and the clearance of {count} motion{'' if count == 1 else 's'}"
    (App.Console.PrintMessage if check.ok else App.Console.PrintWarning)(
        f"WaferScan cross-check of {doc.Label}:\n{text}\n")
    box = QtGui.QMessageBox(QtGui.QMessageBox.Information if check.ok
                            else QtGui.QMessageBox.Warning, "WaferScan cross-check",
                            f"{'Confirmed' if check.ok else 'NOT confirmed'}: largest deviation "
                            f"{check.largest_deviation:.2e} mm over {len(check.wafers)} wafers "
                            f"and {len(check.runs)} sensor runs{motions}.",
                            QtGui.QMessageBox.Ok, Gui.getMainWindow())
    box.setDetailedText(text)
    box.setWindowTitle(f"WaferScan cross-check: {doc.Label}")
    for details in box.findChildren(QtGui.QTextEdit):  # a table: its columns line up
        details.setFont(QtGui.QFontDatabase.systemFont(QtGui.QFontDatabase.FixedFont))
        details.setLineWrapMode(QtGui.QTextEdit.NoWrap)
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    session.dialogs = [box]
    return check


def calibrate_layout(doc):
    """SPEC §11: calibrate the document's recipe from its reference wafers (slots 1 and n) and
    show the calibrated recipe beside the current one with the check scan's code. A failure is
    reported in its own words. Returns the core Calibration, or None."""
    from ..cad.document_calibration import calibrate_document
    from ..core.scan.calibration import CalibrationError, format_calibration
    from .calibration_view import calibration_dialog

    QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
    try:
        calibration = calibrate_document(doc)
    except CalibrationError as exc:
        report(f"Calibration of {doc.Label} failed: {exc}", error=True)
        return None
    finally:
        QtGui.QApplication.restoreOverrideCursor()
    App.Console.PrintMessage(f"WaferScan calibration of {doc.Label}:\n"
                             f"{format_calibration(calibration)}\n")
    dialog = calibration_dialog(calibration, f"WaferScan calibration: {doc.Label}",
                                Gui.getMainWindow(), doc)
    dialog.show()
    session.dialogs = [dialog]
    return calibration


def _calibrated(doc, what):
    """The document's calibration as ``calibrate_layout`` makes it, or None when it cannot be
    made: the failure (a user's: CalibrationError, InputError) is reported in its own words,
    ``what`` naming the action."""
    from ..cad.document_calibration import calibrate_document

    QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
    try:
        return calibrate_document(doc)
    except WaferScanError as exc:
        report(f"{what} of {doc.Label}: nothing done: {exc}", error=True)
        return None
    finally:
        QtGui.QApplication.restoreOverrideCursor()


def apply_calibration(doc):
    """SPEC §11, "Apply to document": calibrate the document as it is now and write the
    calibrated recipe into it, in one undo step named "Apply calibration": the scanned
    carrier's taught slot-1 seat and pitch, the scan range and the recipe's keys on
    ScanSettings. The wafers stay where they are. Returns the Calibration, or None when the
    document cannot be calibrated (reported, the document left as it is)."""
    from ..cad.document_calibration import apply_calibration as write_calibration
    from ..core.scan.calibration import shown_value

    calibration = _calibrated(doc, "Apply calibration")
    if calibration is None:
        return None
    changed = [f"{key} {shown_value(key, old)} → {shown_value(key, new)}"
               for key, old, new in calibration.changes()]
    if not changed:  # no undo step, and a range that follows the carrier keeps following
        App.Console.PrintMessage(f"WaferScan: {doc.Label} already holds the calibrated "
                                 "recipe: nothing to apply\n")
        return calibration
    try:
        with transaction(doc, "Apply calibration"):
            write_calibration(doc, calibration)
    except InputError as exc:  # the carrier deleted since it was read: nothing written
        report(f"Apply calibration of {doc.Label}: nothing done: {exc}", error=True)
        return None
    App.Console.PrintMessage(f"WaferScan: applied the calibration to {doc.Label}: "
                             f"{', '.join(changed)}\n")
    return calibration


def save_calibration_recipe(doc, path):
    """SPEC §11, "Save recipe…": calibrate the document as it is now and write the calibrated
    recipe to ``path`` as a whole parameters.txt, atomically: byte for byte what
    ``waferscan calibrate LAYOUT --out FILE`` writes. Returns the Calibration, or None (the
    failure reported, nothing written)."""
    from ..core.files.mcs import format_parameters
    from ..core.files.text_files import atomic_write_text, check_output_path

    calibration = _calibrated(doc, "Save recipe")
    if calibration is None:
        return None
    try:
        check_output_path(path, "the recipe")
        try:
            atomic_write_text(path, format_parameters(calibration.after))
        except OSError as exc:
            raise InputError(path, None, f"cannot write: {exc.strerror or exc}") from None
    except InputError as exc:
        report(f"Save recipe of {doc.Label}: nothing written: {exc}", error=True)
        return None
    App.Console.PrintMessage(f"WaferScan: calibrated recipe of {doc.Label} written to {path}\n")
    return calibration


def open_tolerance_study(input_path="", **settings):
    """The "Tolerance study…" dialog (SPEC §12), non-modal; ``settings`` preset its fields
    (tolerances, n, seed, workers, out). Returns the dialog."""
    from .tolerance_dialog import open_study

    return open_study(input_path, **settings)
