# Run by FreeCAD's GUI (tests/gui/test_gui_quit.py): FreeCAD told to quit (QApplication.quit(),
# as a script or a macro may) while a scan plays: the paper's layout with its robot in the Z
# stroke, or slow_jab.toml in its jabs and sweeps. The result is written first; the test then
# reads FreeCAD's exit.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, later, result, scan_scenario, start, wait_for  # noqa: E402

PHASE = os.environ["WAFERSCAN_GUI_QUIT_IN"]  # "stroke", "pockets" or "idle" (no scan)


def begin():
    from waferscan.gui.session import session
    if PHASE == "idle":  # the document open, nothing playing: FreeCAD's own quit
        from waferscan.gui.commands import open_scenario
        open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
        result["playing"], result["frame"] = False, 0
        later(finish, 500)
        return
    animation = scan_scenario(steps_per_frame=5 if PHASE == "stroke" else 500)
    if PHASE == "stroke":
        wait_for("the stroke under way", lambda: animation.k > 20,
                 lambda: later(lambda: quit_now(animation), 50))
    else:
        wait_for("the pockets under way", lambda: animation.ended
                 and session.pocket_animation is not None
                 and session.pocket_animation.k > 10,
                 lambda: later(lambda: quit_now(session.pocket_animation), 50))


def quit_now(animation):
    result["playing"] = not animation.ended
    result["frame"] = animation.k
    finish()  # writes the result, then QApplication.quit()


start(begin)
