"""A wafer's centre, normal, diameter and thickness read off its solid: a Part::Cylinder, a
PartDesign body, an imported STEP solid. Anything that is not a solid disc is refused; a bowed
wafer's solid of revolution (SPEC §10, cad/bowed_solid.py) is read with its bow given."""

from __future__ import annotations

import math

import Part

from ..core.errors import ShapeError

ANGLE_TOLERANCE = 1e-9  # on unit vectors: sines and cosines
VOLUME_TOLERANCE = 1e-6  # relative
BOW_TOLERANCE = 1e-6  # mm: a solid's bow (twice its centre of mass's lift) against the property


class NotADisc(ShapeError):
    """The shape is not a solid disc; the message says why."""


def _unit(v):
    n = v.Length
    return v * (1.0 / n)


def disc_of(shape):
    """(center, normal, diameter, thickness) of a solid disc, in the shape's placed coordinates.
    ``center`` is the centre of the bottom face and ``normal`` points through the thickness,
    upwards (positive Z) when the disc is not standing on edge."""
    solid, (axis, radius, origin, positions) = _rim_and_flats(shape)
    reading = _disc_from(axis, radius, origin, positions)
    thickness = reading[3]
    if thickness <= 0.0:
        raise NotADisc("its two flat faces coincide")
    expected = math.pi * radius * radius * thickness
    if abs(solid.Volume - expected) > VOLUME_TOLERANCE * expected:
        raise NotADisc(f"its volume {solid.Volume:.6g} mm^3 is not that of a full disc of "
                       f"diameter {2 * radius:.6g} mm and thickness {thickness:.6g} mm "
                       f"({expected:.6g} mm^3)")
    return reading


def whole_disc_of(shape):
    """``disc_of`` of a solid known to be a whole disc, a Part::Cylinder's or a flat wafer's
    of positive radius and height: the same floats, without the volume integration that is
    most of ``disc_of``'s time (0.5 ms a wafer)."""
    return _disc_from(*_rim_and_flats(shape)[1])


def _rim_and_flats(shape):
    """(solid, (unit axis, radius, origin of the rim, positions of the two flat faces)) of a
    shape made of one solid with a cylindrical rim and two flat faces square to it."""
    solids = shape.Solids
    if len(solids) != 1:
        raise NotADisc(f"expected one solid, found {len(solids)}")
    solid = solids[0]
    cylinders, planes = [], []
    for face in solid.Faces:
        surface = face.Surface
        if isinstance(surface, Part.Cylinder):
            cylinders.append(surface)
        elif isinstance(surface, Part.Plane):
            planes.append(surface)
        else:
            raise NotADisc(f"has a {type(surface).__name__} face; a disc has only a "
                           "cylindrical rim and two flat faces")
    if not cylinders:
        raise NotADisc("has no cylindrical rim")
    axis = _unit(cylinders[0].Axis)
    radius = cylinders[0].Radius
    origin = cylinders[0].Center
    for other in cylinders[1:]:  # a rim split at its seam is still one rim
        offset = other.Center - origin
        if (abs(abs(_unit(other.Axis).dot(axis)) - 1.0) > ANGLE_TOLERANCE
                or abs(other.Radius - radius) > 1e-9 * max(1.0, radius)
                or (offset - axis * offset.dot(axis)).Length > 1e-7):
            raise NotADisc("has cylindrical faces about different axes or of different radii")
    if len(planes) != 2:
        raise NotADisc(f"has {len(planes)} flat faces; a disc has two")
    for plane in planes:
        if abs(abs(_unit(plane.Axis).dot(axis)) - 1.0) > ANGLE_TOLERANCE:
            raise NotADisc("a flat face is not square to the rim's axis")
    return solid, (axis, radius, origin, [plane.Position for plane in planes])


def _disc_from(axis, radius, origin, positions):
    """(center, normal, diameter, thickness) from a disc's rim (unit ``axis``, ``radius``, the
    rim surface's ``origin``) and its flat faces' ``positions``: one arithmetic for the B-rep
    read and the cylinder read, so that both give the same floats."""
    heights = [(position - origin).dot(axis) for position in positions]
    low, high = min(heights), max(heights)
    thickness = high - low
    if axis.z < 0.0 or (axis.z == 0.0 and (axis.y < 0.0 or (axis.y == 0.0 and axis.x < 0.0))):
        axis = -axis
        low, high = -high, -low
    center = origin + axis * low
    return ((center.x, center.y, center.z), (axis.x, axis.y, axis.z), 2.0 * radius, thickness)


_CYLINDERS = {}  # (radius, height) -> Part.makeCylinder(radius, height), the unplaced solid
_MAX_CYLINDERS = 256  # distinct wafer sizes kept; a document rarely has more than a few


def cylinder_disc(radius, height, placement, frame=None):
    """(center, normal, diameter, thickness) of the disc that a cylinder of ``radius`` and
    ``height`` (a Part::Cylinder's, a flat WaferScan wafer's) placed by ``placement`` (its own,
    an App.Matrix) in a container placed by ``frame`` (an App.Matrix, None at the top) makes:
    the floats ``disc_of`` reads off the B-rep a recompute gives it, without that B-rep. The
    same unplaced solid is located as ``Part.getShape`` locates the object's (its own
    placement, then its container's, OpenCASCADE composing the two): computed from the
    placements in Python, a tilted wafer in a carrier's assembly read 1 to 4 units in the last
    place off (OpenCASCADE orthogonalises each matrix and composes the two transforms before
    it moves the surfaces)."""
    key = (radius, height)
    unplaced = _CYLINDERS.get(key)
    if unplaced is None:
        if len(_CYLINDERS) >= _MAX_CYLINDERS:
            _CYLINDERS.clear()
        unplaced = _CYLINDERS[key] = Part.makeCylinder(radius, height)
    shape = unplaced.transformed(placement)
    if frame is not None:
        shape.transformShape(frame)
    return whole_disc_of(shape)


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
