"""The robot's collision geometry reduced once, for a sweep's ``[clearance]`` report (SPEC §12,
§15), to the numbers core/sweep/clearance.py computes with over arrays: over a fast scan's
strokes each collision part becomes a vertical prism (a ``PrismPart``).

The parts are placed as ``clearance.RobotBody`` places them (the URDF's <collision> elements,
the start pose taught from the layout's beam, the lift moving the beam from each stroke's start
to its end). A part must keep one axis vertical (a box turned about Z, a vertical cylinder;
a sphere is any way up) and the lift must be vertical: the bundled robot's joints all turn
about Z. Anything else is a ValueError (the exact per-layout check, ``clearance_for``, still
applies to single layouts).
"""

from __future__ import annotations

import math

import coal
import numpy as np

from ..core.sweep.clearance import PrismPart, StrokeBody, stroke_motions
from .clearance import RobotBody

VERTICAL = 1e-9  # how far from vertical (|sin|) an axis may be to count as vertical


def stroke_body(layout, body=None):
    """The StrokeBody of the layout's robot over its fast scan's strokes (``body``: a
    RobotBody of the layout, made here by default). A beam_tilt drawn by a sweep turns the
    sensor's beam, not the robot: the pose is the INPUT beam's."""
    body = body or RobotBody(layout)
    motions = stroke_motions(layout)
    if abs(body.lift_axis[2]) < 1.0 - VERTICAL:
        raise ValueError("[clearance]: the robot's lift is not vertical; its strokes do not "
                         "sweep vertical prisms")
    placed = [body.parts_at(m, s) for m in motions for s in (m.start, m.end)]
    parts = []
    for i, (name, shape, _, _, _) in enumerate(placed[0]):
        poses = [p[i] for p in placed]
        rotation, translation = poses[0][2], poses[0][3]
        if any(np.abs(p[2] - rotation).max() > 1e-9 or
               np.abs(p[3][:2] - translation[:2]).max() > 1e-9 for p in poses):
            raise ValueError(f"[clearance]: the robot's {name} does not move straight up and "
                             "down in the stroke")
        z = [float(p[3][2]) for p in poses]
        parts.append(_prism(name, shape, rotation, translation, min(z), max(z)))
    return StrokeBody("robot", tuple(m.phase for m in motions), tuple(parts))


def _prism(name, shape, rotation, translation, z_low, z_high):
    """The PrismPart of a coal shape centred at ``translation`` (mm) turned by ``rotation``,
    its centre moving from z_low to z_high."""
    centre = (float(translation[0]), float(translation[1]))
    if isinstance(shape, coal.Sphere):
        r = float(shape.radius)
        return PrismPart(name, centre, (1.0, 0.0), (0.0, 0.0), r, True, (z_low, z_high))
    if isinstance(shape, coal.Box):
        hx, hy, hz = (float(v) for v in shape.halfSide)
        # The box's local axis that is vertical becomes its height; the other two its plan.
        vertical = int(np.argmax(np.abs(rotation[2, :])))
        if abs(abs(rotation[2, vertical]) - 1.0) > VERTICAL:
            raise ValueError(f"[clearance]: the robot's {name} is a box not turned about Z")
        halves = (hx, hy, hz)
        sides = [k for k in range(3) if k != vertical]
        axis = rotation[:2, sides[0]]
        norm = math.hypot(*axis)
        return PrismPart(name, centre, (float(axis[0] / norm), float(axis[1] / norm)),
                         (halves[sides[0]], halves[sides[1]]), 0.0, False,
                         (z_low - halves[vertical], z_high + halves[vertical]))
    if isinstance(shape, coal.Cylinder):
        if abs(abs(rotation[2, 2]) - 1.0) > VERTICAL:
            raise ValueError(f"[clearance]: the robot's {name} is a cylinder whose axis is not "
                             "vertical")
        half = float(shape.halfLength)
        return PrismPart(name, centre, (1.0, 0.0), (0.0, 0.0), float(shape.radius), False,
                         (z_low - half, z_high + half))
    raise ValueError(f"[clearance]: the robot's {name} is not a box, a cylinder or a sphere")

