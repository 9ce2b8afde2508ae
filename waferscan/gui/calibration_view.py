"""The Calibrate command's dialog (SPEC §11): the layout's current recipe beside the one its
reference wafers give, and the check scan's slot code."""

from __future__ import annotations

import html

from PySide import QtCore, QtGui

from ..addon import icon_path

COLUMNS = ("Key", "Current", "Calibrated")


def shown(value):
    """A recipe value as the table shows it: lengths to 0.1 µm, the rest as they are."""
    return f"{value:.4f}" if isinstance(value, float) else str(value)


def calibration_dialog(calibration, title, parent=None):
    """A non-modal dialog with the table (one row a key: current, calibrated; changed values
    bold) and the check scan's code."""
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
    box = QtGui.QVBoxLayout(dialog)
    box.addWidget(table)
    box.addWidget(label)
    box.addWidget(buttons)
    width = sum(table.columnWidth(c) for c in range(len(COLUMNS))) + 60
    dialog.resize(max(width, 420), 150 + 22 * len(rows))
    dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    return dialog


def table_contents(dialog):
    """The dialog's table as rows of cell texts (what a user reads; the GUI test's too)."""
    table = dialog.findChild(QtGui.QTableWidget, "recipe")
    return [[table.item(r, c).text() for c in range(table.columnCount())]
            for r in range(table.rowCount())]
