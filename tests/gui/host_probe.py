# Run by FreeCAD's GUI (tests/gui/test_gui_host.py): the paper's layout opened, the Host link
# panel started on WAFERSCAN_GUI_PORT; a secsgem GEM host, unmodified, in a thread of this
# process connects and subscribes to the slot-map events. Load places FOUP0042 (the host
# verifies it with the map it was sent: VERIFICATION OK) and then FOUP0043 (the host expects
# slot 3 occupied: VERIFICATION FAILED). What the panel and the slot-code dialog show is
# recorded, with screenshots; closing the panel frees the port.
import os
import socket
import sys
import threading

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import artifact, finish, later, result, start, task_panel, wait_for, window_shot  # noqa: E402,E501

import FreeCADGui as Gui  # noqa: E402

PORT = int(os.environ["WAFERSCAN_GUI_PORT"])
state = {"events": [], "replies": []}


def host_session():
    """The host's side, in its own thread: connect, subscribe, then verify each carrier whose
    WAITING FOR HOST event arrives (the second one against a map expecting slot 3 occupied)."""
    import queue

    import secsgem.common
    import secsgem.gem
    import secsgem.hsms
    from secsgem.secs import variables as V

    from waferscan.host.ids import DEFAULTS
    from waferscan.host.messages import registry

    try:
        events = queue.Queue()
        host = secsgem.gem.GemHostHandler(secsgem.hsms.HsmsSettings(
            address="127.0.0.1", port=PORT, connect_mode=secsgem.hsms.HsmsConnectMode.ACTIVE,
            device_type=secsgem.common.DeviceType.HOST, streams_functions=registry(), t5=1.0))

        def on_event(handler, message):
            event = handler.settings.streams_functions.decode(message)
            events.put((event.CEID.get(), event.RPT[0].V.get()))
            return handler.stream_function(6, 12)(0)

        host.register_stream_function(6, 11, on_event)
        host.enable()
        state["host"] = host
        if not host.waitfor_communicating(30):
            state["host_error"] = "the host did not reach COMMUNICATING"
            return

        def ask(stream, function, value=None):
            reply = host.send_and_waitfor_response(host.stream_function(stream, function)(value))
            return host.settings.streams_functions.decode(reply).get()

        data, ceids = DEFAULTS["data"], DEFAULTS["events"]
        state["acks"] = [
            ask(2, 33, {"DATAID": V.U4(1), "DATA": [{"RPTID": V.U4(1), "VID": [
                V.U4(v) for v in data.values()]}]}),
            ask(2, 35, {"DATAID": V.U4(2), "DATA": [{"CEID": V.U4(c), "RPTID": [V.U4(1)]}
                                                    for c in ceids.values()]}),
            ask(2, 37, {"CEED": True, "CEID": []})]
        state["subscribed"] = True
        for n, carrier in enumerate(("FOUP0042", "FOUP0043")):
            while True:
                ceid, values = events.get(timeout=120)
                state["events"].append([ceid, values[1], values[3]])
                if ceid == ceids["waiting_for_host"]:
                    break
            expected = list(values[2])
            if n == 1:
                expected[2] = 3
            state["replies"].append(ask(3, 17, {
                "DATAID": V.U4(10 + n), "CARRIERACTION": "ProceedWithCarrier",
                "CARRIERID": carrier, "PTN": V.U1(1),
                "CATTRS": [{"ATTRID": "SlotMap", "ATTRDATA": V.Array(V.U1, expected)}]}))
            ceid, values = events.get(timeout=60)
            state["events"].append([ceid, values[1], values[3]])
    except Exception as exc:  # noqa: BLE001 (written into the result)
        state["host_error"] = repr(exc)


