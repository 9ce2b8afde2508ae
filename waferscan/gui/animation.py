"""The animated scan: a QTimer that steps the robot's lift joint (or the scanner) through the
scan positions by setting placements only, no recompute; the beam drawn red while blocked and
the wafer being hit highlighted. What is blocked comes from the headless scan's result: the
animation shows it, it does not compute it."""

from __future__ import annotations

import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..cad.document_scan import mover_for
from ..cad.reader import DocumentScene

BEAM_CLEAR, BEAM_BLOCKED = (0.1, 0.6, 0.1), (0.9, 0.1, 0.1)
WAFER_HIT = (0.95, 0.55, 0.1)


class ScanAnimation(QtCore.QObject):
    """Play, pause and stop an animated scan of ``doc`` whose result is ``result``."""

    finished = QtCore.Signal()

    def __init__(self, doc, result, steps_per_frame=10):
        super().__init__()
        self.doc, self.result = doc, result
        self.scan = result.layout.scan
        self.steps_per_frame = max(1, int(steps_per_frame))
        scene = DocumentScene.of(doc)
        self.mover = mover_for(scene, result.layout)
        self.beam = scene.scanner().obj
        self.spans = [(run.bottom, run.top, run.wafers) for run in result.runs]
        self.wafers = {w.Label: w for w in doc.Objects
                       if getattr(w, "WaferScanRole", "") == "Wafer"}
        self.colours = {label: tuple(w.ViewObject.ShapeColor[:3])
                        for label, w in self.wafers.items() if w.ViewObject}
        self.k = 0
        self.timer = QtCore.QTimer(self)
        self.timer.timeout.connect(self._tick)
        self.bar = QtGui.QProgressBar()
        self.bar.setRange(0, self.scan.position_count - 1)
        self.bar.setMaximumWidth(220)
        self.bar.setFormat("scanning %p %")
        Gui.getMainWindow().statusBar().addPermanentWidget(self.bar)
        self._lit = ()

    def play(self):
        self.timer.start(0)

    def pause(self):
        self.timer.stop()

    def stop(self):
        """Stop and put the robot back in its start pose."""
        self.timer.stop()
        self._light(())
        self.mover.restore()
        self._set_beam(BEAM_CLEAR)
        Gui.getMainWindow().statusBar().removeWidget(self.bar)
        self.finished.emit()

    @property
    def running(self):
        return self.timer.isActive()

    def _set_beam(self, colour):
        if self.beam.ViewObject is not None:
            self.beam.ViewObject.ShapeColor = colour
            self.beam.ViewObject.LineColor = colour

    def _light(self, names):
        if names == self._lit:
            return
        for name in self._lit:
            if name in self.wafers and name in self.colours:
                self.wafers[name].ViewObject.ShapeColor = self.colours[name]
        for name in names:
            if name in self.wafers and self.wafers[name].ViewObject:
                self.wafers[name].ViewObject.ShapeColor = WAFER_HIT
        self._lit = names

    def _tick(self):
        if self.k >= self.scan.position_count:
            self.stop()
            return
        z = self.scan.position(self.k)
        self.mover.move_to(z)
        hit = next((names for bottom, top, names in self.spans if bottom <= z <= top), ())
        self._set_beam(BEAM_BLOCKED if hit else BEAM_CLEAR)
        self._light(tuple(hit))
        self.bar.setValue(self.k)
        self.k += self.steps_per_frame
        if self.k >= self.scan.position_count and self.k - self.steps_per_frame < \
                self.scan.position_count - 1:
            self.k = self.scan.position_count - 1  # always show the last position
