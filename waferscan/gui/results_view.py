"""Showing a scan's results: the table of the paper's Table 1 (kept in the document as a
Spreadsheet by cad.results_sheet) and the slot-code dialog. Everything shown comes from a core ``ScanResult``;
nothing is computed here."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..cad.results_sheet import COLUMNS, columns, table_cells
from ..core.files.report import STATE_COLOURS, duration_note
from ..core.errors import InputError
from ..core.mapping import E87, STATE_NAMES
from .inputs import length_unit
from .qt import fitted_size
from .session import doc_ref, last_result, record, report
from .side_view import SideView

MM = " [mm]"


def shown_columns(result):
    """The table's headers with its lengths in the user's unit ("IN [in]" in an inch schema);
    an exported CSV keeps the stored columns, in mm."""
    unit, _ = length_unit()
    return [c.replace(MM, f" [{unit}]") for c in columns(result)]


def shown_cell(header, text):
    """A cell's text as the table shows it: a length column's mm in the user's unit, to the
    same resolution (two more decimals in inches)."""
    unit, factor = length_unit()
    if factor == 1.0 or not header.endswith(MM) or not text:
        return text
    try:
        value = float(text)
    except ValueError:
        return text
    decimals = len(text.partition(".")[2]) + 2
    return f"{value / factor:.{decimals}f}"


def export_start(doc):
    """Where Export CSV… starts: next to the saved document, named after it; for a document
    never saved, in the user's home folder (not FreeCAD's working directory)."""
    if doc is not None and doc.FileName:
        return str(Path(doc.FileName).with_name(f"{Path(doc.FileName).stem}-results.csv"))
    label = doc.Label if doc is not None else "results"
    return str(Path.home() / f"{label}-results.csv")


class ResultsTable(QtGui.QDialog):
    """Slot, slot Z, wafer, IN, OUT, diff and state, coloured by state. Selecting a row selects
    its wafer in the 3D view; the table can be exported as CSV."""

    def __init__(self, result, doc=None, parent=None):
        super().__init__(parent or Gui.getMainWindow())
        self.setWindowTitle("WaferScan results")
        self.result, self.doc = result, doc
        self.table = QtGui.QTableWidget(0, len(columns(result)), self)
        self.table.setHorizontalHeaderLabels(shown_columns(result))
        headers = columns(result)
        self.table.setSelectionBehavior(QtGui.QAbstractItemView.SelectRows)
        self.table.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
        for cells, code in table_cells(result):
            row = self.table.rowCount()
            self.table.insertRow(row)
            for column, text in enumerate(cells):
                item = QtGui.QTableWidgetItem(shown_cell(headers[column], text))
                if column == 6:
                    item.setBackground(QtGui.QColor(*STATE_COLOURS[code]))
                if column in (0, 1, 3, 4, 5) or column >= len(COLUMNS):
                    item.setTextAlignment(QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter)
                self.table.setItem(row, column, item)
        self.table.resizeColumnsToContents()
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().setVisible(False)  # the Slot column numbers the rows
        self.table.itemSelectionChanged.connect(self._select_wafer)
        export = QtGui.QPushButton("Export CSV…", self)
        export.setToolTip("Save the table as a CSV file")
        export.clicked.connect(self._export)
        layout = QtGui.QVBoxLayout(self)
        layout.addWidget(QtGui.QLabel(f"Slot code <b>{result.code}</b> (engine {result.engine})"))
        layout.addWidget(self.table)
        layout.addWidget(export)
        # Wide enough for every column (a slow scan's Front and Sweep ones too), within the
        # screen: no sideways scrolling to read a row.
        frame = self.table.frameWidth() * 2 + self.table.verticalScrollBar().sizeHint().width()
        width = sum(self.table.columnWidth(c) for c in range(self.table.columnCount()))
        margins = layout.contentsMargins()
        wanted = max(620, width + frame + margins.left() + margins.right() + 4)
        self.resize(*fitted_size(wanted, 700))

    def rows(self):
        """The table's text, row by row (what a user sees)."""
        return [[self.table.item(r, c).text() for c in range(self.table.columnCount())]
                for r in range(self.table.rowCount())]

    def _select_wafer(self):
        if self.doc is None:
            return
        Gui.Selection.clearSelection()
        for index in self.table.selectionModel().selectedRows():
            for name in self.table.item(index.row(), 2).text().split(", "):
                for obj in self.doc.getObjectsByLabel(name):
                    Gui.Selection.addSelection(obj)

    def export_csv(self, path):
        """Write the table (this dialog's result) as CSV to ``path``, whole or not at all, in
        mm whatever the unit schema (as stored); InputError when it cannot be written."""
        write_csv(self.result, path)

    def _export(self):
        path, _ = QtGui.QFileDialog.getSaveFileName(self, "Export results", export_start(self.doc),
                                                    "CSV (*.csv)")
        if not path:
            return
        if self.doc is not None and last_result(self.doc) is self.result:
            # The line a macro replays: the document's last scan, exported (it says what
            # went wrong itself).
            record(f"export_results_csv({doc_ref(self.doc)}, {path!r})")
            return
        try:
            self.export_csv(path)
        except InputError as exc:
            report(f"Export CSV: nothing written: {exc}", error=True)
            return
        App.Console.PrintMessage(f"WaferScan: results exported to {path}\n")


