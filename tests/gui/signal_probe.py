# Run by FreeCAD's GUI (tests/gui/test_gui_signal.py): a scenario with a 1 mm beam spot, opened
# and scanned with the workbench's commands. Reads what a user sees of the sensor's signal: the
# live trace in the scan panel (its window around the beam and its pixels) and the whole-scan
# trace in the slot-code dialog.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, scan_scenario, start, wait_for  # noqa: E402


seen = []


def colours(widget):
    image = widget.grab().toImage()
    counts = {}
    for x in range(0, image.width()):
        for y in range(0, image.height()):
            rgb = image.pixelColor(x, y).getRgb()[:3]
            counts[rgb] = counts.get(rgb, 0) + 1
    return [[list(rgb), n] for rgb, n in counts.items()]


def begin():
    from waferscan.gui.session import session
    animation = scan_scenario(steps_per_frame=200)
    trace = session.task_panel.trace
    animation.moved.connect(lambda k, z: seen.append([z, list(trace.window())]))
    wait_for("the animation's end", lambda: animation.ended, after_animation)


def after_animation():
    from waferscan.gui.session import session
    trace = session.task_panel.trace
    result["live_windows"] = seen
    result["live_cursor"] = trace.cursor
    trace.repaint()  # the ticks as drawn at the cursor's last position
    result["live_ticks"] = [list(t) for t in trace.ticks]
    result["live_width"] = trace.width()
    result["live_samples"] = [list(map(float, a)) for a in trace.samples_in_window()]
    wait_for("the results dialogs", lambda: len(session.dialogs) == 2, dialogs)


def dialogs():
    from waferscan.gui.session import session
    _, code = session.dialogs
    view = code.signal_view
    result["dialog_window"] = list(view.window())
    result["dialog_size"] = [view.width(), view.height()]
    result["dialog_colours"] = colours(view)
    result["thresholds"] = list(view.thresholds)
    result["edges"] = len(view.edges)
    view.repaint()
    result["dialog_ticks"] = [list(t) for t in view.ticks]
    finish()


start(begin)
