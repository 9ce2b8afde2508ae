# Run by FreeCAD's GUI (tests/gui/test_gui_clearance.py): SPEC §15's clearance as the GUI shows
# it. (1) The paper's layout scanned with Run scan: the scan panel's live clearance read at
# chosen frames, the fork's colour, the slot-code dialog's clearance line. (2) The same layout
# with the recipe's ClearanceMin raised to 1.0 mm: the fork red at the closest frame and its own
# colour again after, the contact listed in the slot-code dialog; a screenshot. (3) The slow
# scan of slow_jab.toml scanned through its document: a pocket frame's clearance in the pocket
# panel, and the fork's swept outline in the slot-code dialog's plan; a screenshot.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, finish, later, result, scan_settings, start, wait_for, window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402

PAPER, SLOW = os.environ["WAFERSCAN_GUI_PAPER"], os.environ["WAFERSCAN_GUI_SLOW"]
FRAMES = [0, 2400, 4840]  # Z 280, 400 and 522 (the least: 522.017)
state = {}


def fork_colour(doc):
    fork = [o for o in doc.Objects if "RobotLink" in o.PropertiesList and o.RobotLink == "fork"]
    return [list(fork[0].ViewObject.ShapeColor[:3]), len(fork[0].ViewObject.DiffuseColor)]


def report_record(report):
    """The scan's ClearanceReport as the GUI's result holds it: its least and its contacts."""
    from waferscan.core.scan.clearance import describe

    def record(c):
        return {"distance": c.distance, "part": c.part, "obstacle": c.obstacle, "slot": c.slot,
                "phase": c.motion.phase, "unit": c.motion.unit, "position": c.position,
                "z": c.motion.z, "exact": c.exact, "words": describe(c)}

    return {"clearance_min": report.clearance_min, "least": record(report.least),
            "contacts": [record(c) for c in report.contacts]}


def show_frame(animation, k):
    """Hold the scan's animation at frame k (its timer stopped) and read the panel."""
    from waferscan.gui.session import session

    animation.k = k
    animation._tick()
    Gui.updateGui()
    panel = session.task_panel
    return {"k": k, "z": animation.z, "clearance": panel.clearance.text(),
            "style": panel.clearance.styleSheet(), "least": panel.least.text(),
            "fork": fork_colour(animation.doc)}


def begin():
    from waferscan.gui.playback import run_scan
    from waferscan.gui.scanning import open_scenario

    Gui.activateWorkbench("WaferScanWorkbench")
    doc = state["doc"] = open_scenario(PAPER)
    result["fork_before"] = fork_colour(doc)
    animation = run_scan(doc, steps_per_frame=1)
    animation.timer.stop()
    result["paper_frames"] = [show_frame(animation, k) for k in FRAMES]
    result["paper_report"] = report_record(animation.result.clearance)
    animation.k = animation.frames - 1
    animation._tick()  # the last frame: the animation ends, the dialogs open
    wait_for("the paper's dialogs", lambda: animation.ended and _code_dialog() is not None,
             paper_dialogs)


def _code_dialog():
    from waferscan.gui.session import session

    found = [d for d in session.dialogs if hasattr(d, "code_label")]
    return found[0] if found else None


def paper_dialogs():
    dialog = _code_dialog()
    result["paper_dialog"] = {"label": dialog.clearance_label.text(),
                              "table": dialog.contacts is not None}
    result["fork_after_paper"] = fork_colour(state["doc"])
    later(contact_scan)


def contact_scan():
    """ClearanceMin raised to 1.0 mm in the recipe (the document's property), scanned again."""
    from waferscan.gui.playback import run_scan

    doc = state["doc"]
    settings = scan_settings()
    doc.openTransaction("clearance_min 1.0")
    settings.ClearanceMin = 1.0
    doc.commitTransaction()
    doc.recompute()
    animation = run_scan(doc, steps_per_frame=1)
    animation.timer.stop()
    frames = [show_frame(animation, FRAMES[0]), show_frame(animation, FRAMES[2])]
    window_shot("gui-clearance.png")
    frames.append(show_frame(animation, FRAMES[0]))  # clear again: the fork's own colour
    frames.append(show_frame(animation, FRAMES[2]))  # red again, then the animation stopped
    result["contact_frames"] = frames
    result["contact_min"] = animation.clearance.clearance_min
    result["contact_report"] = report_record(animation.result.clearance)
    animation.k = animation.frames - 1
    animation._tick()
    wait_for("the contact's dialogs", lambda: animation.ended and _code_dialog() is not None
             and _code_dialog().result is animation.result, contact_dialogs)


