# Run by FreeCAD's GUI (tests/gui/test_gui_mcs_pockets.py): a slow scan with jabs and sweeps
# (WAFERSCAN_GUI_SCENARIO, resources/examples/slow_jab.toml) asked for through the MCS link panel
# as an MCS asks: "1 SCS" in commands.txt. After the Z steps the arm jabs and sweeps pocket by
# pocket as after Run scan; the probe holds it at the end of slot 8's jab, reads the robot's fork
# and the beam from the document and takes a screenshot. Then the MCS asks "2 SCF" while the
# pockets still play: they end first (the arm back in its start pose), and the fast scan reads
# the arm where it starts.
import os
import sys
from pathlib import Path

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, later, result, start, wait_for, window_shot  # noqa: E402

import FreeCADGui as Gui  # noqa: E402

FOLDER = Path(os.environ["WAFERSCAN_GUI_MCS"])
state = {}


def placements(doc):
    return {o.Name: [list(o.Placement.Base), list(o.Placement.Rotation.Q)]
            for o in doc.Objects if hasattr(o, "Placement")}


def fork(doc):
    return next(list(o.Placement.Base) for o in doc.Objects
                if getattr(o, "RobotLink", None) == "fork")


def begin():
    from waferscan.gui import preferences
    from waferscan.gui.scanning import open_scenario
    from waferscan.gui.session import session

    Gui.activateWorkbench("WaferScanWorkbench")
    preferences._group().SetFloat("PlaybackSeconds", 1.0)  # the Z steps quickly
    doc = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    state["doc"] = doc
    state["start"] = placements(doc)
    result["fork_start"] = fork(doc)
    Gui.runCommand("WaferScan_McsLink")
    panel = session.task_panel
    state["panel"] = panel
    panel.set_folder(str(FOLDER))
    result["started"] = panel.start(events=True, poll_ms=200)
    (FOLDER / "commands.txt").write_text("1 SCS\n", encoding="utf-8")
    wait_for("the jabs and sweeps after the MCS's slow scan",
             lambda: session.pocket_animation is not None and not session.pocket_animation.ended
             and session.pocket_animation.k > 3, pockets, timeout_s=150)


def pockets():
    from waferscan.cad.reader import DocumentScene, beam_from
    from waferscan.gui.pocket_animation import frame_of
    from waferscan.gui.session import session

    panel = state["panel"]
    animation = session.pocket_animation
    animation.timer.stop()  # held: the frame shown below
    doc = state["doc"]
    result["rows"] = panel.log_rows()
    result["pockets_of"] = {"doc": animation.doc.Name == doc.Name,
                            "code": animation.result.code, "slots": animation.pockets(),
                            "panel_kept": session.task_panel is panel}
    index = frame_of(animation, 8, "jab", 1.0)
    animation.show(index)
    animation.moved.emit(index)
    Gui.updateGui()
    beam = beam_from(DocumentScene.of(doc).scanner())
    result["jab"] = {"frame": list(animation.frames[index]), "fork": fork(doc),
                     "emitter": list(beam.emitter), "direction": list(beam.direction),
                     "blocked": animation.blocked}
    window_shot("gui-mcs-jab.png")
    # The MCS asks again while the pockets still play.
    animation.play()
    state["pockets"] = animation
    with open(FOLDER / "commands.txt", "a", encoding="utf-8") as handle:
        handle.write("2 SCF\n")
    wait_for("the fast scan's answer", lambda: len(panel.log_rows()) >= 2, answered,
             timeout_s=150)


def answered():
    doc = state["doc"]
    result["rows_after"] = state["panel"].log_rows()
    result["pockets_ended_before"] = state["pockets"].ended
    result["restored_after"] = placements(doc) == state["start"]
    later(last, 300)


def last():
    panel = state["panel"]
    window_shot("gui-mcs-after-pockets.png")
    panel.reject()
    finish()


start(begin)
