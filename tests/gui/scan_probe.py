# Run by FreeCAD's GUI (tests/gui/test_gui_scan.py): the paper's experiment as an engineer does
# it. Activate WaferScan, build the paper's layout with its command, run the scan with its
# command, pause and go on in the task panel, change the speed, let it run to the end; read the
# results table, the slot-code dialog and the side view as a user sees them; cross-check; then a
# second animation whose robot link is deleted mid-scan. Screenshots go to the artifacts folder.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, console_calls, finish, later, message_texts, result, start, wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

state = {}


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    Gui.updateGui()
    result["document"] = App.ActiveDocument.Name
    Gui.runCommand("WaferScan_RunScan")
    from waferscan.gui.session import session
    panel = session.task_panel
    state["panel"], state["animation"] = panel, panel.animation
    result["task_panel_shown"] = Gui.Control.activeDialog()
    result["recipe_label"] = panel.recipe.text()  # SPEC §11
    panel.speed.setValue(120.0)  # slow for now (seconds for the whole scan): a pause lands mid-scan
    frames = state["frames"] = []
    panel.animation.moved.connect(lambda k, z: frames.append(k))
    # Pause on the cross-slotted wafer of slot 5, as the README's screenshot shows.
    wait_for("the beam blocked by LP1_W04", lambda: "LP1_W04" in panel.animation.lit,
             paused_on_a_wafer)


def paused_on_a_wafer():
    panel = state["panel"]
    panel.pause_button.click()
    Gui.updateGui()
    result["paused_running"] = panel.animation.running
    result["paused_beam_label"] = panel.beam.text()
    result["paused_z"] = panel.animation.z
    result["paused_position_field"] = panel.z.value_mm()
    result["paused_buttons"] = [panel.play_button.isEnabled(), panel.pause_button.isEnabled(),
                                panel.stop_button.isEnabled()]
    lit = panel.animation.lit
    wafer = App.ActiveDocument.getObjectsByLabel(lit[0])[0]
    result["highlight"] = list(wafer.ViewObject.ShapeColor[:3])
    result["beam_colour"] = list(panel.animation.appearance.beam.ViewObject.LineColor[:3])
    carrier = App.ActiveDocument.getObjectsByLabel("LP1")[0]
    result["see_through_during"] = [carrier.ViewObject.Transparency,
                                    panel.animation.appearance.beam.ViewObject.LineWidth]
    view = Gui.ActiveDocument.ActiveView
    view.saveImage(artifact("gui-during-scan.png"), 1200, 800, "White")
    window_shot("gui-scan-panel.png")
    later(resume, 200)


def resume():
    panel = state["panel"]
    panel.speed.setValue(4.0)
    panel.play_button.click()
    wait_for("the animation's end", lambda: panel.animation.ended, after_animation)


def after_animation():
    from waferscan.gui.session import session
    panel = state["panel"]
    result["completed"] = panel.animation.completed
    frames = state["frames"]
    result["frames"] = [len(frames), all(a < b for a, b in zip(frames, frames[1:])),
                        frames[-1], panel.animation.frames, panel.animation.duration_s]
    carrier = App.ActiveDocument.getObjectsByLabel("LP1")[0]
    result["see_through_after"] = [carrier.ViewObject.Transparency,
                                   panel.animation.appearance.beam.ViewObject.LineWidth]
    result["panel_status"] = panel.status.text()
    wait_for("the results dialogs", lambda: len(session.dialogs) == 2, dialogs)


def dialogs():
    from waferscan.gui.dialogs import cross_check
    from waferscan.gui.session import session
    table, dialog = session.dialogs
    Gui.updateGui()
    result["rows"] = table.rows()
    csv_path = os.environ["WAFERSCAN_GUI_SAVE"].replace(".FCStd", ".csv")
    # Export CSV… as a user clicks it: the file dialog answers with csv_path.
    asked = QtGui.QFileDialog.getSaveFileName
    QtGui.QFileDialog.getSaveFileName = staticmethod(lambda *args: (csv_path, "CSV (*.csv)"))
    try:
        table._export()
    finally:
        QtGui.QFileDialog.getSaveFileName = asked
    result["csv"] = csv_path
    result["console_calls"] = console_calls()
    # Into a folder that does not exist: said to the user, no traceback, nothing written.
    from waferscan.gui.commands import export_results_csv
    result["bad_export"] = [export_results_csv(App.ActiveDocument, "/no-such-folder/r.csv"),
                            message_texts()]
    result["state_colours"] = [table.table.item(r, 6).background().color().name()
                               for r in range(table.table.rowCount())]
    result["dialog_code"] = dialog.code_label.text()
    result["strip"] = [cell.text().split("\n") for cell in dialog.cells]
    result["e87_label"] = dialog.e87_label.text()
    result["sheet_code"] = App.ActiveDocument.getObject("ScanResults").get("code")
    # Selecting a row selects its wafer in the 3D view.
    table.table.selectRow(0)
    result["selected"] = [o.Label for o in Gui.Selection.getSelection()]
    dialog.copy_code()
    result["clipboard"] = QtGui.QApplication.clipboard().text()
    # The side view, drawn: sample the colours of its pixels.
    image = dialog.side_view.grab().toImage()
    colours = {image.pixel(x, y) & 0xFFFFFF for x in range(0, image.width(), 2)
               for y in range(0, image.height(), 2)}
    result["side_view_colours"] = sorted(f"#{c:06x}" for c in colours)
    table.grab().save(artifact("gui-results-table.png"))
    dialog.grab().save(artifact("gui-slot-code.png"))
    Gui.ActiveDocument.ActiveView.saveImage(artifact("gui-after-scan.png"), 1200, 800, "White")
    window_shot("gui-main-window.png")
    App.ActiveDocument.saveAs(os.environ["WAFERSCAN_GUI_SAVE"])
    check = cross_check(App.ActiveDocument)
    result["crosscheck_ok"] = check.ok
    result["crosscheck_deviation"] = check.largest_deviation
    result["crosscheck_box"] = session.dialogs[0].text()
    result["crosscheck_details"] = session.dialogs[0].detailedText()
    later(fault_during_animation, 100)


def fault_during_animation():
    from waferscan.gui.playback import run_scan
    doc = App.ActiveDocument
    animation = run_scan(doc, steps_per_frame=5)
    state["fault_animation"] = animation
    wait_for("a few frames", lambda: animation.k > 100, delete_a_link)


def delete_a_link():
    doc = App.ActiveDocument
    fork = doc.getObjectsByLabel("robot fork")[0]
    result["deleted"] = fork.Name
    doc.removeObject(fork.Name)
    animation = state["fault_animation"]
    wait_for("the animation to end on the fault", lambda: animation.ended, after_fault)


def after_fault():
    from waferscan.gui.session import session
    animation = state["fault_animation"]
    panel = session.task_panel
    result["fault"] = animation.fault
    result["fault_completed"] = animation.completed
    result["fault_status"] = panel.status.text()
    Gui.Control.closeDialog()
    finish()


start(begin)
