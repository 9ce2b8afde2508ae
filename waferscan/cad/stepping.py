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
        self.normal = inverse.Rotation.multVec(App.Vector(*wafer.normal))

    def wafer_now(self):
        """The wafer where its instance's placement puts it now (global coordinates)."""
        placement = self.instance.placement()
        c = placement.multVec(self.center)
        # FreeCAD 0.20 leaks ~80 B on each Placement.Rotation (and vector property) access:
        # the normal is turned by the placement's matrix with its translation taken out.
        turn = placement.toMatrix()
        turn.A14 = turn.A24 = turn.A34 = 0.0
        n = turn.multVec(self.normal)
        return Wafer(self.wafer.name, (c.x, c.y, c.z), (n.x, n.y, n.z), self.wafer.diameter,
                     self.wafer.thickness, bow=self.wafer.bow)


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
    if scene.robots:
        from .robot import RobotMover  # pinocchio is imported only when a robot is there
        return RobotMover(scene, layout)
    return ScannerMover(scene.scanner(), layout.lift_axis)



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
        holder = roles.role_holder(scanner.obj)
        ends = (App.Vector(holder.Emitter), App.Vector(holder.Receiver))
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

