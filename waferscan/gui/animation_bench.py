"""Run inside the FreeCAD GUI (``freecad this_file.py``): measure how many placement updates a
second the 3D view takes while the GUI's scan animation (``ScanAnimation``: a QTimer that only
sets placements, no recompute) steps the robot's lift joint through the demo layout, and the
longest stall between two updates. Writes a JSON result to $WAFERSCAN_BENCH_RESULT and quits."""

import json
import os
import time
import traceback

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

SECONDS = float(os.environ.get("WAFERSCAN_BENCH_SECONDS", "3"))


def main():
    from waferscan.cad.document_scan import scan_document
    from waferscan.gui.animation import ScanAnimation

    result = {"ok": False}
    try:
        doc = App.openDocument(os.environ["WAFERSCAN_BENCH_LAYOUT"])
        Gui.getDocument(doc.Name).ActiveView.viewIsometric()
        Gui.SendMsgToActiveView("ViewFit")
        # The GUI's own animation (as Run scan plays it, 10 steps a frame), with a redraw
        # forced at every frame so that each update counted is a frame drawn.
        animation = ScanAnimation(doc, scan_document(doc, "analytic"), steps_per_frame=10)
        ticks = []

        def frame(k, z):
            Gui.updateGui()
            ticks.append(time.perf_counter())
            if ticks[-1] - ticks[0] > SECONDS:
                animation.stop()

        def ended():
            gaps = [b - a for a, b in zip(ticks, ticks[1:])]
            result.update(ok=len(ticks) > 1 and animation.fault is None, updates=len(ticks),
                          seconds=ticks[-1] - ticks[0],
                          updates_per_second=(len(ticks) - 1) / (ticks[-1] - ticks[0]),
                          max_stall=max(gaps), fault=animation.fault)
            finish(result)

        animation.moved.connect(frame)
        animation.finished.connect(ended)
        animation.play()
    except Exception:
        result["error"] = traceback.format_exc()
        finish(result)


def finish(result):
    with open(os.environ["WAFERSCAN_BENCH_RESULT"], "w", encoding="utf-8") as handle:
        json.dump(result, handle)
    QtGui.QApplication.quit()


QtCore.QTimer.singleShot(500, main)
