"""A slow scan's jabs and sweeps animated (SPEC §13): after the Z steps, pocket by pocket, the
arm jabs in, the wrist sweeps -A .. +A and the arm draws back, moved in the document as the
``document`` engine moves it (``cad.pocket_probe``: inverse kinematics for the straight advance,
the wrist joint for the sweep). Its task panel shows the pocket, the phase and the advance or the
wrist angle, and what the beam meets. The beam's state at each frame is the exact test on the
layout's wafers (the analytic answer the results give)."""

from __future__ import annotations

import html
import math

import FreeCAD as App
from PySide import QtCore, QtGui

from ..addon import icon_path
from ..cad.document_scan import mover_for
from ..cad.pocket_probe import arm_for
from ..cad.reader import DocumentScene
from ..core.geometry.beam import beam_hits_wafer
from ..core.scan import slow_scan
from .beam_preview import previews
from .qt import ClosableTaskPanel, GuiDocumentClosing
from .scan_appearance import BEAM_BLOCKED, BEAM_CLEAR  # the beam's colours as the scan's
JAB_FRAMES, SWEEP_FRAMES = 16, 40  # frames of the jab in (and as many out) and of the sweep
FRAME_MS = 10
SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)  # the panel's choices: × the frames a tick


def pocket_frames(result):
    """The animation's frames: (slot, phase, z, advance mm, wrist turn deg) for each probed
    pocket: the jab in, the sweep 0 -> low -> high -> 0 at the deepest point (-A and +A unless
    the sweep stopped short), the jab out."""
    from ..core.scan.pocket_plan import sweep_angles

    layout = result.layout
    frames = []
    for probe in result.pockets:
        z, depth = probe.z, probe.depth
        if depth > 0.0:
            frames += [(probe.slot, "jab", z, depth * k / JAB_FRAMES, 0.0)
                       for k in range(JAB_FRAMES + 1)]
        # The angles the sweep turned: where each side stopped short of clearance_min
        # (SPEC §13 amended), else the whole ±sweep.
        angles = sweep_angles(layout, probe)
        if angles is not None:
            low, high = angles
            quarter = SWEEP_FRAMES // 4
            turns = ([low * k / quarter for k in range(quarter + 1)]
                     + [low + (high - low) * k / (2 * quarter)
                        for k in range(1, 2 * quarter + 1)]
                     + [high - high * k / quarter for k in range(1, quarter + 1)])
            frames += [(probe.slot, "sweep", z, depth, a) for a in turns]
        if depth > 0.0:
            frames += [(probe.slot, "back", z, depth * (1 - k / JAB_FRAMES), 0.0)
                       for k in range(1, JAB_FRAMES + 1)]
    return frames


def describe(frame):
    """What the panel says of a frame: the pocket, the phase and the advance or angle."""
    slot, phase, z, advance, turn = frame
    if phase == "sweep":
        return (f"pocket {slot}", "sweep", f"wrist {turn:+.2f}°")
    return (f"pocket {slot}", "jab in" if phase == "jab" else "jab out", f"advance {advance:.2f} mm")


