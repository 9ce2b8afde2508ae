"""The host link task panel (SPEC §14): the active layout's carriers as SEMI E87 load ports of an
HSMS equipment that a factory host connects to, as ``waferscan serve`` makes them, in the GUI.

The panel has the address to listen on (or, with Active, the host to reach), an optional IDs
file, the connection's state, a row per load port (its carrier, the CarrierID loaded, the
slot-map status and the slot code), a Load button that places a carrier on a port (it is
scanned here, in the document, by the analytic engine), and the log: every change of state,
and every HSMS message decoded (SML). A loaded carrier's slot code is shown in the slot-code
dialog, which then follows the host's verification: VERIFICATION OK, or FAILED with its reason.

The equipment answers the host from secsgem's threads; everything the panel shows reaches it
through a queue read by a timer on the GUI thread, and scans run on the GUI thread only.
Closing the panel or the document stops the link.
"""

from __future__ import annotations

import queue

from PySide import QtCore, QtGui

from ..cad.reader import read_layout
from ..core.errors import InputError
from ..host.e87 import STATUS_NAMES, VERIFICATION_FAILED, VERIFICATION_OK
from .qt import ClosableTaskPanel, alive

__all__ = ["HostLinkPanel", "open_host_panel"]

DEFAULT_ADDRESS = "127.0.0.1:5000"
PORT_COLUMNS = ("Port", "CarrierID", "Slot map status", "Slot code")
LOG_LINES = 5000  # the log keeps this many lines
POLL_MS = 100


