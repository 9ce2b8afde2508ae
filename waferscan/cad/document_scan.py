"""Scans through the FreeCAD document, as the paper does through the CAD API.

``scan_document(doc, engine)`` reads the document into a core ``Layout`` and scans it. With the
``document`` engine every step goes through the document: move the scanner (or set the robot's
lift joint), then read the scanner's and every wafer's global placement back and test. With the
``brep`` engine the test is OpenCASCADE's (see ``brep``). Other engines scan the layout read.
"""

from __future__ import annotations

import FreeCAD as App

from ..core.engines import CAD_ENGINES, StepHits, reachable_wafers, runs_from_blocked
from ..core.geometry import beam_hits_wafer
from ..core.mcs import apply_parameters
from ..core.model import Beam, Wafer, unit
from ..core.rules import check_stepped
from ..core.scan import scan_layout
from . import roles
from .reader import DocumentScene, beam_from, read_layout


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
        moved = App.Placement(self.start)
        moved.Base = self.start.Base + self.axis * ((z - self.z0) / self.axis.z)
        self.obj.Placement = self.parent_inverse.multiply(moved)

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


class _LocalDisc:
    """A wafer instance's disc in its own frame, so each step can place it from the placement
    read back through the document."""

    def __init__(self, instance, wafer):
        self.instance = instance
        self.wafer = wafer
        inverse = instance.placement().inverse()
        self.center = inverse.multVec(App.Vector(*wafer.center))
        self.normal = inverse.Rotation.multVec(App.Vector(*wafer.normal))

    def read(self):
        placement = self.instance.placement()
        c = placement.multVec(self.center)
        # FreeCAD 0.20 leaks ~80 B on each Placement.Rotation (and vector property) access:
        # the normal is turned by the placement's matrix with its translation taken out.
        turn = placement.toMatrix()
        turn.A14 = turn.A24 = turn.A34 = 0.0
        n = turn.multVec(self.normal)
        return Wafer(self.wafer.name, (c.x, c.y, c.z), (n.x, n.y, n.z), self.wafer.diameter,
                     self.wafer.thickness)


def stepper_through_document(scene, mover, prepare):
    """A stepped engine that goes through the document: for each scan position, move the
    scanner (or the robot's lift joint), read the beam back, and ask ``hits(beam)`` for the
    indices of the wafers it meets. ``prepare(layout, reachable)`` returns ``hits``; reachable
    are the wafers that pass the accessibility check."""

    def stepper(layout, progress=None):
        scan = layout.scan
        check_stepped(scan)
        hits = prepare(layout, reachable_wafers(layout))
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
                for i in hits(beam_from(scanner, ends)):
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


def document_stepper(scene, mover):
    """The ``document`` engine: the paper's procedure through the document API, every wafer's
    placement read back at every step and tested exactly."""

    def prepare(layout, reachable):
        discs = {i: _LocalDisc(scene.wafers[i], layout.wafers[i]) for i in reachable}
        return lambda beam: [i for i, disc in discs.items()
                             if beam_hits_wafer(beam.emitter, beam, disc.read())]

    return stepper_through_document(scene, mover, prepare)


def scan_document(doc, engine="analytic", progress=None, parameters=None, check=None,
                  read=None):
    """Read the document and scan it. ``parameters`` (a core ``mcs.Parameters``) override the
    document's own scan settings; ``check(layout)`` may refuse the layout before the scan;
    ``read`` is (scene, layout) already read from this document, unchanged since (the MCS
    link's cache). Returns the core ``ScanResult``."""
    if read is not None:
        scene, layout = read
    else:
        scene = DocumentScene.of(doc)
        # The scanner's LiftAxis says how the scan moves it (the robot's builder writes its
        # lift joint's axis there): reading needs no kinematics, so pinocchio stays unimported.
        layout = read_layout(doc, scene)
    if parameters is not None:
        layout = apply_parameters(layout, parameters)
    if check is not None:
        check(layout)
    stepper = None
    if engine in CAD_ENGINES:
        mover = mover_for(scene, layout)
        if engine == "document":
            stepper = document_stepper(scene, mover)
        else:
            from .brep import brep_stepper
            stepper = brep_stepper(scene, mover)
    return scan_layout(layout, engine, progress=progress, stepper=stepper)
