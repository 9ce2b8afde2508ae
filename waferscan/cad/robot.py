"""The robot in the document: an App::Part at the robot's base holding one solid per URDF link
(built from the URDF's visual primitives) and the scanner on the fork. Link placements come from
Pinocchio's forward kinematics (``waferscan.robot``); the taught start pose is stored in the
document; a scan sets the lift joint and moves the links without a recompute.
"""

from __future__ import annotations

import math

import FreeCAD as App
import numpy as np
import Part

from ..core.errors import InputError
from ..robot.kinematics import WaferRobot
from . import features, roles

SCANNER_LINK = "fork"  # the link that carries the beam's emitter and receiver
EMITTER_FRAME, RECEIVER_FRAME = "beam_emitter", "beam_receiver"


def placement_of(rotation, translation):
    """An App.Placement from a 3x3 rotation matrix and a translation in mm."""
    r = np.asarray(rotation, dtype=float)
    t = np.asarray(translation, dtype=float)
    matrix = App.Matrix(r[0, 0], r[0, 1], r[0, 2], t[0],
                        r[1, 0], r[1, 1], r[1, 2], t[1],
                        r[2, 0], r[2, 1], r[2, 2], t[2],
                        0.0, 0.0, 0.0, 1.0)
    return App.Placement(matrix)


def _primitive(visual):
    if visual["kind"] == "box":
        x, y, z = visual["size"]
        shape = Part.makeBox(x, y, z, App.Vector(-x / 2, -y / 2, -z / 2))
    else:
        r, length = visual["radius"], visual["length"]
        shape = Part.makeCylinder(r, length, App.Vector(0, 0, -length / 2))
    shape.Placement = placement_of(visual["R"], visual["t"])
    return shape


def base_of(placement):
    """(xyz mm, yaw deg) of a robot base placement; the robot must stand upright."""
    axis = placement.Rotation.multVec(App.Vector(0, 0, 1))
    if abs(axis.z - 1.0) > 1e-9:
        raise ValueError("the robot's base must stand upright (rotated about Z only)")
    x_axis = placement.Rotation.multVec(App.Vector(1, 0, 0))
    base = placement.Base
    return (base.x, base.y, base.z), math.degrees(math.atan2(x_axis.y, x_axis.x))


def _joint_dict(holder):
    return dict(zip(holder.JointNames, holder.StartJoints))


def _urdf(holder):
    return holder.Urdf or None


def apply_pose(robot, holder, links, scanner, joints):
    """Place every link solid and the scanner for the joint values, relative to the robot's
    App::Part (whose placement is the base)."""
    for obj, placement in pose_placements(robot, links, scanner, joints):
        obj.Placement = placement


def pose_placements(robot, links, scanner, joints):
    """[(object, Placement)]: where ``apply_pose`` puts each link solid and the scanner for the
    joint values, without putting them there."""
    placements = robot.link_placements(joints)
    moved = [(obj, placement_of(*placements[name])) for name, obj in links.items()]
    moved.append((scanner, placement_of(*placements[SCANNER_LINK])))
    return moved


