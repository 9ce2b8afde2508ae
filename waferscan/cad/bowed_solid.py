"""A bowed wafer as an OpenCASCADE solid of revolution (SPEC §10), for B-rep cross-checks of
the closed forms in core/bow.py, and as the document object that draws a bowed wafer bowed.

In the wafer's frame (origin the centre of the rim's bottom circle, Z its normal) the bottom
surface is z = bow (1 - r²/R²): a quadratic Bezier with poles (0, bow), (R/2, bow), (R, 0)
traces exactly that parabola (r = R s, z = bow (1 - s²)). The profile (bottom parabola, rim,
top parabola t higher, axis) is revolved about Z.

The document object (``BowedWafer``, a Part::FeaturePython) has a Part::Cylinder's Radius,
Height and Placement and the wafer's ``Bow``; its shape is this solid, so the 3D view shows the
bow. The reader gets the same wafer from it as from a flat cylinder carrying ``Bow`` (documents
made before this object): ``bowed_disc_of`` reads the centre, normal, diameter and thickness off
the solid's cylindrical rim and checks the solid's bow against the property. Flat wafers stay
Part::Cylinders.
"""

from __future__ import annotations

import math

import FreeCAD as App
import Part

from . import features
from .disc import VOLUME_TOLERANCE, NotADisc

BOW_TOLERANCE = 1e-6  # mm: a solid's bow (twice its centre of mass's lift) against the property


def bowed_wafer_solid(wafer):
    """The wafer's solid, placed in the base frame."""
    solid = bowed_local_solid(wafer.radius, wafer.thickness, wafer.bow)
    placement = App.Placement(App.Vector(*wafer.center),
                              App.Rotation(App.Vector(0, 0, 1), App.Vector(*wafer.normal)))
    solid.Placement = placement
    return solid


def bowed_local_solid(radius, t, bow):
    """The bowed wafer's solid in its own frame (origin the centre of the rim's bottom circle,
    Z its normal), ``radius``, thickness ``t`` and ``bow`` in mm."""

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
    return Part.Solid(Part.Shell(solid.Faces)) if solid.ShapeType != "Solid" else solid


def bowed_blocked(solid, emitter, beam):
    """Whether the beam segment meets the bowed solid: the length of their common part, since
    OpenCASCADE's distToShape misses a segment that dips into a surface of revolution and out
    again (its extrema there); a segment wholly inside counts by its emitter."""
    end = tuple(o + beam.length * d for o, d in zip(emitter, beam.direction))
    if solid.isInside(App.Vector(*emitter), 0.0, True):
        return True
    edge = Part.LineSegment(App.Vector(*emitter), App.Vector(*end)).toShape()
    return solid.common(edge).Length > 0.0


class BowedWafer(features._Proxy):
    """A wafer drawn as it is: the bowed solid of its Radius, Height and Bow (a flat disc when
    Bow is 0), placed by its Placement as a Part::Cylinder is (origin at the rim's bottom
    centre, Z the normal)."""

    def execute(self, obj):
        radius, t = float(obj.Radius), float(obj.Height)
        bow = float(obj.Bow) if "Bow" in obj.PropertiesList else 0.0
        obj.Shape = bowed_local_solid(radius, t, bow) if bow else Part.makeCylinder(radius, t)


def make_bowed_wafer(doc, label, radius, thickness):
    """A BowedWafer object labelled ``label``; the caller adds its Bow and role."""
    obj = features.add_named(doc, "Part::FeaturePython", label)
    for name, value, tip in (("Radius", radius, "Radius of the wafer's rim"),
                             ("Height", thickness, "Thickness of the wafer along its normal")):
        obj.addProperty("App::PropertyLength", name, "Wafer", tip)
        setattr(obj, name, value)
    BowedWafer(obj)
    return obj


def bowed_disc_of(shape, bow):
    """(center, normal, diameter, thickness) of a bowed wafer's solid whose bow is ``bow`` (mm),
    as ``disc.disc_of`` gives them for a flat disc: ``center`` the centre of the rim's bottom
    circle, ``normal`` the way the centre bows for a positive ``bow``. NotADisc when the shape is
    not such a solid or its bow is not ``bow`` (the property changed, not recomputed)."""
    solids = shape.Solids
    if len(solids) != 1:
        raise NotADisc(f"expected one solid, found {len(solids)}")
    solid = solids[0]
    rims = [f for f in solid.Faces if isinstance(f.Surface, Part.Cylinder)]
    if not rims:
        raise NotADisc("has no cylindrical rim")
    surface = rims[0].Surface
    axis, origin, radius = surface.Axis, surface.Center, surface.Radius
    axis = axis * (1.0 / axis.Length)
    heights = [(v.Point - origin).dot(axis) for face in rims for v in face.Vertexes]
    low, high = min(heights), max(heights)
    thickness = high - low
    expected = math.pi * radius * radius * thickness  # the paraboloid shift keeps the volume
    if thickness <= 0.0 or abs(solid.Volume - expected) > VOLUME_TOLERANCE * expected:
        raise NotADisc(f"its volume {solid.Volume:.6g} mm^3 is not that of a bowed disc of "
                       f"diameter {2 * radius:.6g} mm and thickness {thickness:.6g} mm")
    # The centre of mass lies bow/2 (the mean of bow (1 - r²/R²) over the disc) above the rim's
    # middle along the normal: its side gives the normal's sense, its size checks the bow.
    lift = (solid.CenterOfMass - origin).dot(axis) - 0.5 * (low + high)
    if lift * bow < 0.0:
        axis, low = -axis, -high
    if abs(2.0 * abs(lift) - abs(bow)) > BOW_TOLERANCE:
        raise NotADisc(f"its shape is bowed by {2.0 * abs(lift):.6g} mm, not by its Bow "
                       f"property's {bow:.6g} mm (recompute the document)")
    center = origin + axis * low
    return ((center.x, center.y, center.z), (axis.x, axis.y, axis.z), 2.0 * radius, thickness)
