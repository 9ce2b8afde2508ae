# Run by FreeCAD's GUI on a 1024×700 screen (tests/gui/test_gui_fit.py): the task panels in
# FreeCAD's default combo view width (264 px), the dialogs on the small screen, and the scan
# panel's playback: in seconds of real time, stopped and replayed, scanned twice with one set of
# results dialogs per document; Export CSV… starting next to the document; the cross-check's table
# in a fixed-pitch font.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (artifact, finish, later, result, start, task_dock,  # noqa: E402
                         wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

FOLDER = os.environ["WAFERSCAN_GUI_MCS"]
COMBO_WIDTH = 264  # FreeCAD's default
state = {}


def combo_view(width=COMBO_WIDTH):
    window = Gui.getMainWindow()
    combo = task_dock()
    window.resizeDocks(combo, [width], QtCore.Qt.Horizontal)
    Gui.updateGui()
    return combo[0].width()


def clipped(form):
    """The visible widgets of a task panel that stick out of the task view on the right, and
    whether the task view scrolls sideways."""
    scroll = form.parentWidget()
    while scroll is not None and not isinstance(scroll, QtGui.QScrollArea):
        scroll = scroll.parentWidget()
    viewport = scroll.viewport()
    out = []
    kinds = (QtGui.QAbstractButton, QtGui.QProgressBar, QtGui.QLineEdit,
             QtGui.QAbstractSpinBox, QtGui.QPlainTextEdit, QtGui.QTableWidget)
    for widget in form.findChildren(QtGui.QWidget):
        if not isinstance(widget, kinds) or not widget.isVisible():
            continue
        right = widget.mapTo(viewport, QtCore.QPoint(widget.width(), 0)).x()
        if right > viewport.width():
            out.append(f"{type(widget).__name__} {getattr(widget, 'text', lambda: '')()!s}"
                       f" ends at {right} > {viewport.width()}")
    return {"clipped": out, "sideways": scroll.horizontalScrollBar().maximum() > 0,
            "viewport": viewport.width()}


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.getMainWindow().showMaximized()
    Gui.updateGui()
    screen = QtGui.QApplication.desktop().availableGeometry(Gui.getMainWindow())
    result["screen"] = [screen.width(), screen.height()]
    Gui.runCommand("WaferScan_NewPaperLayout")
    doc = App.ActiveDocument
    doc.saveAs(os.path.join(FOLDER, "paper-fit.FCStd"))
    state["doc"] = doc
    from waferscan.gui.playback import run_scan
    from waferscan.gui.session import session
    run_scan(doc, duration_s=30.0)
    panel = session.task_panel
    state["panel"] = panel
    result["combo_width"] = combo_view()
    wait_for("a few frames", lambda: panel.animation.k > 50, scan_panel_fits)


def scan_panel_fits():
    panel = state["panel"]
    panel.pause_button.click()
    Gui.updateGui()
    result["scan_panel"] = clipped(panel.form)
    result["playback"] = [panel.speed.suffix(), panel.speed.value(), panel.animation.duration_s]
    result["position_text"] = panel.z.text()
    result["position_has_arrows"] = isinstance(panel.z, QtGui.QAbstractSpinBox)
    window_shot("gui-scan-panel-264.png", dock_width=COMBO_WIDTH)
    panel.sensor.toggle.click()  # the Sensor and slow scan section opened: it fits too
    Gui.updateGui()
    result["scan_panel_sensor"] = clipped(panel.form)
    result["sensor_fields_shown"] = sum(f.isVisible() for f in panel.sensor.fields.values())
    window_shot("gui-scan-panel-sensor-264.png", dock_width=COMBO_WIDTH)
    panel.sensor.toggle.click()
    panel.stop_button.click()
    result["after_stop"] = [panel.replay_button.isEnabled(), panel.status.text()]
    panel.replay_button.click()
    later(replayed, 200)


def replayed():
    from waferscan.gui.session import session
    panel = session.task_panel
    result["replay_new_panel"] = panel is not state["panel"]
    result["replay_seconds"] = panel.animation.duration_s
    panel.speed.setValue(1.0)  # the rest of the scan in a second
    result["replay_seconds_after"] = panel.animation.duration_s
    state["panel"] = panel
    wait_for("the replay's end", lambda: panel.animation.ended, lambda: later(dialogs, 300))


