"""Run inside the FreeCAD GUI (``freecad this_file.py``): measure how many placement updates a
second the 3D view takes while the robot's lift joint steps through the demo layout, the way an
animation moves it (a QTimer that only sets placements, no recompute), and the longest stall
between two updates. Writes a JSON result to $WAFERSCAN_BENCH_RESULT and quits."""

import json
import os
import time
import traceback

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

SECONDS = float(os.environ.get("WAFERSCAN_BENCH_SECONDS", "3"))


def main():
    from waferscan.cad.reader import DocumentScene, read_layout
    from waferscan.cad.robot import RobotMover

    result = {"ok": False}
    try:
        doc = App.openDocument(os.environ["WAFERSCAN_BENCH_LAYOUT"])
        Gui.getDocument(doc.Name).ActiveView.viewIsometric()
        Gui.SendMsgToActiveView("ViewFit")
        scene = DocumentScene.of(doc)
        layout = read_layout(doc, scene)
        mover = RobotMover(scene, layout)
        scan = layout.scan
        ticks = []
        state = {"k": 0}
        timer = QtCore.QTimer()

        def tick():
            mover.move_to(scan.position(state["k"] % scan.position_count))
            state["k"] += 10  # playback: 10 steps a frame
            Gui.updateGui()  # the view redraws now: each update is a frame drawn
            ticks.append(time.perf_counter())
            if ticks[-1] - ticks[0] > SECONDS:
                timer.stop()
                gaps = [b - a for a, b in zip(ticks, ticks[1:])]
                result.update(ok=True, updates=len(ticks), seconds=ticks[-1] - ticks[0],
                              updates_per_second=(len(ticks) - 1) / (ticks[-1] - ticks[0]),
                              max_stall=max(gaps))
                finish(result)

        timer.timeout.connect(tick)
        timer.start(0)
    except Exception:
        result["error"] = traceback.format_exc()
        finish(result)


def finish(result):
    with open(os.environ["WAFERSCAN_BENCH_RESULT"], "w", encoding="utf-8") as handle:
        json.dump(result, handle)
    QtGui.QApplication.quit()


QtCore.QTimer.singleShot(500, main)
