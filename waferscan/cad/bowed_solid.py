"""A bowed wafer as an OpenCASCADE solid of revolution (SPEC §10), for B-rep cross-checks of
the closed forms in core/bow.py.

In the wafer's frame (origin the centre of the rim's bottom circle, Z its normal) the bottom
surface is z = bow (1 - r²/R²): a quadratic Bezier with poles (0, bow), (R/2, bow), (R, 0)
traces exactly that parabola (r = R s, z = bow (1 - s²)). The profile (bottom parabola, rim,
top parabola t higher, axis) is revolved about Z.
"""

from __future__ import annotations

import FreeCAD as App
import Part


def bowed_wafer_solid(wafer):
    """The wafer's solid, placed in the base frame."""
    radius, bow, t = wafer.radius, wafer.bow, wafer.thickness

    def parabola(lift):
        curve = Part.BezierCurve()
        curve.setPoles([App.Vector(0, 0, bow + lift), App.Vector(radius / 2, 0, bow + lift),
                        App.Vector(radius, 0, lift)])
        return curve.toShape()

    bottom, top = parabola(0.0), parabola(t)
    rim = Part.LineSegment(App.Vector(radius, 0, 0), App.Vector(radius, 0, t)).toShape()
    axis = Part.LineSegment(App.Vector(0, 0, bow + t), App.Vector(0, 0, bow)).toShape()
    face = Part.Face(Part.Wire([bottom, rim, top.reversed(), axis]))
    solid = face.revolve(App.Vector(0, 0, 0), App.Vector(0, 0, 1), 360)
    solid = Part.Solid(Part.Shell(solid.Faces)) if solid.ShapeType != "Solid" else solid
    placement = App.Placement(App.Vector(*wafer.center),
                              App.Rotation(App.Vector(0, 0, 1), App.Vector(*wafer.normal)))
    solid.Placement = placement
    return solid


def bowed_blocked(solid, emitter, beam):
    """Whether the beam segment meets the bowed solid: the length of their common part, since
    OpenCASCADE's distToShape misses a segment that dips into a surface of revolution and out
    again (its extrema there); a segment wholly inside counts by its emitter."""
    end = tuple(o + beam.length * d for o, d in zip(emitter, beam.direction))
    if solid.isInside(App.Vector(*emitter), 0.0, True):
        return True
    edge = Part.LineSegment(App.Vector(*emitter), App.Vector(*end)).toShape()
    return solid.common(edge).Length > 0.0