class PocketAnimation(QtCore.QObject):
    """Plays ``pocket_frames(result)`` on ``doc``; ``moved(index)`` at every frame shown,
    ``finished`` at the end or on ``stop()`` (the arm then back in its start pose). It can be
    paused and resumed, played faster or slower (``set_speed``: above 1, frames are skipped,
    since moving the arm in the document is what takes the time; below 1, the ticks are
    spaced), and sent to a pocket (``go_to``)."""

    moved = QtCore.Signal(int)
    finished = QtCore.Signal()

    def __init__(self, doc, result):
        super().__init__()
        self.doc, self.result = doc, result
        layout = result.layout
        self.layout = layout
        scene = DocumentScene.of(doc)
        self.arm = arm_for(mover_for(scene, layout), layout)
        # SPEC §15: the least clearance at each frame (the scan's body, made once a scan), the
        # fork drawn red while closer than clearance_min.
        from .clearance_view import ForkColour, LiveClearance

        self.clearance = LiveClearance.of(result, doc, scene)
        self.fork = ForkColour(doc) if self.clearance is not None else None
        self.beam_obj = scene.scanner().obj
        self.frames = pocket_frames(result)
        self.near = {}
        self.k = 0
        self.blocked = False
        self.ended = False
        self.paused = False
        self.speed = 1.0
        self.timer = QtCore.QTimer(self)
        self.timer.timeout.connect(self._tick)
        # As in the scan's animation: the carriers see-through while the arm is in them.
        self._restore_view = []
        for instance in scene.carriers:
            view = instance.obj.ViewObject
            if view is not None and "Transparency" in view.PropertiesList:
                self._restore_view.append((view, view.Transparency))
                view.Transparency = 70
        self.closed = False  # ended because the document is being closed
        self._closing = GuiDocumentClosing(doc.Name, self._document_closing)
        previews.hide(doc)  # the beam is drawn in the animation's colours meanwhile

    def play(self):
        if not self.ended:
            self.paused = False
            self.timer.start(self._interval())

    def _interval(self):
        return max(1, int(round(FRAME_MS / min(self.speed, 1.0))))

    def pause(self):
        """Hold the arm where it is (``play`` goes on from there)."""
        if not self.ended:
            self.paused = True
            self.timer.stop()

    def set_speed(self, factor):
        """Play ``factor`` times as fast (0.25 to 8)."""
        self.speed = float(factor)
        if self.timer.isActive():
            self.timer.start(self._interval())

    def pockets(self):
        """The probed slots, in the order they are played."""
        return list(dict.fromkeys(frame[0] for frame in self.frames))

    def go_to(self, slot):
        """Show the first frame of ``slot``'s pocket now; playing (unless paused) goes on from
        there."""
        if self.ended:
            return
        index = next(i for i, frame in enumerate(self.frames) if frame[0] == slot)
        self.show(index)
        self.moved.emit(index)
        self.k = index + 1

    def _document_closing(self):
        """The document is being closed: end now, leaving the view to go with it."""
        self.closed = True
        self.stop()

    def stop(self):
        if self.ended:
            return
        self.ended = True
        self.timer.stop()
        self._closing.close()
        if self.closed:
            if self.fork is not None:
                self.fork.release()
            self.finished.emit()
            return
        # Each put back on its own: one that fails (its object deleted under the animation)
        # leaves the others to be put back.
        steps = [lambda: previews.show(self.doc), self.arm.restore,
                 lambda: self._colour(BEAM_CLEAR)]
        steps += [lambda view=view, value=value: setattr(view, "Transparency", value)
                  for view, value in self._restore_view]
        if self.fork is not None:
            steps.append(self.fork.restore)
        for step in steps:
            try:
                step()
            except Exception as exc:  # the document changed under the animation
                App.Console.PrintError(f"WaferScan: pocket animation: {exc}\n")
        self.finished.emit()

    def show(self, index):
        """Move the arm to a frame and colour the beam by what it meets there."""
        slot, phase, z, advance, turn = frame = self.frames[index]
        self.arm.move(z, advance, turn)
        if z not in self.near:
            self.near[z] = slow_scan.wafers_near(self.layout, z)
        emitter, beam = slow_scan.beam_at(self.layout, z, advance, turn)
        self.blocked = any(beam_hits_wafer(emitter, beam, w) for w in self.near[z])
        self._colour(BEAM_BLOCKED if self.blocked else BEAM_CLEAR)
        if self.clearance is not None:
            self._clearance(frame)
        return frame

    def _clearance(self, frame):
        """The least distance at the frame, of the pocket's jab (the advance) or sweep (the
        wrist angle) as the scan's report measured them; the fork red while a contact."""
        from ..core.scan import clearance as core
        from ..core.scan.pocket_plan import sweep_angles

        slot, phase, z, advance, turn = frame
        probe = next(p for p in self.result.pockets if p.slot == slot)
        if phase == "sweep":
            motion = self.clearance.pocket_motion(core.SWEEP, slot, z, advance,
                                                  sweep_angles(self.layout, probe))
            self.clearance.at(motion, turn)
        else:
            motion = self.clearance.pocket_motion(core.JAB, slot, z, probe.depth, None)
            self.clearance.at(motion, advance)
        self.fork.show(self.clearance.contact)

    def _colour(self, colour):
        view = self.beam_obj.ViewObject
        if view is not None:
            view.ShapeColor = colour
            view.LineColor = colour

    def _tick(self):
        if self.k >= len(self.frames):
            self.stop()
            return
        if self.speed > 1.0:  # the frames in between skipped; the last one always shown
            self.k = min(len(self.frames) - 1, self.k + int(round(self.speed)) - 1)
        try:
            self.show(self.k)
        except Exception as exc:
            App.Console.PrintError(f"WaferScan: pocket animation stopped: {exc}\n")
            self.stop()
            return
        self.moved.emit(self.k)
        self.k += 1


