# Run by FreeCAD's GUI (tests/gui/test_gui_stale.py): the scan panel follows the document.
# Scan the paper's layout; in the panel's Recipe and Sensor sections apply a value, then Edit →
# Undo and Redo: the fields and the message follow. Replay with nothing changed plays the same
# scan; then the carrier's SlotCount is edited as in the Data tab (one undo step, recompute) and
# Replay scans the document as it is now, and says so.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    console_calls, finish, open_section, replay, result, scan_paper_layout, scan_settings, start, task_panel,
    wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def begin():
    first = scan_paper_layout()
    first.speed.setValue(1.0)
    wait_for("the first scan's end", lambda: first.animation.ended, undo_apply)


def recipe_min():
    """The document's thickness min in mm, None when not set (its ThicknessMinSet unticked)."""
    from waferscan.cad.recipe_properties import limit_value
    return limit_value(scan_settings(), "ThicknessMin")


def fields(panel):
    return {"ThicknessMin": panel.recipe_section.fields["ThicknessMin"].text(),
            "ThresholdOn": panel.sensor.fields["ThresholdOn"].text()}


def undo_apply():
    panel = task_panel()
    open_section(panel.recipe_section)
    open_section(panel.sensor)
    result["fields_before"] = fields(panel)
    panel.recipe_section.fields["ThicknessMin"].setText("0.6")
    result["recipe_applied"] = panel.recipe_section.apply()
    panel.sensor.fields["ThresholdOn"].setText("0.7")
    result["sensor_applied"] = panel.sensor.apply()
    result["document_applied"] = [recipe_min(), scan_settings().ThresholdOn]
    result["fields_applied"] = fields(panel)
    Gui.runCommand("Std_Undo")
    Gui.updateGui()
    result["document_undone_once"] = [recipe_min(), scan_settings().ThresholdOn]
    result["fields_undone_once"] = fields(panel)
    Gui.runCommand("Std_Undo")
    Gui.updateGui()
    result["document_undone"] = [recipe_min(), scan_settings().ThresholdOn]
    result["fields_undone"] = fields(panel)
    result["messages_undone"] = [panel.recipe_section.message.text(),
                                 panel.sensor.message.text()]
    window_shot("gui-scan-panel-undone.png")
    Gui.runCommand("Std_Redo")
    Gui.updateGui()
    result["document_redone"] = [recipe_min(), scan_settings().ThresholdOn]
    result["fields_redone"] = fields(panel)
    Gui.runCommand("Std_Undo")  # back to the scanned values for the replays below
    Gui.updateGui()
    result["fields_final"] = fields(panel)
    state["first"] = panel.animation.result
    replay("Replay, nothing changed", replayed_unchanged)


state = {}


def note(panel):
    """[shown, text] of the panel's line saying Replay scanned again ([False, ""]: no line)."""
    label = getattr(panel, "rescanned", None)
    return [False, ""] if label is None else [label.isVisible(), label.text()]


def replayed_unchanged():
    panel = task_panel()
    result["unchanged_same_result"] = panel.animation.result is state["first"]
    result["unchanged_note"] = note(panel)[0]
    # The carrier's SlotCount, edited as in the Data tab: one undo step and a recompute.
    from waferscan.cad.reader import DocumentScene
    from waferscan.cad.roles import role_holder

    doc = App.ActiveDocument
    carrier = role_holder(DocumentScene.of(doc).carriers[0].obj)
    doc.openTransaction("Edit SlotCount")
    carrier.SlotCount = 20
    doc.commitTransaction()
    doc.recompute()
    replay("Replay after the carrier changed", replayed_changed)


def replayed_changed():
    from waferscan.gui.scanning import result_now

    panel = task_panel()
    shown = panel.animation.result
    result["changed_code"] = shown.code
    result["changed_now_code"] = result_now(App.ActiveDocument).code
    result["changed_note"] = note(panel)
    result["changed_status"] = panel.status.text()
    result["console_calls"] = console_calls()
    window_shot("gui-replay-rescanned.png")
    panel.animation.stop()
    Gui.Control.closeDialog()
    finish()


start(begin)
