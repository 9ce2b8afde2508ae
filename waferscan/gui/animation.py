"""The animated scan: a QTimer that steps the robot's lift joint (or the scanner) through the
scan positions by placing them in the 3D view only (``ViewPose``: the document is not changed, no
recompute); the beam drawn red while blocked and the wafer being hit highlighted
(``scan_appearance``). What is blocked comes from the headless scan's result: the animation
shows it, it does not compute it."""

from __future__ import annotations

import time

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..cad.stepping import mover_for
from ..cad.reader import DocumentScene
from ..core.model import DOWN, UPDOWN
from .beam_preview import previews
from .qt import GuiDocumentClosing, main_window_alive, set_progress
from .scan_appearance import BEAM_BLOCKED, BEAM_CLEAR, ScanAppearance

EXACT_FRAMES = 2000  # an exact scan (z_step = 0) has no steps: it is drawn at this many
CLOCK_FRAME_MS = 15  # played against the clock: a frame every 15 ms at most (≈ 60 a second)


class ScanAnimation(QtCore.QObject):
    """Play, pause and stop an animated scan of ``doc`` whose result is ``result``.

    The robot moves as the scan does: up, down, or up then down (the scan's direction), through
    its positions. The beam is red and a wafer highlighted while the beam meets it (the result's
    per-wafer intervals; the sensor's latched runs are what the table shows).

    ``moved(frame, z)`` is emitted at every frame; ``finished`` when the animation ends, at the
    last frame (``completed`` is then True), by ``stop()``, or by a fault (``fault`` says which).
    ``ended`` says whether it has; ``lit`` names the wafers the beam meets now. How the view
    looks meanwhile (and again after) is its ``appearance``'s. ``clearance`` (a
    ``LiveClearance``, None when the scan's clearance was not checked) holds the least distance
    at the frame shown; ``fork`` draws the fork red while it is a contact.
    """

    moved = QtCore.Signal(int, float)
    finished = QtCore.Signal()

    def __init__(self, doc, result, steps_per_frame=10, duration_s=None, scene=None):
        super().__init__()
        self.doc, self.result = doc, result
        self.scan = result.layout.scan
        self.steps_per_frame = max(1, int(steps_per_frame))
        # Played against the clock when given: the whole scan lasts duration_s seconds of real
        # time on any machine (frames are skipped on a slow one); else steps_per_frame a frame.
        self.duration_s = None if duration_s is None else max(0.1, float(duration_s))
        self._clock = (0.0, 0)  # (monotonic time, frame) the clock counts from
        self._frame_shown = None  # the frame shown last
        # The scene the scan read (DocumentScene), or the document read again (a replay).
        scene = scene or DocumentScene.of(doc)
        self.mover = mover_for(scene, result.layout)
        # The robot (or scanner) moved in the 3D view only, the document left as it is (None:
        # a moved object has no transform node of its own, so through the document).
        self.pose = ViewPose.of(self.mover, self.scan.start_z)
        # The carriers see-through, the beam drawn thick or over the scanner, until the end;
        # its preview (drawn while no scan plays) off the view meanwhile.
        previews.hide(doc)
        self.appearance = ScanAppearance(doc, scene, result)
        # SPEC §15: the least clearance at each frame (the body that measured the scan's
        # report, made once), and the fork drawn red while closer than clearance_min.
        from .clearance_view import ForkColour, LiveClearance

        self.clearance = LiveClearance.of(result, doc, scene)
        self.fork = ForkColour(doc) if self.clearance is not None else None
        # What the animation stands on: a deletion (kept alive for undo in the GUI, so nothing
        # raises) is seen by name at every frame and ends the animation.
        self.tracked = {o.Name: o.Label for o in self.mover.moved_objects()}
        self.tracked.update({i.obj.Name: i.obj.Label for i in scene.wafers + scene.carriers})
        self.spans = [(w.z_in, w.z_out, w.name) for w in result.wafers if w.z_in is not None]
        scan = self.scan
        if scan.exact:
            self.step, self.count = (scan.final_z - scan.start_z) / EXACT_FRAMES, EXACT_FRAMES + 1
        else:
            self.step, self.count = scan.z_step, scan.position_count
        self.frames = 2 * self.count - 1 if scan.direction == UPDOWN else self.count
        self.k = 0  # the frame shown next
        self.z = self.position(0)
        self.completed = False
        self.fault = None
        # The 3D views of the document, asked to draw each frame (see _tick).
        gui_doc = Gui.getDocument(doc.Name)
        self.views = list(gui_doc.mdiViewsOfType("Gui::View3DInventor")) if gui_doc else []
        self.timer = QtCore.QTimer(self)
        # Precise: Qt's default (coarse) timer may fire up to 5 % late, which held Run scan's
        # 15 ms frames to 63.5 a second however fast the view drew (66.7 now).
        self.timer.setTimerType(QtCore.Qt.PreciseTimer)
        self.timer.timeout.connect(self._tick)
        self.bar = QtGui.QProgressBar()
        self.bar.setRange(0, self.frames - 1)
        self.bar.setMaximumWidth(220)
        self.bar.setFormat("scanning %p %")
        Gui.getMainWindow().statusBar().addPermanentWidget(self.bar)
        self.ended = False
        self.closed = False
        self._closing = GuiDocumentClosing(doc.Name, self._document_closing)

    def position(self, frame):
        """The scan position shown at a frame, in the scan's direction."""
        k = frame
        if self.scan.direction == DOWN:
            k = self.count - 1 - frame
        elif self.scan.direction == UPDOWN and frame >= self.count:
            k = 2 * (self.count - 1) - frame
        return self.scan.start_z + k * self.step

    def set_speed(self, steps_per_frame):
        """Scan positions advanced per frame; takes effect at the next frame."""
        self.steps_per_frame = max(1, int(steps_per_frame))
        self.duration_s = None

    def set_duration(self, seconds):
        """Play the whole scan in ``seconds`` of real time, from where it stands now."""
        self.duration_s = max(0.1, float(seconds))
        self._clock = (time.monotonic(), self.k)
        if self.running:
            self.timer.start(CLOCK_FRAME_MS)

    def play(self):
        """Start, or go on after a pause (an animation that ended stays ended)."""
        if not self.ended:
            self._clock = (time.monotonic(), self.k)
            self.timer.start(0 if self.duration_s is None else CLOCK_FRAME_MS)

    def _next_frame(self):
        # Against the clock, the next tick decides (_due); else a fixed number of steps.
        return self.k + (1 if self.duration_s is not None else self.steps_per_frame)

    def _due(self):
        """The frame the clock has reached (played against the clock)."""
        started, first = self._clock
        return first + int((time.monotonic() - started) * (self.frames - 1) / self.duration_s)

    def pause(self):
        self.timer.stop()

    def stop(self):
        """Stop and put the robot back in its start pose."""
        self._end()

    @property
    def running(self):
        return self.timer.isActive()

    @property
    def lit(self):
        """The names of the wafers the beam meets now (highlighted in the 3D view)."""
        return self.appearance.lit

    def _document_closing(self):
        """The document is being closed: end here, while its views still exist, and leave them
        as they are (they go with it)."""
        self.closed = True
        self._end()

    def _end(self, completed=False, fault=None):
        if self.ended:
            return
        self.ended = True
        self.timer.stop()
        self._closing.close()
        self.completed, self.fault = completed, fault
        self.views = []
        if self.closed:  # only the scene-graph nodes held are let go
            undo = [self.appearance.release] + \
                ([self.pose.release] if self.pose is not None else []) + \
                ([self.fork.release] if self.fork is not None else [])
        else:
            # Each put back on its own: one that fails (its object deleted) leaves the others.
            undo = [lambda: self.appearance.light(()),
                    self.pose.restore if self.pose is not None else self.mover.restore,
                    *self.appearance.undo_steps(), lambda: previews.show(self.doc)] + \
                ([self.fork.restore] if self.fork is not None else [])
        for step in undo:
            try:
                step()
            except Exception as exc:  # the document changed under the animation
                self.fault = self.fault or f"{type(exc).__name__}: {exc}"
        if main_window_alive():  # not when FreeCAD quits: the status bar is gone
            Gui.getMainWindow().statusBar().removeWidget(self.bar)
            self.bar.deleteLater()
        if self.fault:
            App.Console.PrintError(f"WaferScan: animation stopped: {self.fault}\n")
        self.finished.emit()

    def _draw(self):
        """Ask the 3D views to draw this frame. Coin schedules a redraw after a placement
        changes from its own idle queue, which the next tick (a 0 ms timer, or 15 ms against
        the clock) keeps waiting: measured with the bench, 60 updates a second were set but
        20 drawn. Asked here, the view draws once per update, in the same paint as the panel's
        widgets. A view closed meanwhile is dropped."""
        for view in list(self.views):
            try:
                view.redraw()
            except Exception:  # the view was closed
                self.views.remove(view)

    def _tick(self):
        last = self.frames - 1
        if self.duration_s is not None and self._frame_shown is not None:
            due = self._due()
            if due <= self._frame_shown:
                return  # the clock has not reached the next frame yet
            self.k = min(due, last)
        try:
            gone = [label for name, label in self.tracked.items()
                    if self.doc.getObject(name) is None]
            if gone:
                self._end(fault=f"{', '.join(gone)} left the document; run the scan again")
                return
            self.z = self.position(self.k)
            if self.pose is not None:
                self.pose.show(self.mover.placements_at(self.z))
            else:
                self.mover.move_to(self.z)
            hit = tuple(name for z_in, z_out, name in self.spans if z_in <= self.z <= z_out)
            self.appearance.show_beam(BEAM_BLOCKED if hit else BEAM_CLEAR)
            self.appearance.light(hit)
            if self.clearance is not None:
                down = self.scan.direction == UPDOWN and self.k >= self.count
                self.clearance.at(self.clearance.motion_at(self.z, down), self.z)
                self.fork.show(self.clearance.contact)
        except Exception as exc:  # e.g. a robot link deleted while the animation runs
            self._end(fault=f"{type(exc).__name__}: {exc}")
            return
        set_progress(self.bar, self.k)  # painted with the frame, not on its own
        self._draw()
        self._frame_shown = self.k
        self.moved.emit(self.k, self.z)
        if self.k >= last:
            self._end(completed=True)
            return
        self.k = min(self._next_frame(), last)  # the last position is always shown


