"""Slow scanning's jab and sweep through the FreeCAD document (SPEC §13).

The arm moves in the document: with a robot, the jab is a straight advance of the fork solved by
inverse kinematics (``WaferRobot.straight_advance``) and the sweep a turn of the wrist joint; a
scanner without a robot is moved by its placement, along the fork's heading and about a wrist
axis ``sweep_radius`` behind the beam. The ``document`` engine moves it in sub-steps, reads the
beam and every wafer back from the document at each, brackets the first block of the jab and the
first and last of the sweep, and bisects each through the document to ``TOLERANCE``.
"""

from __future__ import annotations

import math

import FreeCAD as App

from ..core.errors import InputError
from ..core.geometry.beam import beam_hits_wafer
from ..core.scan import slow_scan
from .reader import beam_from
from .stepping import framed_wafers, scanner_ends

JAB_SUBSTEP = 0.5  # mm between the jab's sub-steps
SWEEP_SUBSTEP = 0.25  # degrees between the sweep's sub-steps
TOLERANCE = 1e-9  # mm for the jab's front, degrees for the sweep's angles


class ScannerArm:
    """A scanner that no robot carries, moved by its placement (``document_scan.ScannerMover``)."""

    def __init__(self, mover, layout):
        self.mover = mover
        self.layout = layout
        self.heading = slow_scan.heading(layout)

    def move(self, z, advance=0.0, turn=0.0):
        mover = self.mover
        moved = App.Placement(mover.start)
        moved.Base = (mover.start.Base + mover.axis * ((z - mover.z0) / mover.axis.z)
                      + App.Vector(*self.heading) * advance)
        if turn:
            wx, wy = slow_scan.wrist_axis(self.layout, z, advance)
            about = App.Placement(App.Vector(0, 0, 0), App.Rotation(App.Vector(0, 0, 1), turn),
                                  App.Vector(wx, wy, 0.0))
            moved = about.multiply(moved)
        mover.obj.Placement = mover.parent_inverse.multiply(moved)

    def restore(self):
        self.mover.restore()


class RobotArm:
    """The robot's arm (``robot.RobotMover``): the jab by inverse kinematics, the sweep by the
    wrist joint. Refuses a robot whose fork or wrist is not where the scan's settings put them:
    the analytic answer and the document would then speak of different motions."""

    def __init__(self, mover, layout):
        from .robot import apply_pose

        self._apply = apply_pose
        self.mover = mover
        robot, base = mover.robot, mover.base
        heading = robot.fork_heading(mover.start, base)
        expected = slow_scan.heading(layout)
        if max(abs(a - b) for a, b in zip(heading, expected)) > 1e-9:
            raise InputError(mover.holder.Label, None, "the fork's heading does not point into the scanned "
                                           "carrier: the robot cannot jab it")
        emitter, direction, length = robot.beam(mover.start, base)
        mid = [e + 0.5 * length * d for e, d in zip(emitter, direction)]
        wx, wy = robot.wrist_axis(mover.start, base)
        behind = (mid[0] - wx) * heading[0] + (mid[1] - wy) * heading[1]
        aside = (mid[0] - wx) * -heading[1] + (mid[1] - wy) * heading[0]
        radius = layout.scan.sweep_radius
        if abs(behind - radius) > 1e-6 or abs(aside) > 1e-6:
            raise InputError(mover.holder.Label, None, f"the robot's wrist axis is {behind:.6g} mm behind "
                                           f"its beam's midpoint ({aside:.3g} mm aside); the "
                                           f"scan's sweep_radius is {radius:g} mm: set "
                                           f"sweep_radius = {behind:.6g}")
        self.wrist = "wrist"
        if self.wrist not in robot.joint_names:
            raise InputError(mover.holder.Label, None, "the robot has no joint named 'wrist' to sweep with")

    def joints(self, z, advance=0.0, turn=0.0):
        mover = self.mover
        joints = mover.joints_at(z)
        if advance:
            try:
                joints = mover.robot.straight_advance(joints, mover.base, advance)
            except ValueError as exc:
                raise InputError(mover.holder.Label, None,
                                 f"the jab of {advance:g} mm at {z:g} mm: {exc}") from None
        if turn:
            joints = dict(joints)
            joints[self.wrist] += turn
        return joints

    def move(self, z, advance=0.0, turn=0.0):
        mover = self.mover
        self._apply(mover.robot, mover.holder, mover.links, mover.scanner,
                    self.joints(z, advance, turn))

    def restore(self):
        self.mover.restore()


