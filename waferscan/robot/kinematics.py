"""The wafer-handling robot's kinematics with Pinocchio, from its URDF.

URDF and Pinocchio work in metres and radians; this module's API in millimetres and degrees. The
conversion happens in ``_to_q`` (joint values in) and ``_placement`` (placements out), and
nowhere else. A base placement is ((x, y, z) mm, yaw degrees about Z).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

from ..addon import addon_root, require_pinocchio

require_pinocchio()  # a clear error with the fix (an Addon Manager install has no pinocchio)
import pinocchio as pin  # noqa: E402

MM = 1000.0  # millimetres per metre
FORK, EMITTER, RECEIVER = "fork", "beam_emitter", "beam_receiver"


def bundled_urdf():
    return str(Path(addon_root()) / "resources" / "robots" / "wafer_robot.urdf")


def _rotation_z(degrees):
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _origin(element):
    """(R, t in m) of a URDF <origin>; absent means identity."""
    if element is None:
        return np.eye(3), np.zeros(3)
    xyz = [float(v) for v in element.get("xyz", "0 0 0").split()]
    roll, pitch, yaw = (float(v) for v in element.get("rpy", "0 0 0").split())
    rotation = pin.rpy.rpyToMatrix(roll, pitch, yaw)
    return np.array(rotation), np.array(xyz)


class WaferRobot:
    """A robot model (Pinocchio ``Model``) with its own ``Data``, frames looked up once."""

    def __init__(self, urdf_path=None):
        self.urdf = urdf_path or bundled_urdf()
        self.model = pin.buildModelFromUrdf(self.urdf)
        self.data = self.model.createData()
        self.joint_names = tuple(self.model.names[i] for i in range(1, self.model.njoints))
        self._prismatic = {name: self.model.joints[i].shortname().startswith("JointModelP")
                           for i, name in enumerate(self.model.names) if i > 0}
        self._frames = {f.name: i for i, f in enumerate(self.model.frames)}
        self.lift_joint = "lift"
        # _to_q's constants, looked up once: it makes the configuration of every pose a
        # clearance search weighs (each lookup through Pinocchio's bindings costs more than
        # the conversion itself).
        self._neutral = pin.neutral(self.model)
        self._q_slots = tuple((name, self.model.joints[i + 1].idx_q, self._prismatic[name])
                              for i, name in enumerate(self.joint_names))
        self.limits = {}
        for name, q, prismatic in self._q_slots:
            scale = MM if prismatic else math.degrees(1.0)
            self.limits[name] = (float(self.model.lowerPositionLimit[q]) * scale,
                                 float(self.model.upperPositionLimit[q]) * scale)
        self._visuals = self._read_visuals()

    # --- the one unit boundary ------------------------------------------------------------

    def _to_q(self, joints):
        q = self._neutral.copy()
        for name, index, prismatic in self._q_slots:
            value = float(joints.get(name, 0.0))
            q[index] = value / MM if prismatic else math.radians(value)
        return q

    @staticmethod
    def _placement(se3):
        return np.array(se3.rotation), np.array(se3.translation) * MM

    # --- forward kinematics ----------------------------------------------------------------

    def frame_placement(self, joints, frame):
        """(R, t mm) of a URDF link or frame in the robot's base frame."""
        pin.framesForwardKinematics(self.model, self.data, self._to_q(joints))
        return self._placement(self.data.oMf[self._frames[frame]])

    def link_placements(self, joints):
        """(R, t mm) in the base frame of every link that has visuals."""
        pin.framesForwardKinematics(self.model, self.data, self._to_q(joints))
        return {name: self._placement(self.data.oMf[self._frames[name]])
                for name in self._visuals}

    def _read_visuals(self):
        visuals = {}
        for link in ElementTree.parse(self.urdf).getroot().iter("link"):
            found = []
            for visual in link.findall("visual"):
                rotation, translation = _origin(visual.find("origin"))
                geometry = visual.find("geometry")
                box, cylinder = geometry.find("box"), geometry.find("cylinder")
                if box is not None:
                    size = tuple(float(v) * MM for v in box.get("size").split())
                    found.append(dict(kind="box", size=size, R=rotation, t=translation * MM))
                elif cylinder is not None:
                    found.append(dict(kind="cylinder", radius=float(cylinder.get("radius")) * MM,
                                      length=float(cylinder.get("length")) * MM, R=rotation,
                                      t=translation * MM))
            if found:
                visuals[link.get("name")] = found
        return visuals

    def visuals(self):
        """Per link, its visual primitives (box size or cylinder radius and length, mm) with
        their placement (R, t mm) in the link's frame; a cylinder's axis is its local Z."""
        return self._visuals

    @staticmethod
    def _world(base, rotation, translation):
        (x, y, z), yaw = base
        turn = _rotation_z(yaw)
        return turn @ rotation, turn @ translation + np.array([x, y, z], dtype=float)

    def beam(self, joints, base=((0.0, 0.0, 0.0), 0.0)):
        """(emitter mm, unit direction, length mm) of the beam in the world."""
        pin.framesForwardKinematics(self.model, self.data, self._to_q(joints))
        _, e = self._world(base, *self._placement(self.data.oMf[self._frames[EMITTER]]))
        _, r = self._world(base, *self._placement(self.data.oMf[self._frames[RECEIVER]]))
        length = float(np.linalg.norm(r - e))
        return tuple(float(v) for v in e), tuple(float(v) for v in (r - e) / length), length

    def lift_axis(self, base=((0.0, 0.0, 0.0), 0.0)):
        """World direction in which the lift joint moves the arm."""
        rest = self.frame_placement({}, FORK)[1]
        raised = self.frame_placement({self.lift_joint: 1.0}, FORK)[1]
        axis = _rotation_z(base[1]) @ (raised - rest)
        return tuple(float(v) for v in axis / np.linalg.norm(axis))

    # --- the taught start-scanning pose ----------------------------------------------------

    def teach_start_pose(self, base, emitter, direction):
        """Joint values that put the beam's emitter at ``emitter`` (world, mm) with the beam
        along ``direction`` (world, horizontal): the start-scanning position.

        The fork's frame follows from the beam (the beam runs along the fork's -Y, the emitter
        sits at a fixed offset in the fork); the wrist centre is then reached by the two-link
        arm in closed form, elbow bent to the right (negative elbow angle); the wrist turns the
        fork to its heading and the lift sets the height. ValueError if out of reach or beyond
        a joint's limits."""
        (bx, by, bz), yaw = base
        to_base = _rotation_z(-yaw)
        d = to_base @ np.asarray(direction, dtype=float)
        if abs(d[2]) > 1e-9:
            raise ValueError("the robot's beam is horizontal; the given direction is not")
        d /= np.linalg.norm(d)
        e = to_base @ (np.asarray(emitter, dtype=float) - np.array([bx, by, bz]))
        heading = math.degrees(math.atan2(d[0], -d[1]))  # fork +X: the beam turned +90 deg
        rest = {name: 0.0 for name in self.joint_names}
        rest_fork_r, rest_fork_t = self.frame_placement(rest, FORK)
        _, rest_emitter = self.frame_placement(rest, EMITTER)
        offset = rest_fork_r.T @ (rest_emitter - rest_fork_t)  # emitter in the fork's frame
        wrist = e - _rotation_z(heading) @ offset  # the fork's origin: the wrist axis
        _, shoulder_at = self.frame_placement(rest, "upper_arm")
        _, elbow_at = self.frame_placement(rest, "forearm")
        l1 = float(np.hypot(*(elbow_at - shoulder_at)[:2]))
        l2 = float(np.hypot(*(rest_fork_t - elbow_at)[:2]))
        wx, wy = wrist[0] - shoulder_at[0], wrist[1] - shoulder_at[1]
        reach = math.hypot(wx, wy)
        cosine = (reach * reach - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
        if not -1.0 <= cosine <= 1.0:
            raise ValueError(f"the wrist would have to be {reach:.1f} mm from the shoulder; the "
                             f"arm reaches {abs(l1 - l2):.1f} to {l1 + l2:.1f} mm")
        elbow = -math.acos(cosine)
        shoulder = math.atan2(wy, wx) - math.atan2(l2 * math.sin(elbow), l1 + l2 * math.cos(elbow))
        wrist_angle = heading - math.degrees(shoulder) - math.degrees(elbow)
        wrist_angle = (wrist_angle + 180.0) % 360.0 - 180.0
        joints = {"shoulder": math.degrees(shoulder), "elbow": math.degrees(elbow),
                  "wrist": wrist_angle, self.lift_joint: 0.0}
        joints[self.lift_joint] = float(e[2] - self.beam(joints)[0][2])
        for name, value in joints.items():
            low, high = self.limits[name]
            if not low - 1e-9 <= value <= high + 1e-9:
                raise ValueError(f"the {name} joint would be at {value:.3f}, beyond its limits "
                                 f"{low:.3f} to {high:.3f}")
        return joints

    # --- slow scanning's arm motions (SPEC §13) ----------------------------------------------

    def fork_heading(self, joints, base=((0.0, 0.0, 0.0), 0.0)):
        """The fork's heading in the world: its +X axis (the way its tines point), a unit
        vector; horizontal for this robot, whose joints all turn about Z."""
        rotation, _ = self._world(base, *self.frame_placement(joints, FORK))
        return tuple(float(v) for v in rotation[:, 0])

    def wrist_axis(self, joints, base=((0.0, 0.0, 0.0), 0.0)):
        """(x, y) mm in the world of the wrist joint's (vertical) axis: the fork's origin."""
        _, origin = self._world(base, *self.frame_placement(joints, FORK))
        return float(origin[0]), float(origin[1])

    def straight_advance(self, joints, base, advance):
        """Joint values that move the fork ``advance`` mm along its heading in a straight line,
        its heading, height and elbow branch kept: the inverse kinematics of the jab. The beam's
        emitter is moved and the pose solved again (teach_start_pose's closed form); ValueError
        when out of reach or beyond a joint's limits."""
        emitter, direction, _ = self.beam(joints, base)
        heading = self.fork_heading(joints, base)
        target = tuple(e + advance * h for e, h in zip(emitter, heading))
        return self.teach_start_pose(base, target, direction)  # the lift: the same height