class PocketTaskPanel(ClosableTaskPanel):
    """The pocket animation's panel: pocket, phase, advance or angle, the beam; Stop."""

    def __init__(self, animation, on_completed=None):
        self.animation = animation
        self.on_completed = on_completed
        scan = animation.layout.scan
        self.form = QtGui.QWidget()
        self.form.setWindowTitle("WaferScan jabs and sweeps")
        self.form.setWindowIcon(QtGui.QIcon(icon_path("WaferScan_RunScan.svg")))
        about = QtGui.QLabel(f"Slow scan, pocket by pocket: jab {scan.jab:g} mm, sweep "
                             f"±{scan.sweep:g}°, {len(animation.result.pockets)} pockets")
        about.setWordWrap(True)
        self.pocket, self.phase, self.amount = QtGui.QLabel(""), QtGui.QLabel(""), QtGui.QLabel("")
        self.beam = QtGui.QLabel("beam clear")
        self.found = QtGui.QLabel("")
        self.found.setWordWrap(True)
        self.progress = QtGui.QProgressBar()
        self.progress.setRange(0, max(1, len(animation.frames) - 1))
        self.stop_button = QtGui.QPushButton("Stop")
        self.stop_button.setToolTip("End the animation and put the arm back in its start pose")
        self.pause_button = QtGui.QPushButton("Pause")
        self.pause_button.setToolTip("Hold the arm where it is; Resume goes on from there")
        self.speed = QtGui.QComboBox()
        for factor in SPEEDS:
            self.speed.addItem(f"{factor:g}×", factor)
        self.speed.setCurrentIndex(SPEEDS.index(1.0))
        self.speed.setToolTip("How fast the jabs and sweeps play (above 1×, frames are skipped)")
        self.go_to = QtGui.QComboBox()
        for slot in animation.pockets():
            self.go_to.addItem(f"pocket {slot}", slot)
        self.go_to.setToolTip("Jump to a pocket's jab")
        form = QtGui.QFormLayout()
        form.addRow("Pocket", self.pocket)
        form.addRow("Phase", self.phase)
        form.addRow("Arm", self.amount)
        form.addRow("Beam", self.beam)
        from .clearance_view import clearance_labels

        self.clearance, self.least = clearance_labels(animation.clearance)
        if animation.clearance is not None:
            form.addRow("Clearance", self.clearance)
        form.addRow("Found", self.found)
        self.status = self.alive_while_shown = QtGui.QLabel("")
        self.status.setWordWrap(True)
        box = QtGui.QVBoxLayout(self.form)
        box.addWidget(about)
        box.addLayout(form)
        box.addWidget(self.progress)
        controls = QtGui.QFormLayout()
        controls.addRow("Speed", self.speed)
        controls.addRow("Go to", self.go_to)
        box.addLayout(controls)
        buttons = QtGui.QHBoxLayout()
        buttons.addWidget(self.pause_button)
        buttons.addWidget(self.stop_button)
        box.addLayout(buttons)
        box.addWidget(self.status)
        box.addStretch(1)
        self.stop_button.clicked.connect(animation.stop)
        self.pause_button.clicked.connect(self._pause_or_resume)
        self.speed.currentIndexChanged.connect(
            lambda index: animation.set_speed(self.speed.itemData(index)))
        self.go_to.activated.connect(lambda index: animation.go_to(self.go_to.itemData(index)))
        animation.moved.connect(self._moved)
        animation.finished.connect(self._finished)
        self.follow_document(animation.doc)

    def _pause_or_resume(self):
        if self.animation.paused:
            self.animation.play()
            self.pause_button.setText("Pause")
        else:
            self.animation.pause()
            self.pause_button.setText("Resume")

    def _moved(self, k):
        if not self.is_open():
            return
        frame = self.animation.frames[k]
        if self.go_to.currentData() != frame[0]:
            self.go_to.setCurrentIndex(self.go_to.findData(frame[0]))
        pocket, phase, amount = describe(frame)
        self.pocket.setText(pocket)
        self.phase.setText(phase)
        self.amount.setText(amount)
        self.progress.setValue(k)
        blocked = self.animation.blocked
        self.beam.setText("blocked" if blocked else "beam clear")
        self.beam.setStyleSheet("color: #c01010; font-weight: bold;" if blocked else "")
        probe = next(p for p in self.animation.result.pockets if p.slot == frame[0])
        front = "none" if probe.front is None else f"{probe.front:.3f} mm"
        sweep = "none" if probe.sweep is None else \
            f"{probe.sweep[0]:+.3f}° to {probe.sweep[1]:+.3f}°"
        self.found.setText(f"front {front}, sweep {sweep}")
        from .clearance_view import show_clearance

        show_clearance(self.clearance, self.animation.clearance)

    def _finished(self):
        if not self.is_open():
            return
        for control in (self.stop_button, self.pause_button, self.speed, self.go_to):
            control.setEnabled(False)
        done = self.animation.k >= len(self.animation.frames)
        # The scan's warnings as the Z steps' panel gives them (SPEC §3): among them a sweep
        # that turns a tine into a wafer, and a pocket off position by its sweep.
        warnings = "".join(f"<br><span style='color: #b05000'>Warning: {html.escape(w)}</span>"
                           for w in self.animation.result.warnings)
        self.status.setText(f"Done. Slot code <b>{self.animation.result.code}</b>{warnings}"
                            if done else "Stopped; the arm is back in its start pose")
        if done and self.on_completed is not None:
            self.on_completed()

    def shut_down(self):
        self.animation.stop()


