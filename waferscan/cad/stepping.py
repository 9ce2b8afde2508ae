"""Stepping a scan through the FreeCAD document: what moves the scanner (its placement, or its
robot's lift joint) and the loop that moves it to each scan position and asks which wafers the
beam read back meets. The ``document`` engine (document_scan) and the ``brep`` engine (brep)
share it; it imports neither, so the data flows one way: document_scan -> brep -> stepping.
"""

from __future__ import annotations

import FreeCAD as App

from ..core.model import Wafer
from ..core.rules import check_stepped
from ..core.scan.engines import StepHits, reachable_wafers, runs_from_blocked
from . import roles
from .reader import beam_from


class WaferInItsFrame:
    """A wafer instance's disc in its own frame, so each step can place it from the placement
    read back through the document."""

    def __init__(self, instance, wafer):
        self.instance = instance
        self.wafer = wafer
        inverse = instance.placement().inverse()
        self.center = inverse.multVec(App.Vector(*wafer.center))
        self.normal = _turned(inverse, App.Vector(*wafer.normal))

    def wafer_now(self):
        """The wafer where its instance's placement puts it now (global coordinates)."""
        placement = self.instance.placement()
        c = placement.multVec(self.center)
        n = _turned(placement, self.normal)
        return Wafer(self.wafer.name, (c.x, c.y, c.z), (n.x, n.y, n.z), self.wafer.diameter,
                     self.wafer.thickness, bow=self.wafer.bow)


def _turned(placement, vector):
    """``vector`` turned by the placement's rotation. FreeCAD (0.20.2 and 1.0) keeps ~80 B for
    each read of ``Placement.Rotation`` (and of a vector property): the vector is turned by the
    placement's matrix with its translation taken out instead."""
    turn = placement.toMatrix()
    turn.A14 = turn.A24 = turn.A34 = 0.0
    return turn.multVec(vector)


def per_scene(scene, key, make):
    """``make()``, made once for a scene and ``key``. The MCS link keeps one scene for each
    version of the document, so its commands do not read the same placements and properties
    again: FreeCAD (0.20.2 and 1.0) keeps ~80 B for each such read, which a watcher answering
    thousands of commands would pile up (issue 25). Only the last scene's are kept."""
    if _MADE[0] is not scene:
        _MADE[:] = [scene, {}]
    made = _MADE[1]
    if key not in made:
        made[key] = make()
    return made[key]


_MADE = [None, {}]  # [the scene, {key: what was made}]


def framed_wafers(scene, layout, indices):
    """{i: WaferInItsFrame} for the wafers ``indices`` of the layout read from ``scene``."""
    return {i: per_scene(scene, ("framed", i, layout.wafers[i]),
                         lambda i=i: WaferInItsFrame(scene.wafers[i], layout.wafers[i]))
            for i in indices}


def scanner_ends(scene):
    """(emitter, receiver): the scanner's beam ends in its own frame, as Vectors."""
    def read():
        holder = roles.role_holder(scene.scanner().obj)
        return App.Vector(holder.Emitter), App.Vector(holder.Receiver)

    return per_scene(scene, "scanner ends", read)


class ScannerMover:
    """Moves a scanner that no robot carries along the lift axis by setting its Placement, and
    puts it back afterwards."""

    def __init__(self, instance, lift_axis):
        self.obj = instance.obj
        self.original = App.Placement(self.obj.Placement)
        start = instance.placement()
        # The placement of whatever contains the scanner, so that a global move can be written
        # into the scanner's own (local) Placement.
        self.parent_inverse = start.multiply(self.original.inverse()).inverse()
        self.start = start
        emitter = App.Vector(roles.role_holder(instance.obj).Emitter)
        self.z0 = start.multVec(emitter).z
        self.axis = App.Vector(*lift_axis)

    def move_to(self, z):
        """Put the emitter at scan position z."""
        for obj, placement in self.placements_at(z):
            obj.Placement = placement

    def placements_at(self, z):
        """[(object, Placement)]: where move_to(z) puts the scanner, without putting it there
        (the GUI's animation shows it in the 3D view only)."""
        moved = App.Placement(self.start)
        moved.Base = self.start.Base + self.axis * ((z - self.z0) / self.axis.z)
        return [(self.obj, self.parent_inverse.multiply(moved))]

    def restore(self):
        self.obj.Placement = self.original

    def moved_objects(self):
        return [self.obj]


def mover_for(scene, layout):
    """What moves the scanner for this document: its robot's lift joint, or its placement."""
    axis = tuple(layout.lift_axis)
    if scene.robots:
        from .robot import RobotMover  # pinocchio is imported only when a robot is there
        mover = per_scene(scene, ("robot mover", axis), lambda: RobotMover(scene, layout))
        mover.check_range(layout)
        return mover
    return per_scene(scene, ("scanner mover", axis),
                     lambda: ScannerMover(scene.scanner(), layout.lift_axis))



def stepper_through_document(scene, mover, prepare):
    """A stepped engine that goes through the document: for each scan position, move the
    scanner (or the robot's lift joint), read the beam back, and ask ``wafers_hit(beam)`` for
    the indices of the wafers it meets. ``prepare(layout, reachable)`` returns ``wafers_hit``;
    reachable are the wafers that pass the accessibility check."""

    def stepper(layout, progress=None):
        scan = layout.scan
        check_stepped(scan)
        wafers_hit = prepare(layout, reachable_wafers(layout))
        scanner = scene.scanner()
        ends = scanner_ends(scene)
        count = scan.position_count
        first = [None] * len(layout.wafers)
        last = [None] * len(layout.wafers)
        blocked = [False] * count
        try:
            for k in range(count):
                mover.move_to(scan.position(k))
                for i in wafers_hit(beam_from(scanner, ends)):
                    blocked[k] = True
                    first[i] = k if first[i] is None else first[i]
                    last[i] = k
                if progress is not None and k % 500 == 0:
                    progress(k, count)
        finally:
            mover.restore()
        steps = tuple(None if f is None else (f, l) for f, l in zip(first, last))
        return StepHits(count, steps, runs_from_blocked(blocked))

    return stepper