def arm_for(mover, layout):
    """The arm that jabs and sweeps for this document's mover."""
    if hasattr(mover, "robot"):
        return RobotArm(mover, layout)
    return ScannerArm(mover, layout)


class JabbedMover:
    """A slow scan's Z steps with the fork in the pocket, advanced by the jab (SPEC §13)."""

    def __init__(self, mover, arm, advance):
        self.mover, self.arm, self.advance = mover, arm, advance

    def move_to(self, z):
        self.arm.move(z, self.advance)

    def restore(self):
        self.mover.restore()

    def moved_objects(self):
        return self.mover.moved_objects()


def document_measure(scene, arm, layout):
    """``measure(z, reach, amplitude)`` -> (front, sweep) for ``slow_scan.probe_pocket``
    (``amplitude``: ±A or the (low, high) angles the sweep reached),
    through the document (see the module's docstring)."""
    scanner = scene.scanner()
    ends = scanner_ends(scene)
    index = {w.name: i for i, w in enumerate(layout.wafers)}
    discs = {}

    def blocked(near, z, advance, turn):
        arm.move(z, advance, turn)
        beam = beam_from(scanner, ends)
        for i in near:
            if i not in discs:
                discs.update(framed_wafers(scene, layout, [i]))
            if beam_hits_wafer(beam.emitter, beam, discs[i].wafer_now()):
                return True
        return False

    def bisect(test, clear, hit):
        return slow_scan.bisect_boundary(test, clear, hit, TOLERANCE)

    def measure(z, reach, amplitude):
        near = [index[w.name] for w in slow_scan.wafers_near(layout, z)]
        front = sweep = None
        try:
            if reach > 0.0 and near:
                count = max(1, math.ceil(reach / JAB_SUBSTEP))
                steps = [min(reach, k * JAB_SUBSTEP) for k in range(count + 1)]
                for k, advance in enumerate(steps):
                    if blocked(near, z, advance, 0.0):
                        front = 0.0 if k == 0 else bisect(
                            lambda a: blocked(near, z, a, 0.0), steps[k - 1], advance)
                        break
            low, high = slow_scan.turn_bounds(amplitude)  # the angles the sweep reached
            if high > low and near:
                count = max(2, math.ceil((high - low) / SWEEP_SUBSTEP))
                grid = [low + (high - low) * k / count for k in range(count + 1)]
                hits = [k for k, a in enumerate(grid) if blocked(near, z, reach, a)]
                if hits:
                    i, j = hits[0], hits[-1]

                    def test(a):
                        return blocked(near, z, reach, a)

                    first = grid[i] if i == 0 else bisect(test, grid[i - 1], grid[i])
                    last = grid[j] if j == count else bisect(test, grid[j + 1], grid[j])
                    sweep = (first, last)
        finally:
            arm.restore()
        return front, sweep

    return measure


def for_document(scene, mover, layout, engine):
    """(mover, measure) for a CAD engine's scan: with a jab the Z steps are made with the fork
    in; the ``document`` engine measures the jab and the sweep through the document (``brep``
    takes the closed forms). Without a slow scan's jab or sweep: (mover, None)."""
    scan = layout.scan
    if not slow_scan.probes_pockets(scan):
        return mover, None
    arm = arm_for(mover, layout)
    if scan.jab > 0.0:
        mover = JabbedMover(mover, arm, scan.jab)
    measure = document_measure(scene, arm, layout) if engine == "document" else None
    return mover, measure