class ViewPose:
    """Shows objects in other placements in the 3D view only: the transform node at the top of
    each one's view (which FreeCAD keeps equal to its Placement) is set, the document is not.
    Setting the Placements themselves cost ~0.23 ms an object a frame (the document's signals,
    the tree, FreeCAD resizing the Part's origin to its bounding box): 1.4 ms a frame for the
    robot's six, and every animation touched the document. A node's field costs about a
    microsecond to set (a frame's whole move, forward kinematics included, ~0.4 ms).
    ``restore`` puts the view back on the document's placements."""

    def __init__(self, fields, nodes=()):
        self.fields = fields  # [(object, translation field, rotation field)]
        self.by_name = {obj.Name: (translation, rotation) for obj, translation, rotation in fields}
        # Held while shown: an object deleted (or its document closed) must not leave the
        # fields pointing into freed nodes.
        self.nodes = list(nodes)
        for node in self.nodes:
            node.ref()

    @classmethod
    def of(cls, mover, z):
        """The ViewPose of what ``mover`` moves, or None when an object's view has no transform
        node that shows its Placement (a link, another FreeCAD): then it moves through the
        document. ``z``: a scan position, to learn which objects move."""
        from pivy import coin

        fields, nodes = [], []
        for obj, _ in mover.placements_at(z):
            view = getattr(obj, "ViewObject", None)
            root = getattr(view, "RootNode", None) if view is not None else None
            node = root.getChild(0) if root is not None and root.getNumChildren() else None
            if node is None or not node.isOfType(coin.SoTransform.getClassTypeId()) or \
                    not _shows(node, obj.Placement):
                return None
            # Fields looked up once: pivy's attribute lookup of a field costs ~20 µs.
            fields.append((obj, node.translation, node.rotation))
            nodes.append(node)
        return cls(fields, nodes)

    def show(self, placements):
        """Draw each (object, Placement) there."""
        for obj, placement in placements:
            _set_fields(*self.by_name[obj.Name], placement)

    def restore(self):
        """The view shows the document's placements again (each on its own: an object deleted
        meanwhile is skipped, and said); the nodes are let go."""
        failed = None
        for obj, translation, rotation in self.fields:
            try:
                placement = obj.Placement
            except Exception as exc:  # deleted from the document meanwhile
                failed = failed or exc
                continue
            _set_fields(translation, rotation, placement)
        self.release()
        if failed is not None:
            raise failed

    def release(self):
        """Let go of the nodes held (once)."""
        nodes, self.nodes, self.fields, self.by_name = self.nodes, [], [], {}
        for node in nodes:
            node.unref()


def _set_fields(translation, rotation, placement):
    """A transform node's translation and rotation fields set to show ``placement``."""
    base = placement.Base
    translation.setValue(base.x, base.y, base.z)
    rotation.setValue(*placement.Rotation.Q)


def _shows(node, placement, tolerance=1e-4):
    """Whether a SoTransform node shows ``placement`` (its fields are single precision)."""
    base = placement.Base
    translation = node.translation.getValue()
    if any(abs(a - b) > tolerance * max(1.0, abs(b)) for a, b in
           zip((translation[0], translation[1], translation[2]), (base.x, base.y, base.z))):
        return False
    scale = node.scaleFactor.getValue()
    if any(abs(c - 1.0) > tolerance for c in (scale[0], scale[1], scale[2])):
        return False
    q = node.rotation.getValue().getValue()
    r = placement.Rotation.Q
    return abs(abs(sum(a * b for a, b in zip(q, r))) - 1.0) < tolerance
