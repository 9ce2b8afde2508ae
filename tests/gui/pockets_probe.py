# Run by FreeCAD's GUI (tests/gui/test_gui_pockets.py): a slow scan with jabs and sweeps, opened
# and scanned with the workbench's commands. After the Z steps the pocket animation starts; the
# probe holds it at the end of slot 8's jab and a quarter into slot 3's sweep, reads the task
# panel, the beam read back from the document and the robot's links, takes a screenshot of the
# jab, then lets the animation end and reads the results dialogs' code.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, finish, later, result, scan_scenario, start, wait_for, window_shot)

state = {}

import FreeCADGui as Gui  # noqa: E402


def begin():
    from waferscan.gui.session import session
    animation = scan_scenario(steps_per_frame=500)
    wait_for("the pocket animation", lambda: animation.ended
             and session.pocket_animation is not None, pockets)


def _read(pockets, index):
    from waferscan.cad.reader import beam_from
    from waferscan.cad.reader import DocumentScene
    from waferscan.gui.session import session

    pockets.show(index)
    pockets.moved.emit(index)
    Gui.updateGui()
    panel = session.task_panel
    beam = beam_from(DocumentScene.of(pockets.doc).scanner())
    links = {o.RobotLink: list(o.Placement.Base) for o in pockets.doc.Objects
             if "RobotLink" in o.PropertiesList}
    return {"frame": list(pockets.frames[index]), "pocket": panel.pocket.text(),
            "phase": panel.phase.text(), "arm": panel.amount.text(), "beam": panel.beam.text(),
            "found": panel.found.text(), "emitter": list(beam.emitter),
            "direction": list(beam.direction), "links": links}


def pockets():
    from waferscan.gui.session import session
    from waferscan.gui.pocket_animation import frame_of
    animation = session.pocket_animation
    animation.timer.stop()  # held: frames shown one by one below
    result["panel_title"] = session.task_panel.form.windowTitle()
    result["start"] = _read(animation, 0)
    result["jab"] = _read(animation, frame_of(animation, 8, "jab", 1.0))
    window_shot("gui-jab.png")
    result["sweep"] = _read(animation, frame_of(animation, 3, "sweep", 0.25))
    later(controls)


def controls():
    """Pause, Resume, Go to a pocket and the speed, from the panel's own controls."""
    from waferscan.cad.reader import DocumentScene, beam_from
    from waferscan.gui.session import session
    animation = session.pocket_animation
    panel = session.task_panel
    animation.k = 0
    animation.play()
    state["seen"] = []
    animation.moved.connect(lambda k: state["seen"].append(k))

    def paused():
        panel.pause_button.click()
        state["held"] = [animation.k, panel.pause_button.text(), animation.timer.isActive()]
        state["beam_held"] = list(beam_from(DocumentScene.of(animation.doc).scanner()).emitter)
        later(still_paused, 400)

    def still_paused():
        beam = beam_from(DocumentScene.of(animation.doc).scanner())
        result["paused"] = state["held"] + [animation.k, list(beam.emitter) == state["beam_held"]]
        # Go to pocket 12 while paused: the arm is there at once, and stays paused.
        index = panel.go_to.findData(12)
        panel.go_to.setCurrentIndex(index)
        panel.go_to.activated.emit(index)
        Gui.updateGui()
        beam = beam_from(DocumentScene.of(animation.doc).scanner())
        frame = animation.frames[animation.k - 1]
        window_shot("gui-pockets-paused.png")
        result["went_to"] = {"pocket": panel.pocket.text(), "frame": list(frame),
                             "emitter_z": beam.emitter[2], "paused": animation.paused,
                             "choices": [panel.go_to.itemText(i)
                                         for i in range(panel.go_to.count())]}
        panel.speed.setCurrentIndex(panel.speed.findData(8.0))
        state["seen"].clear()
        panel.pause_button.click()  # Resume, at 8x
        result["resumed_text"] = panel.pause_button.text()
        later(fast, 300)

    def fast():
        seen = list(state["seen"])
        result["fast_steps"] = [b - a for a, b in zip(seen, seen[1:])]
        result["fast_first"] = seen[0] if seen else None
        animation.k = len(animation.frames) - 1
        wait_for("the results dialogs", lambda: animation.ended
                 and len(session.dialogs) == 2, dialogs)

    later(paused, 300)


def dialogs():
    from waferscan.gui.session import session
    result["panel_status"] = session.task_panel.status.text()
    table, code = session.dialogs
    result["code"] = code.code_label.text()
    result["headers"] = [table.table.horizontalHeaderItem(c).text()
                         for c in range(table.table.columnCount())]
    result["rows"] = table.rows()
    Gui.updateGui()
    result["table_look"] = {"row_numbers": table.table.verticalHeader().isVisible(),
                            "sideways": table.table.horizontalScrollBar().maximum(),
                            "width": table.width()}
    table.grab().save(artifact("gui-pockets-table.png"))
    finish()


start(begin)