def csv_text(result):
    """The results table as CSV text: the header, then a row per slot as the table shows it."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\r\n")
    writer.writerow(columns(result))
    writer.writerows(cells for cells, _ in table_cells(result))
    return buffer.getvalue()


def write_csv(result, path):
    """``csv_text`` written to ``path`` whole or not at all (InputError: a path that cannot be
    a file, or a folder that cannot be written in)."""
    from ..core.files.text_files import atomic_write_text, check_output_path

    check_output_path(path, "the CSV file")
    try:
        atomic_write_text(path, csv_text(result))
    except OSError as exc:
        raise InputError(path, None, f"cannot write: {exc.strerror or exc}") from None


def export_results_csv(doc, path):
    """Write the results table of the document's last scan as CSV to ``path`` (what the table's
    Export CSV… records). A document never scanned, or a path that cannot be written, is said
    to the user (nothing written); returns the path written, or None."""
    result = last_result(doc)
    try:
        if result is None:
            raise InputError(doc.Label, None, "no scan to export: use Run scan first")
        write_csv(result, path)
    except InputError as exc:
        report(f"Export CSV: nothing written: {exc}", error=True)
        return None
    App.Console.PrintMessage(f"WaferScan: results exported to {path}\n")
    return path


class SlotCodeDialog(QtGui.QDialog):
    """The slot code in large type, a strip of per-slot cells coloured by state (as the paper's
    Fig. 7), a side view of the carrier with the sensor runs against the slots (as its Fig. 6),
    the SEMI E87 map, and a button to copy the code."""

    def __init__(self, result, parent=None, doc=None):
        super().__init__(parent or Gui.getMainWindow())
        self.setWindowTitle("WaferScan slot code")
        self.result = result
        self.code_label = QtGui.QLabel(result.code, self)
        font = self.code_label.font()
        font.setPointSize(22)
        font.setFamily("Monospace")
        self.code_label.setFont(font)
        self.code_label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        strip = QtGui.QHBoxLayout()
        strip.setSpacing(2)
        self.cells = []
        for slot in result.slot_map.slots:
            cell = QtGui.QLabel(f"{slot.slot}\n{slot.state}", self)
            cell.setAlignment(QtCore.Qt.AlignCenter)
            cell.setMinimumSize(18, 36)  # 25 slots fit a 1024 px screen
            r, g, b = STATE_COLOURS[slot.state]
            cell.setStyleSheet(f"background: rgb({r},{g},{b}); border: 1px solid #777;")
            cell.setToolTip(f"slot {slot.slot}: {STATE_NAMES[slot.state]}, E87 {E87[slot.state]}")
            self.cells.append(cell)
            strip.addWidget(cell)
        copy = QtGui.QPushButton("Copy code", self)
        copy.setToolTip("Copy the slot code to the clipboard")
        copy.clicked.connect(self.copy_code)
        self.e87_label = QtGui.QLabel(f"SEMI E87 slot map:\n{result.e87}", self)
        self.e87_label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        self.e87_label.setToolTip("E87 SlotMap values: 0 undefined (not wholly scanned), 1 "
                                  "empty, 2 not empty (thin, out of position, protruding), 3 "
                                  "correctly occupied, 4 double slotted, 5 cross slotted")
        legend = QtGui.QVBoxLayout()
        for code, name in STATE_NAMES.items():
            r, g, b = STATE_COLOURS[code]
            swatch = QtGui.QLabel(f"{code}  {name}", self)
            swatch.setStyleSheet(f"background: rgb({r},{g},{b}); padding: 2px 6px;")
            legend.addWidget(swatch)
        # SPEC §14: a carrier loaded on the host link: the host's verification of this map
        self.host_label = QtGui.QLabel(self)
        # its own lines' height always (a line for the status, one for a failure's reason):
        # the plots below give way when the reason is added
        self.host_label.setSizePolicy(QtGui.QSizePolicy.Preferred, QtGui.QSizePolicy.Fixed)
        self.host_label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        self.host_label.hide()
        self.side_view = SideView(result, STATE_COLOURS, self)
        # SPEC §13: the simulated time of a fast and of a slow scan side by side (the trade-off).
        durations = result.durations
        note = duration_note(result)
        self.duration_label = QtGui.QLabel(
            f"Simulated duration:\nfast {durations['fast']:.2f} s, slow {durations['slow']:.2f} s"
            + ("\n(lift acceleration not set)" if note else ""), self)
        self.duration_label.setToolTip(
            "A fast scan: one stroke at scan_speed. A slow scan: pocket by pocket, each Z step "
            "from rest to rest with a read at rest, and the jab and the sweep at each pocket "
            "(arm and wrist speeds and accelerations from the scan settings)"
            + (f". {note[0].upper()}{note[1:]}." if note else ""))
        side = QtGui.QVBoxLayout()
        side.addWidget(self.e87_label)
        side.addWidget(self.duration_label)
        side.addLayout(legend)
        side.addStretch(1)
        side.addWidget(copy)
        lower = QtGui.QHBoxLayout()
        self.plan_view = None
        if result.pockets:  # SPEC §13: each probed pocket seen from above, beside the side view
            from .plan_view import PocketPlanView

            self.plan_view = PocketPlanView(result, STATE_COLOURS, self, doc)
            self.views = QtGui.QTabWidget(self)
            self.views.addTab(self.side_view, "Side view")
            self.views.addTab(self.plan_view, "Pockets from above")
            lower.addWidget(self.views, 1)
        else:
            lower.addWidget(self.side_view, 1)
        lower.addLayout(side)
        layout = QtGui.QVBoxLayout(self)
        layout.addWidget(self.code_label)
        layout.addWidget(self.host_label)  # one line under the code, the width of the dialog
        layout.addLayout(strip)
        # SPEC §15: the least clearance of the scan's motions, and each contact
        self.clearance_label, self.contacts = clearance_widgets(result, self)
        if self.clearance_label is not None:
            layout.addWidget(self.clearance_label)
        if self.contacts is not None:
            layout.addWidget(self.contacts)
        from .signal_view import SignalView  # SPEC §10: the sensor's signal, the whole scan

        self.signal_view = SignalView(result, self)
        layout.addWidget(self.signal_view)
        layout.addLayout(lower, 1)

    def copy_code(self):
        QtGui.QApplication.clipboard().setText(self.result.code)
        App.Console.PrintMessage(f"WaferScan: slot code {self.result.code} copied\n")

    def set_host_status(self, carrier_id, status, reason=""):
        """Show the host's verification of this map (SPEC §14): the carrier's E87 slot-map
        status (``host.e87``), green when verified, red with the reason when it failed."""
        from ..host.e87 import STATUS_NAMES, VERIFICATION_FAILED, VERIFICATION_OK

        text = f"Host verification of {carrier_id}: {STATUS_NAMES[status]}"
        if reason:
            text += f"\n{reason}"
        colour = {VERIFICATION_OK: "#c8f0c8", VERIFICATION_FAILED: "#f4c4c4"}.get(status)
        self.host_label.setStyleSheet(f"background: {colour}; padding: 4px;" if colour else "")
        self.host_label.setText(text)
        self.host_label.show()


CONTACT_HEADERS = ("Distance [mm]", "Robot", "Obstacle", "Slot", "Motion", "Position")


def clearance_words(report):
    """The slot-code dialog's line on SPEC §15's clearance: the least distance of the scan's
    motions, where, and against clearance_min; the contacts counted when there are any."""
    from ..core.scan.clearance import describe

    least = report.least
    if least is None:
        return f"Clearance: no motion checked (clearance_min {report.clearance_min:g} mm)"
    text = f"Least clearance {describe(least)}; clearance_min {report.clearance_min:g} mm"
    contacts = report.contacts
    if contacts:
        text += (f". {len(contacts)} contact{'s' if len(contacts) > 1 else ''} closer than "
                 "clearance_min: the robot must not run this scan")
    return text


def contact_row(c):
    """A contact's cells (CONTACT_HEADERS), as ``clearance.describe`` words them."""
    from ..core.scan.clearance import _WHERE  # the words describe() gives a position

    where = _WHERE[c.motion.unit].format(c.position)
    if c.motion.z is not None and c.motion.unit != "z":
        where += f" at scan position {c.motion.z:.3f} mm"
    return (f"{c.distance:.3f}" + ("" if c.exact else " (at least)"), c.part, c.obstacle,
            "" if c.slot is None else str(c.slot), c.motion.phase, where)


