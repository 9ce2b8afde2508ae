"""The task panel of an animated scan, in the combo view: play, pause and stop, the playback
speed, the scan position and what the beam sees, and the progress."""

from __future__ import annotations

import html

from PySide import QtCore, QtGui

from ..addon import icon_path
from .inputs import format_length, length_input, set_length
from .clearance_view import clearance_labels, show_clearance
from .qt import ClosableTaskPanel, set_progress


class ScanTaskPanel(ClosableTaskPanel):
    """Controls for a ``ScanAnimation``; closing the panel stops the animation."""

    def __init__(self, animation, on_completed=None, on_replay=None):
        self.animation = animation
        self.on_completed = on_completed
        self.on_replay = on_replay  # plays the same result again, in a fresh panel
        scan = animation.scan
        layout = animation.result.layout
        self.form = QtGui.QWidget()
        self.form.setWindowTitle("WaferScan scan")
        self.form.setWindowIcon(QtGui.QIcon(icon_path("WaferScan_RunScan.svg")))
        steps = (f"exact edges, drawn at {animation.count} positions" if scan.exact
                 else f"{scan.position_count} positions, step {format_length(scan.z_step)}")
        about = QtGui.QLabel(
            f"<b>{animation.doc.Label}</b>, carrier <b>{layout.carrier}</b>: Z "
            f"{format_length(scan.start_z)} to {format_length(scan.final_z)}, {steps}, "
            f"{scan.mode} mode, direction {scan.direction}")
        about.setWordWrap(True)
        from ..core.recipe import describe  # SPEC §11: the recipe the slots are judged by

        # Shown when Replay found the document changed since the scan and scanned it again.
        self.rescanned = QtGui.QLabel("The document changed since the last scan: Replay "
                                      "scanned it again.")
        self.rescanned.setWordWrap(True)
        self.rescanned.setStyleSheet("color: #b05000;")
        self.rescanned.hide()
        self.recipe = QtGui.QLabel(f"Recipe: {describe(animation.result.plan)}")
        self.recipe.setWordWrap(True)
        self.recipe.setToolTip("The mapping recipe (ScanSettings' Recipe properties)")
        self.z = length_input(scan.start_z, "Scan position: the emitter's Z", -1e6, 1e6)
        self.z.setReadOnly(True)
        self.beam = QtGui.QLabel("beam clear")
        self.beam.setToolTip("What the beam is blocked by at this position")
        # SPEC §15: the least clearance at the frame shown, and over the whole scan.
        self.clearance, self.least = clearance_labels(animation.clearance)
        self.progress = QtGui.QProgressBar()
        self.progress.setRange(0, animation.frames - 1)
        self.play_button = QtGui.QPushButton("Play")
        self.play_button.setToolTip("Play the scan, or go on after a pause")
        self.pause_button = QtGui.QPushButton("Pause")
        self.pause_button.setToolTip("Hold the robot where it is")
        self.stop_button = QtGui.QPushButton("Stop")
        self.stop_button.setToolTip("End the animation and put the robot back in its start pose")
        self.replay_button = QtGui.QPushButton("Replay")
        self.replay_button.setToolTip("Play the same scan again from the start")
        style = self.form.style()
        self.play_button.setIcon(style.standardIcon(QtGui.QStyle.SP_MediaPlay))
        self.pause_button.setIcon(style.standardIcon(QtGui.QStyle.SP_MediaPause))
        self.stop_button.setIcon(style.standardIcon(QtGui.QStyle.SP_MediaStop))
        self.replay_button.setIcon(style.standardIcon(QtGui.QStyle.SP_MediaSkipBackward))
        # Playback in real time: seconds for the whole scan, the same on any machine.
        self.speed = QtGui.QDoubleSpinBox()
        self.speed.setRange(0.5, 3600.0)
        self.speed.setDecimals(1)
        self.speed.setSingleStep(1.0)
        self.speed.setSuffix(" s")
        self.speed.setValue(animation.duration_s if animation.duration_s is not None
                            else animation.frames / (60.0 * animation.steps_per_frame))
        self.speed.setToolTip("Playback: seconds of real time for the whole scan")
        self.status = QtGui.QLabel("")
        self.alive_while_shown = self.status
        self.status.setWordWrap(True)
        # Two buttons a row: the panel fits FreeCAD's default combo view (264 px wide).
        buttons = QtGui.QGridLayout()
        for index, button in enumerate((self.play_button, self.pause_button, self.stop_button,
                                        self.replay_button)):
            buttons.addWidget(button, index // 2, index % 2)
        form = QtGui.QFormLayout()
        form.addRow("Position", self.z)
        form.addRow("Beam", self.beam)
        if animation.clearance is not None:
            form.addRow("Clearance", self.clearance)
            form.addRow("Least", self.least)
        form.addRow("Playback", self.speed)
        layout_box = QtGui.QVBoxLayout(self.form)
        layout_box.addWidget(about)
        layout_box.addWidget(self.rescanned)
        layout_box.addWidget(self.recipe)
        layout_box.addLayout(form)
        # Issues 14 and 17: the sensor's and the slow scan's settings, edited where scans run.
        from .sensor_section import SensorSection

        self.sensor = SensorSection(animation.doc)
        layout_box.addWidget(self.sensor.box)
        from .recipe_section import RecipeSection  # SPEC §11: the recipe, edited here too

        self.recipe_section = RecipeSection(animation.doc, None, animation.result.plan)
        layout_box.addWidget(self.recipe_section.box)
        layout_box.addWidget(self.progress)
        from .signal_view import live_trace  # SPEC §10: b(z) beside the animation

        self.trace = live_trace(animation)
        layout_box.addWidget(self.trace)
        layout_box.addLayout(buttons)
        layout_box.addWidget(self.status)
        layout_box.addStretch(1)
        self.play_button.clicked.connect(self.play)
        self.pause_button.clicked.connect(self.pause)
        self.stop_button.clicked.connect(animation.stop)
        self.replay_button.clicked.connect(self.replay)
        self.speed.valueChanged.connect(animation.set_duration)
        animation.moved.connect(self._moved)
        animation.finished.connect(self._finished)
        self._buttons()
        self.follow_document(animation.doc)

    def play(self):
        self.animation.play()
        self._buttons()

    def pause(self):
        self.animation.pause()
        self._buttons()

    def replay(self):
        if self.animation.ended and self.on_replay is not None:
            # Later: the replay replaces this panel, whose button is still being clicked.
            seconds = self.speed.value()
            QtCore.QTimer.singleShot(0, lambda: self.on_replay(seconds))

    def say_rescanned(self):
        """Say that this scan was made by Replay because the document had changed."""
        if self.is_open():
            self.rescanned.show()

    def object_changed(self, obj, prop):
        """The document changed (an Undo or Redo, the property editor): the sections show its
        values (``ClosableTaskPanel.follow_document``)."""
        for section in (self.sensor, self.recipe_section):
            section.follow(obj, prop)

    def _buttons(self):
        if not self.is_open():  # FreeCAD closed the panel; the animation ran on
            return
        ended = self.animation.ended
        running = self.animation.running
        self.play_button.setEnabled(not ended and not running)
        self.pause_button.setEnabled(running)
        self.stop_button.setEnabled(not ended)
        self.replay_button.setEnabled(ended and self.on_replay is not None)

    def _moved(self, k, z):
        if not self.is_open():
            return
        self._buttons()
        set_length(self.z, z)
        set_progress(self.progress, k)  # painted with the frame (gui/qt.py)
        lit = self.animation.lit
        # Only on a change: a style sheet set, even the same one, restyles the label and lays
        # the panel out again, at every frame of the animation.
        text = f"blocked by {', '.join(lit)}" if lit else "beam clear"
        if text != self.beam.text():
            self.beam.setText(text)
            self.beam.setStyleSheet("color: #c01010; font-weight: bold;" if lit else "")
        show_clearance(self.clearance, self.animation.clearance)

    def _finished(self):
        animation = self.animation
        if not self.is_open():
            return
        self._buttons()
        if animation.fault:
            self.status.setText(f"Stopped: {animation.fault}")
        elif animation.completed:
            self.progress.setValue(self.progress.maximum())
            warnings = "".join(f"<br><span style='color: #b05000'>Warning: {html.escape(w)}</span>"
                               for w in animation.result.warnings)
            self.status.setText(f"Done. Slot code <b>{animation.result.code}</b>{warnings}")
            if self.on_completed is not None:
                self.on_completed()
        else:
            self.status.setText(f"Stopped at Z {format_length(animation.z)}; the results of the "
                                "whole scan are in the results table (WaferScan → Results "
                                "table); Replay plays it again")

    def shut_down(self):
        self.animation.stop()

