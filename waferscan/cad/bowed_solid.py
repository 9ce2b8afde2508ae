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
the solid's cylindrical rim and checks the solid's bow against the property (disc.py). Flat wafers stay
Part::Cylinders.
"""

from __future__ import annotations

import FreeCAD as App
import Part

from . import features


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