def clearance_widgets(result, parent):
    """(label, table): the least clearance in words (red with a contact), and a table of the
    contacts (None when there is none); (None, None) when the scan's clearance was not checked
    (no pinocchio)."""
    from ..core.scan.clearance import describe

    report = getattr(result, "clearance", None)
    if report is None:
        return None, None
    label = QtGui.QLabel(clearance_words(report), parent)
    label.setWordWrap(True)
    label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
    label.setToolTip("SPEC §15: the least distance between the robot's collision geometry (its "
                     "URDF's, or the scanner's heads without a robot) and every wafer, along "
                     "each motion of the scan")
    contacts = report.contacts
    if not contacts:
        return label, None
    label.setStyleSheet("color: #c01010; font-weight: bold;")
    table = QtGui.QTableWidget(len(contacts), len(CONTACT_HEADERS), parent)
    table.setHorizontalHeaderLabels(list(CONTACT_HEADERS))
    table.verticalHeader().setVisible(False)
    table.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
    for row, c in enumerate(contacts):
        for column, text in enumerate(contact_row(c)):
            item = QtGui.QTableWidgetItem(text)
            item.setToolTip(describe(c))
            table.setItem(row, column, item)
    table.resizeColumnsToContents()
    table.horizontalHeader().setStretchLastSection(True)
    rows = min(len(contacts), 4)
    table.setFixedHeight(table.horizontalHeader().height() + rows * table.rowHeight(0) + 6)
    table.setToolTip("Each motion of the scan that comes closer than clearance_min")
    return label, table
