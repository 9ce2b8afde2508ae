# Run by FreeCAD's GUI (tests/gui/test_gui_unscanned.py): a scenario whose scan stops below the
# top slots, opened and scanned with the workbench's commands. Reads what a user sees: the task
# panel's message when the scan is done, the results table's state column and colours, the
# slot-code strip and the side view's colours.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, scan_scenario, start, wait_for  # noqa: E402


def begin():
    animation = scan_scenario(steps_per_frame=500)
    wait_for("the animation's end", lambda: animation.ended, after_animation)


def after_animation():
    from waferscan.gui.session import session
    result["panel_status"] = session.task_panel.status.text()
    wait_for("the results dialogs", lambda: len(session.dialogs) == 2, dialogs)


def dialogs():
    from waferscan.gui.session import session
    table, code = session.dialogs
    result["rows"] = table.rows()
    result["state_colours"] = [list(table.table.item(r, 6).background().color().getRgb()[:3])
                               for r in range(table.table.rowCount())]
    result["code"] = code.code_label.text()
    result["e87"] = code.e87_label.text()
    result["strip"] = [cell.text().split("\n") for cell in code.cells]
    result["strip_styles"] = [cell.styleSheet() for cell in code.cells]
    image = code.side_view.grab().toImage()
    counts = {}
    for x in range(0, image.width(), 2):
        for y in range(0, image.height(), 2):
            rgb = image.pixelColor(x, y).getRgb()[:3]
            counts[rgb] = counts.get(rgb, 0) + 1
    result["side_view_colours"] = [[list(rgb), n] for rgb, n in counts.items() if n >= 20]
    finish()


start(begin)