def contact_dialogs():
    dialog = _code_dialog()
    table = dialog.contacts
    result["contact_dialog"] = {
        "label": dialog.clearance_label.text(),
        "headers": [table.horizontalHeaderItem(c).text() for c in range(table.columnCount())],
        "rows": [[table.item(r, c).text() for c in range(table.columnCount())]
                 for r in range(table.rowCount())],
        "tooltips": [table.item(r, 0).toolTip() for r in range(table.rowCount())]}
    result["fork_after_contact"] = fork_colour(state["doc"])
    dialog.grab().save(os.path.join(os.environ["WAFERSCAN_GUI_ARTIFACTS"],
                                    "gui-clearance-dialog.png"))
    later(slow_scan)


def slow_scan():
    """slow_jab.toml scanned through its document (no Z animation); its pockets' animation held
    at slot 8's deepest jab and a quarter into slot 3's sweep."""
    from waferscan.gui.pocket_animation import frame_of, play_pockets
    from waferscan.gui.scanning import open_scenario, scan_and_store
    from waferscan.gui.session import session, show_task_panel

    doc = state["slow"] = open_scenario(SLOW)
    _, scanned = scan_and_store(doc)
    state["slow_result"] = scanned
    result["slow_report"] = report_record(scanned.clearance)
    result["slow_pockets"] = {p.slot: [p.z, p.depth, getattr(p, "reached", None)]
                              for p in scanned.pockets}
    pockets = play_pockets(doc, scanned, show_panel=show_task_panel)
    pockets.timer.stop()
    seen = []
    for slot, phase, fraction in ((8, "jab", 1.0), (3, "sweep", 0.25), (1, "jab", 0.0)):
        index = frame_of(pockets, slot, phase, fraction)
        pockets.show(index)
        pockets.moved.emit(index)
        Gui.updateGui()
        panel = session.task_panel
        seen.append({"frame": list(pockets.frames[index]), "clearance": panel.clearance.text(),
                     "style": panel.clearance.styleSheet(), "fork": fork_colour(doc)})
    result["pocket_frames"] = seen
    pockets.stop()
    Gui.updateGui()
    result["fork_after_pockets"] = fork_colour(doc)
    later(plan)


def plan():
    from waferscan.gui.dialogs import show_results_dialogs
    from waferscan.gui.plan_view import FORK, FORK_FILL_ALPHA

    doc = state["slow"]
    dialog = show_results_dialogs(doc, ("code",), result=state["slow_result"])[0]
    dialog.resize(1000, 900)
    view = dialog.plan_view
    dialog.views.setCurrentWidget(view)
    view.show_slot(8)
    view.canvas.repaint()
    Gui.updateGui()
    canvas = view.canvas
    result["fork_colour"] = [list(FORK), FORK_FILL_ALPHA]
    result["plan_drawn"] = [list(d) for d in canvas.drawn]
    result["swept"] = [{"part": s.part, "angles": s.angles, "advance": s.advance,
                        "pieces": len(s.pieces),
                        "outlines": {what: [list(p) for p in polygon]
                                     for what, polygon in s.outlines}}
                       for s in canvas.swept]
    image = canvas.grab().toImage()
    ratio = image.width() / canvas.width()
    points = {}
    for name, (u, v) in __import__("json").loads(os.environ["WAFERSCAN_GUI_POINTS"]).items():
        x, y = canvas.to_pixel(u, v)
        colour = QtGui.QColor(image.pixel(int(x * ratio), int(y * ratio)))
        points[name] = [colour.red(), colour.green(), colour.blue()]
    result["plan_points"] = points
    result["plan_legend"] = canvas.legend()
    dialog.grab().save(artifact("gui-clearance-plan.png"))
    result["slow_dialog_label"] = dialog.clearance_label.text()
    result["slow_contacts"] = dialog.contacts.rowCount() if dialog.contacts is not None else 0
    App.closeDocument(doc.Name)
    finish()


start(begin)