def load_robot(urdf, source):
    """The robot model of a URDF file; a file Pinocchio cannot read, or a model without the
    joints a scan needs, is bad input naming ``source`` (the scenario or the document)."""
    try:
        robot = WaferRobot(urdf)
        robot.limits[robot.lift_joint]  # noqa: B018 (a model without a lift joint cannot scan)
    except (ValueError, KeyError, RuntimeError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        where = "" if str(source) == str(urdf) else f"{urdf}: "
        raise InputError(source, None, f"{where}not a URDF robot WaferScan can move "
                                       f"({first[:200]})") from None
    return robot


class SensorConflict(InputError):
    """A scenario's [sensor] says what its [robot] cannot do: ``key`` is the [sensor] key. The
    scenario's reader names the key's line (``layout_files.open_layout``)."""

    def __init__(self, key, message):
        self.key = key
        super().__init__("[sensor]", None, f"{key}: {message}")


def _vector_text(v):
    return "[" + ", ".join(f"{c:.6g}" for c in v) + "]"


def check_sensor(robot, joints, base, beam, lift_axis):
    """Refuse (SensorConflict) a [sensor] the robot cannot honour: the beam's length is the
    fork's, emitter to receiver in the URDF, and the scan moves along the robot's lift axis.
    Silently using the robot's values would change the runs without a word."""
    _, _, length = robot.beam(joints, base)
    if abs(length - beam.length) > 1e-6:
        raise SensorConflict("length", f"the scenario's beam is {beam.length:g} mm long, the "
                             f"robot's fork holds emitter and receiver {length:g} mm apart: give "
                             f"length = {length:g}, or leave the [robot] out")
    axis = robot.lift_axis(base)
    if lift_axis is not None and max(abs(a - b) for a, b in zip(axis, lift_axis)) > 1e-9:
        raise SensorConflict("lift_axis", f"the scenario lifts along {_vector_text(lift_axis)}, "
                             f"the robot along {_vector_text(axis)} (its lift joint, its base "
                             f"upright): drop lift_axis, or leave the [robot] out")


def build_robot(doc, spec, beam, lift_axis=None):
    """Add the robot of a ``RobotSpec`` to the document, its start pose taught so that its beam
    lies on ``beam``; returns the robot's App::Part. A beam length or ``lift_axis`` (unit) the
    robot cannot give is refused (SensorConflict)."""
    robot = load_robot(spec.urdf, spec.urdf or "[robot]")
    base = (tuple(spec.base), spec.base_yaw)
    try:
        joints = robot.teach_start_pose(base, beam.emitter, beam.direction)
    except ValueError as exc:
        raise InputError(spec.urdf or "[robot]", None, f"cannot teach the start pose: {exc}") \
            from None
    check_sensor(robot, joints, base, beam, lift_axis)
    part = doc.addObject("App::Part", "Robot")
    part.Placement = App.Placement(App.Vector(*spec.base), App.Rotation(App.Vector(0, 0, 1),
                                                                          spec.base_yaw))
    roles.set_role(part, roles.ROBOT)
    roles.add_property(part, "App::PropertyString", "Urdf", "The robot's URDF; empty: the "
                       "bundled robot", spec.urdf or "")
    roles.add_property(part, "App::PropertyStringList", "JointNames", "Joints in order",
                       list(robot.joint_names))
    roles.add_property(part, "App::PropertyFloatList", "StartJoints", "Taught start-scanning "
                       "pose (mm for prismatic, degrees for revolute joints)",
                       [float(joints.get(n, 0.0)) for n in robot.joint_names])
    roles.add_property(part, "App::PropertyString", "LiftJoint", "The joint a scan moves",
                       robot.lift_joint)
    links = {}
    for name, visuals in robot.visuals().items():
        obj = doc.addObject("Part::Feature", "RobotLink")
        obj.Label = f"robot {name}"
        obj.Shape = Part.makeCompound([_primitive(v) for v in visuals])
        roles.add_property(obj, "App::PropertyString", "RobotLink", "URDF link shown", name)
        part.addObject(obj)
        links[name] = obj
    # The scanner sits in the fork's frame: emitter and receiver where the URDF puts them.
    fork_r, fork_t = robot.frame_placement(joints, SCANNER_LINK)
    local = []
    for frame in (EMITTER_FRAME, RECEIVER_FRAME):
        _, t = robot.frame_placement(joints, frame)
        local.append(tuple(np.asarray(fork_r).T @ (np.asarray(t) - np.asarray(fork_t))))
    scanner = features.make_scanner(doc, 0.0, robot.lift_axis(base))
    scanner.Emitter, scanner.Receiver = App.Vector(*local[0]), App.Vector(*local[1])
    part.addObject(scanner)
    apply_pose(robot, part, links, scanner, joints)
    return part


class RobotMover:
    """Moves the scanner by setting the robot's lift joint: Pinocchio's forward kinematics, then
    the links' placements, no recompute. Puts the robot back in its start pose afterwards."""

    def __init__(self, scene, layout):
        if len(scene.robots) != 1:
            raise scene.error(f"expected one robot, found {len(scene.robots)}")
        instance = scene.robots[0]
        self.holder = roles.role_holder(instance.obj)
        self.robot = load_robot(_urdf(self.holder), self.holder.Label)
        self.start = _joint_dict(self.holder)
        self.links, self.scanner = {}, None
        for obj in self.holder.Group:
            if "RobotLink" in obj.PropertiesList:
                self.links[obj.RobotLink] = obj
            elif roles.role_of(obj) == roles.SCANNER:
                self.scanner = obj
        if self.scanner is None:
            raise scene.error(f"the robot {self.holder.Label} carries no scanner")
        self.base = base_of(instance.placement())
        self.axis = self.robot.lift_axis(self.base)
        if max(abs(a - b) for a, b in zip(self.axis, layout.lift_axis)) > 1e-9:
            raise scene.error(f"the scanner's LiftAxis {tuple(layout.lift_axis)} is not the "
                              f"robot's lift axis {self.axis}")
        self.z0 = self.robot.beam(self.start, self.base)[0][2]
        self.error = scene.error
        self.check_range(layout)

    def check_range(self, layout):
        """Refuse a layout whose scan range takes the lift joint beyond its limits."""
        lift = self.robot.lift_joint
        low, high = self.robot.limits[lift]
        for z in (layout.scan.start_z, layout.scan.final_z):
            value = self.joints_at(z)[lift]
            if not low - 1e-9 <= value <= high + 1e-9:
                raise self.error(f"scan position {z:g} mm needs the {lift} joint at "
                                 f"{value:.3f} mm, beyond its limits {low:g}..{high:g} mm")

    def joints_at(self, z):
        joints = dict(self.start)
        lift = self.robot.lift_joint
        joints[lift] = joints.get(lift, 0.0) + (z - self.z0) / self.axis[2]
        return joints

    def move_to(self, z):
        apply_pose(self.robot, self.holder, self.links, self.scanner, self.joints_at(z))

    def placements_at(self, z):
        """[(object, Placement)]: where move_to(z) puts each link and the scanner, without
        putting them there (the GUI's animation shows them in the 3D view only)."""
        return pose_placements(self.robot, self.links, self.scanner, self.joints_at(z))

    def restore(self):
        apply_pose(self.robot, self.holder, self.links, self.scanner, self.start)

    def moved_objects(self):
        return [self.holder, *self.links.values(), self.scanner]
