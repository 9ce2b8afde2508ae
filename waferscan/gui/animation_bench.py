"""Run inside the FreeCAD GUI (``freecad this_file.py``): measure how many placement updates a
second the 3D view shows while the GUI's scan animation plays the demo layout as **Run scan**
plays it (``playback.play_scan``: the ``ScanAnimation``, a QTimer that places the robot in the 3D
view, no recompute, with its task panel: position, progress and the live signal trace), and the longest
stall. Writes a JSON result to $WAFERSCAN_BENCH_RESULT and quits.

What counts is what the user sees: a **frame shown** is a render of the 3D view (counted by a
callback node at the root of its scene graph, which a paint may traverse more than once: only
the first traversal after a new update counts) after at least one new placement update. The
bench does not force a redraw at each update, as its first version did (``Gui.updateGui()``):
Run scan forces none, and whether its updates get drawn is part of what is measured; updates
the event loop draws together count once, as one frame shown. ``updates_per_second`` counts
the placement updates, ``frames_per_second`` the frames shown, ``max_stall`` the longest gap
between two frames shown; ``view_fps`` and ``empty_view_fps`` the frames a second the same view
draws on demand with the layout and with nothing shown (FreeCAD's own view, the floor)."""

import json
import os
import time
import traceback

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

SECONDS = float(os.environ.get("WAFERSCAN_BENCH_SECONDS", "3"))


def main():
    from pivy import coin

    from waferscan.cad.document_scan import scan_document
    from waferscan.gui.playback import play_scan

    result = {"ok": False}
    try:
        doc = App.openDocument(os.environ["WAFERSCAN_BENCH_LAYOUT"])
        view = Gui.getDocument(doc.Name).ActiveView
        view.viewIsometric()
        Gui.SendMsgToActiveView("ViewFit")
        updates, shown = [], []

        def rendered(_data, action):
            # A render after a new update is a frame shown; other renders (a repaint of the
            # same pose) are not counted.
            if action.isOfType(coin.SoGLRenderAction.getClassTypeId()) and updates and \
                    (not shown or shown[-1][1] < len(updates)):
                shown.append((time.perf_counter(), len(updates)))

        counter = coin.SoCallback()
        counter.setCallback(rendered)
        view.getSceneGraph().insertChild(counter, 0)
        # The GUI's own Run scan (10 steps a frame, frames as fast as they come), panel and all.
        animation = play_scan(doc, scan_document(doc, "analytic"), steps_per_frame=10,
                                       show_results=False, panel=True)

        def frame(k, z):
            updates.append(time.perf_counter())
            if updates[-1] - updates[0] > SECONDS:
                animation.stop()

        def ended():
            # Up to the last update (the robot put back by stop() is no frame of the scan).
            times = [t for t, _ in shown if t <= updates[-1]]
            gaps = [b - a for a, b in zip(times, times[1:])]
            seconds = updates[-1] - updates[0]
            result.update(ok=len(times) > 1 and animation.fault is None,
                          updates=len(updates), seconds=seconds,
                          updates_per_second=(len(updates) - 1) / seconds,
                          frames=len(times),
                          frames_per_second=(len(times) - 1) / (times[-1] - times[0]),
                          max_stall=max(gaps), fault=animation.fault,
                          view_size=_view_size(view))
            try:
                result.update(_drawn_on_demand(doc, view))
            except Exception:  # the animation's figures stand without these
                result["on_demand_error"] = traceback.format_exc()
            finish(result)

        animation.moved.connect(frame)
        animation.finished.connect(lambda: QtCore.QTimer.singleShot(200, ended))
    except Exception:
        result["error"] = traceback.format_exc()
        finish(result)


def _drawn_on_demand(doc, view, frames=20):
    """How many frames a second the same 3D view draws when asked to (``redraw`` and the
    events it makes, one after the other, nothing else between): with the layout as the scan
    left it (``view_fps``), and with every object hidden (``empty_view_fps``: FreeCAD's own
    view, its background and navigation cube, the floor of any animation in it)."""

    def rate():
        for _ in range(3):
            view.redraw()
            Gui.updateGui()
        start = time.perf_counter()
        for _ in range(frames):
            view.redraw()
            Gui.updateGui()
        return frames / (time.perf_counter() - start)

    shown = rate()
    hidden = [o for o in doc.Objects
              if getattr(o, "ViewObject", None) is not None and o.ViewObject.Visibility]
    for obj in hidden:
        obj.ViewObject.Visibility = False
    try:
        empty = rate()
    finally:
        for obj in hidden:
            obj.ViewObject.Visibility = True
    return {"view_fps": shown, "empty_view_fps": empty}


def _view_size(view):
    """(width, height) in pixels of the 3D view's GL widget, as the measure drew it: the frame
    rate depends on it (software rendering)."""
    widget = view.graphicsView().viewport()
    return [widget.width(), widget.height()]


def finish(result):
    with open(os.environ["WAFERSCAN_BENCH_RESULT"], "w", encoding="utf-8") as handle:
        json.dump(result, handle)
    QtGui.QApplication.quit()


QtCore.QTimer.singleShot(500, main)