class HostLinkPanel(ClosableTaskPanel):
    def __init__(self, doc):
        self.doc = doc
        self.link = self.equipment = self.message_log = self._quiet = None
        self.dialogs = {}  # port -> the SlotCodeDialog of its last carrier
        self.events = queue.Queue()  # (kind, text) from any thread
        self.form = form = QtGui.QWidget()
        form.setWindowTitle("Host link")
        layout = QtGui.QVBoxLayout(form)

        settings = QtGui.QFormLayout()
        self.address = QtGui.QLineEdit(DEFAULT_ADDRESS, form)
        self.address.setToolTip("HOST:PORT the equipment listens on (with Active: the host "
                                "it connects to)")
        self.active = QtGui.QCheckBox("Active (connect to the host)", form)
        self.ids_path = QtGui.QLineEdit(form)
        self.ids_path.setPlaceholderText("default IDs (docs: Verifying slot maps)")
        self.ids_path.setToolTip("IDS.toml: the tool's CEIDs, DVIDs, SVIDs and ports")
        settings.addRow("Address:", self.address)
        settings.addRow("", self.active)
        settings.addRow("IDs file:", self.ids_path)
        layout.addLayout(settings)
        buttons = QtGui.QHBoxLayout()
        self.start_button = QtGui.QPushButton("Start", form)
        self.stop_button = QtGui.QPushButton("Stop", form)
        self.stop_button.setEnabled(False)
        self.start_button.clicked.connect(self.start)
        self.stop_button.clicked.connect(self.stop)
        buttons.addWidget(self.start_button)
        buttons.addWidget(self.stop_button)
        layout.addLayout(buttons)
        self.state = QtGui.QLabel("not started", form)
        self.state.setWordWrap(True)
        layout.addWidget(self.state)

        self.ports = QtGui.QTableWidget(0, len(PORT_COLUMNS), form)
        self.ports.setHorizontalHeaderLabels(PORT_COLUMNS)
        self.ports.verticalHeader().setVisible(False)
        self.ports.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
        header = self.ports.horizontalHeader()
        for column in range(len(PORT_COLUMNS)):
            header.setSectionResizeMode(column, QtGui.QHeaderView.ResizeToContents)
        header.setSectionResizeMode(2, QtGui.QHeaderView.Stretch)
        layout.addWidget(self.ports)

        load = QtGui.QHBoxLayout()
        self.carrier_id = QtGui.QLineEdit(form)
        self.carrier_id.setPlaceholderText("CarrierID")
        self.port_choice = QtGui.QComboBox(form)
        self.load_button = QtGui.QPushButton("Load", form)
        self.load_button.setToolTip("Place a carrier with this ID on the port: it is scanned, "
                                    "and the host is told (SLOT MAP NOT READ, then WAITING FOR "
                                    "HOST)")
        self.load_button.setEnabled(False)
        self.load_button.clicked.connect(self.load)
        load.addWidget(self.carrier_id, 2)
        load.addWidget(self.port_choice, 1)
        load.addWidget(self.load_button)
        layout.addLayout(load)

        layout.addWidget(QtGui.QLabel("Log (changes of state, HSMS messages):", form))
        self.log = QtGui.QPlainTextEdit(form)
        self.log.setReadOnly(True)
        self.log.setMaximumBlockCount(LOG_LINES)
        font = self.log.font()
        font.setFamily("Monospace")
        self.log.setFont(font)
        layout.addWidget(self.log, 1)
        self.alive_while_shown = self.log
        self.timer = QtCore.QTimer(form)
        self.timer.timeout.connect(self.drain)
        self.follow_document(doc)

    # --- the link --------------------------------------------------------------------------

    def start(self):
        """Start the equipment on the address given; an error is said in the state line."""
        from ..host import hsms, messages
        from ..host.equipment import LoadPortEquipment
        from ..host.ids import default_ids, read_ids
        from ..host.link import HostLink
        from ..host.server import (check_port_free, layout_scanner, library_log_on_stderr,
                                   parse_address)

        if self.link is not None:
            return
        try:
            ids = read_ids(self.ids_path.text().strip()) if self.ids_path.text().strip() \
                else default_ids()
            host, port = parse_address(self.address.text().strip(), "Address")
            active = self.active.isChecked()
            if not active:
                check_port_free(host, port, "Address")
            layout = read_layout(self.doc)
            carriers = [(c.name, c.slot_count) for c in layout.carriers]
            link = HostLink(ids, carriers, layout_scanner(self.doc, self.doc.Label, "analytic"),
                            log=lambda text: self.events.put(("log", text)))
            settings = hsms.settings(host, port, active=active, session_id=ids.device_id,
                                     registry=messages.registry())
            equipment = LoadPortEquipment(settings, link,
                                          log=lambda text: self.events.put(("log", text)))
            link.report = self._reporting(equipment.report)
            quiet = library_log_on_stderr()
            quiet.__enter__()  # left in shut_down
            try:
                equipment.enable()
            except BaseException:
                quiet.__exit__(None, None, None)
                raise
            self._quiet = quiet
        except (InputError, OSError, ValueError) as exc:
            self.state.setText(f"not started: {exc}")
            return
        self.link, self.equipment, self.address_text = link, equipment, f"{host}:{port}"
        self.message_log = hsms.attach_log(lambda text: self.events.put(("message", text)),
                                           settings.name)
        for widget in (self.address, self.active, self.ids_path, self.start_button):
            widget.setEnabled(False)
        self.stop_button.setEnabled(True)
        self.load_button.setEnabled(True)
        self.port_choice.clear()
        for p in link.port_ids:
            self.port_choice.addItem(f"{p.number} ({p.carrier})", p.number)
        self.events.put(("log", f"{'connecting to' if active else 'listening on'} "
                                f"{self.address_text} as equipment {ids.mdln} {ids.softrev}"))
        self.refresh()
        self.timer.start(POLL_MS)

    def _reporting(self, report):
        def tell(transition):
            report(transition)
            self.events.put(("transition", transition))

        return tell

    def stop(self):
        """Stop the link (the host is disconnected); the ports' state stays shown."""
        self.shut_down()
        if alive(self.log):
            self.drain()
            self.state.setText("stopped")
            for widget in (self.address, self.active, self.ids_path, self.start_button):
                widget.setEnabled(True)
            self.stop_button.setEnabled(False)
            self.load_button.setEnabled(False)

    def shut_down(self):
        from ..host import hsms

        self.timer.stop()
        if self.equipment is not None:
            self.equipment.close()
        if self.message_log is not None:
            hsms.detach_log(self.message_log)
        if self._quiet is not None:
            self._quiet.__exit__(None, None, None)
        self.link = self.equipment = self.message_log = self._quiet = None

    def load(self):
        """Place the carrier typed on the port chosen: it is scanned now, the host told."""
        from ..host.server import MAX_CARRIER_ID
        from .results_view import SlotCodeDialog

        carrier_id = self.carrier_id.text().strip()
        if not carrier_id or not carrier_id.isascii() or not carrier_id.isprintable() \
                or len(carrier_id) > MAX_CARRIER_ID:
            self.state.setText(f"Load: a CarrierID is 1 to {MAX_CARRIER_ID} printable ASCII "
                               "characters")
            return
        port = self.port_choice.currentData()
        QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
        try:
            arrival = self.link.load(port, carrier_id)
        except InputError as exc:
            self.state.setText(f"Load: {exc.message}")
            return
        finally:
            QtGui.QApplication.restoreOverrideCursor()
        old = self.dialogs.get(port)
        if old is not None and alive(old):
            old.close()
        dialog = SlotCodeDialog(arrival.result)
        dialog.set_host_status(carrier_id, arrival.transitions[-1].status, "")
        dialog.show()
        self.dialogs[port] = dialog
        self.drain()

    # --- what the panel shows ----------------------------------------------------------------

    def drain(self):
        """Show what the link's threads queued: log lines, messages, transitions."""
        lines = []
        while True:
            try:
                kind, item = self.events.get_nowait()
            except queue.Empty:
                break
            if kind == "transition":
                dialog = self.dialogs.get(item.port)
                if dialog is not None and alive(dialog) and item.status is not None:
                    dialog.set_host_status(item.carrier_id, item.status, item.reason)
            else:
                lines.append(item)
        if lines and alive(self.log):
            self.log.appendPlainText("\n".join(lines))
        self.refresh()

    def refresh(self):
        if not alive(self.ports) or self.link is None:
            return
        link = self.link
        if self.ports.rowCount() != len(link.port_ids):
            self.ports.setRowCount(len(link.port_ids))
            rows = min(len(link.port_ids), 6)
            self.ports.setMaximumHeight(self.ports.horizontalHeader().height()
                                        + rows * self.ports.verticalHeader()
                                        .defaultSectionSize() + 6)
        for row, p in enumerate(link.port_ids):
            state = link.ports.port(p.number)
            result = link.results.get(p.number)
            status = STATUS_NAMES[state.status] if state.carrier_id else "no carrier"
            code = result.code if result is not None and state.carrier_id else ""
            cells = (f"{p.number} ({p.carrier})", state.carrier_id or "", status, code)
            tips = (f"port {p.number}: the layout's carrier {p.carrier}", cells[1],
                    f"{status}: {state.reason}" if state.reason else status,
                    f"slot code {code}, E87 {result.e87}" if code else "")
            for column, (text, tip) in enumerate(zip(cells, tips)):
                item = QtGui.QTableWidgetItem(text)
                item.setToolTip(tip)
                if column == 3:
                    item.setFont(QtGui.QFont("Monospace"))
                if column == 2 and state.carrier_id:
                    colour = {VERIFICATION_OK: "#c8f0c8",
                              VERIFICATION_FAILED: "#f4c4c4"}.get(state.status)
                    if colour:
                        item.setBackground(QtGui.QColor(colour))
                self.ports.setItem(row, column, item)
        self.state.setText(self._connection_text())

    def _connection_text(self):
        from secsgem.gem.communication_state_machine import CommunicationState

        equipment = self.equipment
        if equipment is None:
            return "stopped"
        communicating = equipment.communication_state.current == \
            CommunicationState.COMMUNICATING
        where = f"{'connecting to' if self.active.isChecked() else 'listening on'} " \
                f"{self.address_text}"
        return f"{where}: a host is connected and communicating" if communicating else \
            f"{where}: no host connected"


def open_host_panel(doc):
    """The host link's task panel on ``doc``; returns it."""
    from .session import check_no_other_task_panel, show_task_panel

    if doc is None:
        raise InputError("host link", None, "open a layout first")
    check_no_other_task_panel()
    return show_task_panel(HostLinkPanel(doc))