def begin():
    from waferscan.gui.scanning import open_scenario

    Gui.activateWorkbench("WaferScanWorkbench")
    repo = os.path.dirname(os.environ["WAFERSCAN_GUI_PROBES"].rstrip("/"))
    state["doc"] = open_scenario(os.path.join(os.path.dirname(repo), "resources", "examples",
                                              "paper.toml"))
    Gui.SendMsgToActiveView("ViewFit")
    later(open_panel, 300)


def open_panel():
    Gui.runCommand("WaferScan_HostLink")
    panel = state["panel"] = task_panel()
    result["panel_class"] = type(panel).__name__
    panel.address.setText(f"127.0.0.1:{PORT}")
    panel.start_button.click()
    result["state_started"] = panel.state.text()
    threading.Thread(target=host_session, daemon=True).start()
    wait_for("the host's subscription", lambda: state.get("subscribed")
             or state.get("host_error"), load_first)


def load_first():
    if state.get("host_error"):
        finish(state["host_error"])
        return
    panel = state["panel"]
    later(lambda: None, 300)  # the panel's timer shows the connection
    panel.carrier_id.setText("FOUP0042")
    panel.load_button.click()
    wait_for("the first verification", lambda: len(state["replies"]) >= 1
             and len(state["events"]) >= 3, after_first)


def after_first():
    panel = state["panel"]
    panel.drain()
    dialog = panel.dialogs[1]
    result["dialog_first"] = dialog.host_label.text()
    result["dialog_code"] = dialog.code_label.text()
    result["rows_first"] = rows(panel)
    result["state_connected"] = panel.state.text()
    later(load_second, 300)  # the dialog laid out again with the host's answer


def load_second():
    panel = state["panel"]
    dialog = panel.dialogs[1]
    dialog.grab().save(artifact("gui-host-dialog-ok.png"))
    result["label_fits"] = [dialog.host_label.height() >= dialog.host_label.sizeHint().height()]
    panel.carrier_id.setText("FOUP0043")
    panel.load_button.click()
    wait_for("the second verification", lambda: len(state["replies"]) >= 2
             and len(state["events"]) >= 6, after_second)


def after_second():
    panel = state["panel"]
    panel.drain()
    result["dialog_second"] = panel.dialogs[1].host_label.text()
    result["rows_second"] = rows(panel)
    result["status_tip"] = panel.ports.item(0, 2).toolTip()
    result["report_view_warnings"] = report_view_lines("unexpected function")
    result["replies"] = state["replies"]
    result["events"] = state["events"]
    result["acks"] = state["acks"]
    log = panel.log.toPlainText()
    result["log_has"] = {key: key in log for key in (
        "S3F17 W", "S3F18", "S6F11 W", "port 1: carrier FOUP0043 VERIFICATION FAILED")}
    later(shots, 300)


def shots():
    panel = state["panel"]
    dialog = panel.dialogs[1]
    dialog.grab().save(artifact("gui-host-dialog-failed.png"))
    result["label_fits"].append(dialog.host_label.height()
                                >= dialog.host_label.sizeHint().height())
    window_shot("gui-host-panel.png", dock_width=520)
    state["host"].disable()
    panel.reject()  # Close: the link stops
    later(port_free, 500)


def port_free():
    with socket.socket() as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(("127.0.0.1", PORT))
            result["port_free_after_close"] = True
        except OSError as exc:
            result["port_free_after_close"] = repr(exc)
    finish()


def report_view_lines(text):
    """The Report view's lines holding ``text``."""
    from PySide import QtGui

    window = Gui.getMainWindow()
    views = [w for w in window.findChildren(QtGui.QTextEdit)
             if w.objectName() in ("Report view", "ReportOutput")
             or w.metaObject().className().endswith("ReportOutput")]
    result["report_view_text"] = sum(len(view.toPlainText()) for view in views)
    return [line for view in views for line in view.toPlainText().splitlines() if text in line]


def rows(panel):
    table = panel.ports
    return [[table.item(r, c).text() for c in range(table.columnCount())]
            for r in range(table.rowCount())]


start(begin)