def play_pockets(doc, result, on_completed=None, show_panel=None):
    """Animate a slow scan's jabs and sweeps; ``show_panel(panel)`` opens its task panel (the
    commands' way, closing the scan's). Returns the animation, playing."""
    animation = PocketAnimation(doc, result)
    if show_panel is not None:
        show_panel(PocketTaskPanel(animation, on_completed))
    elif on_completed is not None:
        animation.finished.connect(lambda: animation.k >= len(animation.frames)
                                   and on_completed())
    animation.play()
    return animation


def frame_of(animation, slot, phase, fraction=1.0):
    """Index of the frame of ``slot``'s ``phase`` at ``fraction`` of it (probes, screenshots)."""
    indices = [i for i, f in enumerate(animation.frames) if f[0] == slot and f[1] == phase]
    return indices[min(len(indices) - 1, int(math.floor(fraction * (len(indices) - 1))))]


def then_pockets(doc, result, on_completed, show_panel, session):
    """What the scan's animation does when it completes, for a slow scan with probed pockets:
    play the jabs and sweeps (in their own panel, which replaces the scan's, once the scan's
    has finished its own work), then ``on_completed``. ``session`` keeps the animation."""

    def start():
        session.pocket_animation = play_pockets(doc, result, on_completed, show_panel)

    return lambda: QtCore.QTimer.singleShot(0, start)
