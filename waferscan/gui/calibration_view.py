"""The Calibrate command's dialog (SPEC §11): the layout's current recipe beside the one its
reference wafers give, and the check scan's slot code; "Save recipe…" writes the calibrated
recipe as ``waferscan calibrate --out`` does and "Apply to document" writes it into the layout
(one undo step), each as a recorded line (``commands.save_calibration_recipe``,
``commands.apply_calibration``) that replays without this dialog."""

from __future__ import annotations

import html
import os

from PySide import QtCore, QtGui

from ..addon import icon_path
from .session import doc_ref, record

COLUMNS = ("Key", "Current", "Calibrated")


def shown(value):
    """A recipe value as the table shows it: lengths to 0.1 µm, the rest as they are."""
    return f"{value:.4f}" if isinstance(value, float) else str(value)


def calibration_dialog(calibration, title, parent=None, doc=None):
    """A non-modal dialog with the table (one row a key: current, calibrated; changed values
    bold), the check scan's code and, for a calibration of ``doc``, Save recipe… and Apply to
    document."""
    dialog = QtGui.QDialog(parent)
    dialog.setWindowTitle(title)
    dialog.setWindowIcon(QtGui.QIcon(icon_path("WaferScan_Calibrate.svg")))
    rows = calibration.rows()
    table = QtGui.QTableWidget(len(rows), len(COLUMNS), dialog)
    table.setObjectName("recipe")
    table.setHorizontalHeaderLabels(list(COLUMNS))
    table.verticalHeader().setVisible(False)
    table.verticalHeader().setDefaultSectionSize(22)
    table.horizontalHeader().setStretchLastSection(True)
    table.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
    for row, (key, old, new) in enumerate(rows):
        for column, text in enumerate((key, shown(old), shown(new))):
            item = QtGui.QTableWidgetItem(text)
            if column:
                item.setTextAlignment(QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter)
            if column == 2 and shown(old) != shown(new):
                font = item.font()
                font.setBold(True)
                item.setFont(font)
            table.setItem(row, column, item)
    table.resizeColumnsToContents()
    check = calibration.check
    n = calibration.after.scanned_carrier.slot_count
    label = QtGui.QLabel(
        f"Measured from the reference wafers in slots 1 and {n}. Check scan with the calibrated "
        f"recipe: slot code <b>{html.escape(check.code)}</b> (E87 {html.escape(check.e87)}).")
    label.setObjectName("check")
    label.setWordWrap(True)
    label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
    buttons = QtGui.QDialogButtonBox(QtGui.QDialogButtonBox.Close, parent=dialog)
    buttons.rejected.connect(dialog.close)
    status = QtGui.QLabel("")
    status.setObjectName("status")
    status.setWordWrap(True)
    status.hide()
    if doc is not None:
        _document_buttons(dialog, buttons, status, calibration, doc)
    box = QtGui.QVBoxLayout(dialog)
    box.addWidget(table)
    box.addWidget(label)
    box.addWidget(status)
    box.addWidget(buttons)
    width = sum(table.columnWidth(c) for c in range(len(COLUMNS))) + 60
    dialog.resize(max(width, 460), 170 + 22 * len(rows))
    dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    return dialog


def table_contents(dialog):
    """The dialog's table as rows of cell texts (what a user reads; the GUI test's too)."""
    table = dialog.findChild(QtGui.QTableWidget, "recipe")
    return [[table.item(r, c).text() for c in range(table.columnCount())]
            for r in range(table.rowCount())]


def _document_buttons(dialog, buttons, status, calibration, doc):
    """Save recipe… and Apply to document: each runs a recorded line that calibrates the
    document again, so each is offered only while the document reads as it did when this
    calibration was made (else the user is told to calibrate again)."""
    from .session import report

    save = buttons.addButton("Save recipe…", QtGui.QDialogButtonBox.ActionRole)
    save.setObjectName("save")
    save.setToolTip("Write the calibrated recipe as a parameters.txt (as waferscan calibrate "
                    "--out writes it), for the MCS or waferscan scan --params")
    apply = buttons.addButton("Apply to document", QtGui.QDialogButtonBox.ActionRole)
    apply.setObjectName("apply")
    apply.setToolTip("Write the calibrated seat, pitch, scan range and recipe into the layout "
                     "(one undo step); the wafers stay where they are")

    def still_current(what):
        if _reads_as(doc, calibration.before):
            return True
        report(f"{what}: {_label(doc)} changed since this calibration: run Calibrate again",
               error=True)
        return False

    def on_save():
        if not still_current("Save recipe"):
            return
        folder = os.path.dirname(doc.FileName) if doc.FileName else os.getcwd()
        path, _ = QtGui.QFileDialog.getSaveFileName(
            dialog, "Save the calibrated recipe", os.path.join(folder, "recipe.txt"),
            "Parameters (*.txt);;All files (*)", None, QtGui.QFileDialog.DontUseNativeDialog)
        if not path:
            return
        before = _signature(path)
        record(f"save_calibration_recipe({doc_ref(doc)}, {path!r})")
        if _signature(path) not in (None, before):  # written (a failure was reported)
            status.setText(f"Recipe saved to {html.escape(path)}.")
            status.show()

    def on_apply():
        if not still_current("Apply to document"):
            return
        if not calibration.changes():  # said, not written: no empty undo step
            status.setText(f"{html.escape(doc.Label)} already holds the calibrated recipe: "
                           "nothing to apply.")
            status.show()
            return
        record(f"apply_calibration({doc_ref(doc)})")
        if _reads_as(doc, calibration.before):
            return  # not applied: the reason was reported
        apply.setEnabled(False)
        save.setEnabled(False)
        status.setText(f"Applied to {html.escape(doc.Label)} as one undo step, "
                       "<i>Apply calibration</i> (Edit → Undo takes it back). Calibrate "
                       "again to save a recipe from the document as it is now.")
        status.show()

    save.clicked.connect(on_save)
    apply.clicked.connect(on_apply)


def _signature(path):
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_ino, st.st_mtime_ns, st.st_size


def _label(doc):
    try:
        return doc.Label
    except Exception:  # noqa: BLE001 (closed)
        return "the document"


def _reads_as(doc, layout):
    """Whether the document reads as ``layout`` now (a document that cannot be read does not)."""
    from ..cad.reader import read_layout

    try:
        return read_layout(doc) == layout
    except Exception:  # noqa: BLE001 (deleted objects, a closed document, bad settings)
        return False
