# Run by FreeCAD's GUI (tests/gui/test_gui_missed.py): the scenario WAFERSCAN_GUI_SCENARIO,
# whose beam passes beside every wafer, built: its beam is drawn before any scan; Run scan: a
# message box says the beam misses at once, and the panel's status when the scan ends. Then a
# box of the user's tagged as scanner: its beam is drawn, and follows its Receiver.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    finish, later, message_texts, result, start, task_panel, wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def preview(doc, name):
    """[drawn, from, to] of the scanner's beam preview ([False] when it has none); ``doc``: the
    document or its name."""
    from waferscan.gui.beam_preview import previews

    line = previews.lines.get((getattr(doc, "Name", doc), name))
    if line is None:
        return [False]
    drawn = line.shown and line.root.findChild(line.node) >= 0
    return [drawn] + [[round(c, 6) for c in line.points.point[i].getValue()] for i in (0, 1)]


def begin():
    from waferscan.gui.scanning import open_scenario

    Gui.activateWorkbench("WaferScanWorkbench")
    doc = open_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"])
    state["doc"] = doc
    Gui.SendMsgToActiveView("ViewFit")
    later(before_scan, 200)


state = {}


def before_scan():
    from waferscan.gui.playback import run_scan

    doc = state["doc"]
    result["preview_before"] = preview(doc, "Scanner")
    window_shot("gui-beam-before-scan.png")
    animation = run_scan(doc, duration_s=1.0)
    result["preview_during"] = preview(doc, "Scanner")
    window_shot("gui-beam-misses-box.png")
    result["boxes"] = message_texts()
    result["code"] = animation.result.code
    wait_for("the scan's end", lambda: animation.ended, ended)


def ended():
    panel = task_panel()
    result["status"] = panel.status.text()
    window_shot("gui-beam-misses-panel.png")
    panel.animation.stop()
    Gui.Control.closeDialog()
    result["preview_after"] = preview(state["doc"], "Scanner")
    # A user's own sensor: a box tagged as scanner shows its beam, which follows its Receiver.
    from waferscan.gui.tagging import tag_selection

    doc = App.newDocument("Own")
    box = doc.addObject("Part::Box", "Fork")
    doc.recompute()
    tag_selection("scanner", [box])
    state["own"] = (doc, box)
    later(tagged, 100)


def tagged():
    doc, box = state["own"]
    result["own_tagged"] = preview(doc, "Fork")
    box.Receiver = App.Vector(50.0, 0.0, 0.0)
    later(moved, 100)


def moved():
    doc, box = state["own"]
    result["own_moved"] = preview(doc, "Fork")
    name = doc.Name
    App.closeDocument(name)
    result["own_closed"] = preview(name, "Fork")
    finish()


start(begin)
