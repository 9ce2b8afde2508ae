# Run by FreeCAD's GUI (tests/gui/test_gui_recipe_section.py): the scan panel's "Recipe" section
# as a user uses it. Scan the paper's layout; open the section; type a window whose min is above
# its max (refused: nothing written), then a thickness min of 0.66 mm with the boundary rules
# and apply; Replay judges by them.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    finish, open_section, replay, result, scan_paper_layout, scan_settings, start, task_panel,
    wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def limit(prop):
    """A recipe limit of the document in mm, None when not set (its ...Set box unticked)."""
    from waferscan.cad.recipe_properties import limit_value
    return limit_value(scan_settings(), prop)


def begin():
    first = scan_paper_layout()
    first.speed.setValue(1.0)
    section = first.recipe_section
    result["first_code"] = first.animation.result.code
    result["collapsed_visible"] = section.body.isVisible()
    result["shown"] = {p: [f.text(), f.placeholderText()] for p, f in section.fields.items()}
    result["shown_rules"] = section.rules.currentText()
    result["shown_correction"] = section.correction.text()
    wait_for("the first scan's end", lambda: first.animation.ended, edit_recipe)


def edit_recipe():
    section = task_panel().recipe_section
    result["expanded_visible"] = open_section(section)
    undo_before = App.ActiveDocument.UndoCount
    section.fields["ThicknessMin"].setText("0.9")
    section.fields["ThicknessMax"].setText("0.8")
    result["bad_applied"] = section.apply()
    result["bad_message"] = section.message.text()
    result["after_bad"] = [limit("ThicknessMin"), limit("ThicknessMax"),
                           App.ActiveDocument.UndoCount - undo_before]
    section.fields["ThicknessMin"].setText("0.66")
    section.fields["ThicknessMax"].setText("")
    section.rules.setCurrentIndex(section.rules.findText("boundary"))
    result["good_applied"] = section.apply()
    result["good_message"] = section.message.text()
    stored = scan_settings()
    result["after_good"] = [limit("ThicknessMin"), limit("ThicknessMax"), stored.Rules,
                            App.ActiveDocument.UndoCount - undo_before,
                            App.ActiveDocument.UndoNames[0]]
    window_shot("gui-scan-panel-recipe.png")
    replay("the replay with the recipe", after_replay)


def after_replay():
    replayed = task_panel().animation.result
    result["replay_code"] = replayed.code
    result["replay_plan"] = [replayed.plan.rules, list(replayed.plan.thickness_window())]
    result["replay_label"] = task_panel().recipe.text()
    task_panel().animation.stop()
    Gui.Control.closeDialog()
    finish()


start(begin)