def dialogs():
    from waferscan.gui.playback import run_scan
    from waferscan.gui.session import session
    panel = state["panel"]
    result["replay_completed"] = panel.animation.completed
    table, code = session.dialogs
    Gui.updateGui()
    screen = QtGui.QApplication.desktop().availableGeometry(Gui.getMainWindow())
    result["dialog_sizes"] = {d.windowTitle(): [d.width(), d.height()] for d in (table, code)}
    result["dialog_minimums"] = {d.windowTitle(): [d.minimumSizeHint().width(),
                                                   d.minimumSizeHint().height()]
                                 for d in (table, code)}
    export = [b for b in table.findChildren(QtGui.QPushButton) if "Export" in b.text()][0]
    corner = export.mapTo(table, QtCore.QPoint(export.width(), export.height()))
    result["export_inside"] = corner.x() <= table.width() and corner.y() <= table.height()
    result["screen_for_dialogs"] = [screen.width(), screen.height()]
    table.grab().save(artifact("gui-results-1024x700.png"))
    code.grab().save(artifact("gui-slot-code-1024x700.png"))
    # Export CSV… starts next to the document.
    asked = []
    original = QtGui.QFileDialog.getSaveFileName
    QtGui.QFileDialog.getSaveFileName = staticmethod(
        lambda parent, title, start, *rest: (asked.append(start), ("", ""))[1])
    try:
        export.click()
    finally:
        QtGui.QFileDialog.getSaveFileName = original
    result["export_start"] = asked
    # A second scan of the same document: its dialogs replace the first ones, in place.
    state["first_geometry"] = [table.x(), table.y(), table.width(), table.height()]
    run_scan(state["doc"], duration_s=0.5)
    panel = session.task_panel
    wait_for("the second scan's end", lambda: panel.animation.ended, lambda: later(second, 300))


def second():
    from waferscan.gui.dialogs import cross_check
    from waferscan.gui.session import session
    from waferscan.gui.qt import alive
    shown = [w for w in QtGui.QApplication.topLevelWidgets()
             if isinstance(w, QtGui.QDialog) and alive(w) and w.isVisible()
             and w.windowTitle().startswith("WaferScan")]
    result["dialogs_after_second_scan"] = sorted(w.windowTitle() for w in shown)
    table = session.dialogs[0]
    result["second_geometry"] = [table.x(), table.y(), table.width(), table.height()]
    result["first_geometry"] = state["first_geometry"]
    for dialog in session.dialogs:
        dialog.close()
    check = cross_check(state["doc"])
    box = session.dialogs[0]
    details = box.findChildren(QtGui.QTextEdit)
    result["crosscheck"] = [check.ok, box.windowTitle(),
                            bool(details) and QtGui.QFontInfo(details[0].font()).fixedPitch()]
    box.close()
    Gui.Control.closeDialog()
    mcs_panel()


def mcs_panel():
    from waferscan.gui.session import session
    Gui.runCommand("WaferScan_McsLink")
    panel = session.task_panel
    panel.set_folder(FOLDER)
    with open(os.path.join(FOLDER, "commands.txt"), "w", encoding="utf-8") as handle:
        handle.write("1 SCF\n2 FROB\n")
    panel.start(events=False, poll_ms=0)
    panel.poll()
    combo_view()
    later(lambda: mcs_panel_fits(panel), 300)


def mcs_panel_fits(panel):
    result["mcs_rows"] = len(panel.log_rows())
    result["mcs_panel"] = clipped(panel.form)
    result["mcs_log_sideways"] = panel.log.horizontalScrollBar().maximum() > 0 or \
        panel.log.horizontalHeader().length() > panel.log.viewport().width()
    header = panel.log.horizontalHeader()
    result["mcs_log_sizes"] = [[header.sectionSize(c) for c in range(header.count())],
                               header.length(), panel.log.viewport().width()]
    window_shot("gui-mcs-panel-264.png", dock_width=COMBO_WIDTH)
    panel.stop()
    Gui.Control.closeDialog()
    finish()


start(begin)
