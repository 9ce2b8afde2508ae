"""A bowed wafer as an OpenCASCADE solid of revolution (SPEC §10), for B-rep cross-checks of
the closed forms in core/geometry/bow.py, and as the document object that draws a bowed wafer bowed.

In the wafer's frame (origin the centre of the rim's bottom circle, Z its normal) the bottom
surface is z = bow (1 - r²/R²): a quadratic Bezier with poles (0, bow), (R/2, bow), (R, 0)
traces exactly that parabola (r = R s, z = bow (1 - s²)). The profile (bottom parabola, rim,
top parabola t higher, axis) is revolved about Z. Whether a beam meets it (``bowed_blocked``)
is found on these faces' own surfaces, exactly (to ~1e-12 mm), rim included: not with
OpenCASCADE's Boolean common, classifier or sampled curve-surface intersection, which lose or
misplace a beam that grazes the rim or dips into a paraboloid over a short stretch.

The document object (``BowedWafer``, a Part::FeaturePython) has a Part::Cylinder's Radius,
Height and Placement and the wafer's ``Bow``; its shape is this solid, so the 3D view shows the
bow. The reader gets the same wafer from it as from a flat cylinder carrying ``Bow`` (documents
made before this object): ``bowed_disc_of`` reads the centre, normal, diameter and thickness off
the solid's cylindrical rim and checks the solid's bow against the property (disc.py). Flat
wafers are ``features.Wafer`` objects, with the same Radius, Height and Placement.
"""

from __future__ import annotations

import math

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


# How far (mm) beyond the segment's ends a crossing still touches it: OpenCASCADE's confusion.
_TOUCH = Part.Precision.confusion()
# How far a surface parameter may lie outside its face's range and still be on the face: the
# rim cylinder's height (mm) or the paraboloids' Bezier parameter (0 to 1 over R mm).
_PARAMETER_SLACK = 1e-12
# How far (mm) a crossing may lie from the point of the face its parameters give: the
# intersection's own precision on these surfaces (~1e-12 mm), with room.
_ON_FACE = 1e-9


def bowed_blocked(solid, emitter, beam):
    """Whether the beam segment meets the bowed solid (``bowed_wafer_solid``): it crosses one
    of the solid's faces between its ends, or it lies wholly inside (its emitter inside).

    The crossings are found on each face's own surface, as OpenCASCADE holds it: the rim
    cylinder's by OpenCASCADE's curve-surface intersection (GeomAPI_IntCS, in closed form for
    a cylinder), the two paraboloids' by ``_revolution_crossings`` from their surfaces of
    revolution's axes and Bezier profiles. OpenCASCADE's own tools do not serve for these:
    the Boolean common of the segment with the solid and the solid classifier (``isInside``)
    lose a beam that crosses the wafer within ~0.3 mm of its rim and put edges up to ~4e-3
    mm off, and GeomAPI_IntCS samples a surface of revolution, missing a line that dips into
    it over a short stretch (0.3 mm off on a steeply tilted wafer)."""
    direction = _unit(beam.direction)
    if any(-_TOUCH <= s <= beam.length + _TOUCH
           for s in _crossings(solid, emitter, direction)):
        return True
    return _inside(solid, emitter)


def _unit(vector):
    x, y, z = vector
    norm = (x * x + y * y + z * z) ** 0.5
    return (x / norm, y / norm, z / norm)


def _crossings(solid, origin, direction):
    """The distances (mm, signed, along the unit ``direction`` from ``origin``) at which the
    line through them meets the solid's faces. Each face of ``bowed_local_solid`` is a whole
    turn of one profile edge, so its domain is its rectangle of surface parameters: a point the
    intersection finds on the surface is on the face when its parameters are in range. A line
    lying in a face's surface (a ruling of the rim cylinder, along which its height parameter
    changes linearly) meets the face where that parameter reaches the face's ends."""
    o = App.Vector(*origin)
    d = App.Vector(*direction)
    line = Part.Line(o, o + d)
    found = []
    for face in solid.Faces:
        surface = face.Surface
        u0, u1, v0, v1 = face.ParameterRange
        if isinstance(surface, Part.SurfaceOfRevolution):
            found += _revolution_crossings(surface, v0, v1, o, d)
            continue
        points, segments = line.intersectCS(surface)
        if segments:
            start, rate = surface.parameter(o)[1], surface.parameter(o + d)[1]
            rate -= start
            if rate != 0.0:
                found += [(v - start) / rate for v in (v0, v1)]
        for at in (App.Vector(p.X, p.Y, p.Z) for p in points):
            # A point the intersection finds a little beyond a bounded surface's end projects
            # onto that end: on the face only if its parameters are in range and it is there.
            u, v = surface.parameter(at)
            if v0 - _PARAMETER_SLACK <= v <= v1 + _PARAMETER_SLACK and \
                    (surface.value(u, v) - at).Length <= _ON_FACE:
                found.append((at - o).dot(d))
    return found


def _revolution_crossings(surface, v0, v1, o, d):
    """The distances along the unit ``d`` from ``o`` at which that line meets a surface of
    revolution whose profile is a polynomial (non-rational Bezier) curve, within its profile
    parameters [v0, v1]. In the axis's frame a line point at s has height zp + s zq and squared
    distance A s² + B s + C from the axis; a profile point at v has height z(v) and distance
    ρ(v), both polynomials in v. Eliminating s (s = (z(v) − zp) / zq) leaves one polynomial in
    v (for a line across the axis, zq = 0: z(v) = zp, then s from the quadratic); its real roots
    are refined by Newton's method on the two equations in (s, v) and kept where the line
    point lies on the surface."""
    import numpy as np
    from numpy.polynomial import polynomial as poly

    curve = surface.BasisCurve
    if not isinstance(curve, Part.BezierCurve) or curve.isRational():
        raise ValueError("a bowed wafer's faces are turns of polynomial Bezier profiles")
    axis = surface.Direction
    axis = axis * (1.0 / axis.Length)
    centre = surface.Location
    offsets = [pole - centre for pole in curve.getPoles()]
    across = [w - axis * w.dot(axis) for w in offsets]
    radial = max(across, key=lambda w: w.Length)
    radial = radial * (1.0 / radial.Length)
    k = len(offsets) - 1
    bernstein = [math.comb(k, i) * poly.polymul(poly.polypow([0.0, 1.0], i),
                                                  poly.polypow([1.0, -1.0], k - i))
                 for i in range(k + 1)]
    rho = sum(b * w.dot(radial) for b, w in zip(bernstein, offsets))
    height = sum(b * w.dot(axis) for b, w in zip(bernstein, offsets))
    p = o - centre
    zp, zq = p.dot(axis), d.dot(axis)
    p_across, q_across = p - axis * zp, d - axis * zq
    a, b, c = q_across.dot(q_across), 2.0 * p_across.dot(q_across), p_across.dot(p_across)
    shifted = poly.polysub(height, [zp])
    if abs(zq) > 1e-9:
        # zq² (A s² + B s + C − ρ²) with zq s = z(v) − zp
        equation = poly.polyadd(poly.polyadd(a * poly.polymul(shifted, shifted),
                                             b * zq * shifted),
                                poly.polysub([c * zq * zq], zq * zq * poly.polymul(rho, rho)))
    else:
        equation = shifted
    equation = np.trim_zeros(np.asarray(equation, dtype=float), "b")
    scale = np.max(np.abs(equation)) if len(equation) else 0.0
    if scale == 0.0:
        return []
    while abs(equation[-1]) <= 1e-14 * scale:  # a degree lost to rounding
        equation = equation[:-1]
    if len(equation) < 2:
        return []
    pairs = []
    for root in poly.polyroots(equation):
        if abs(root.imag) > 1e-6:
            continue
        v = root.real
        if abs(zq) > 1e-9:
            pairs.append(((poly.polyval(v, height) - zp) / zq, v))
        else:
            r2 = poly.polyval(v, rho) ** 2
            disc = b * b - 4.0 * a * (c - r2)
            if disc >= -1e-12 * max(1.0, b * b):
                root_disc = math.sqrt(max(0.0, disc))
                pairs += [((-b - root_disc) / (2.0 * a), v), ((-b + root_disc) / (2.0 * a), v)]
    d_rho, d_height = poly.polyder(rho), poly.polyder(height)
    found = []
    for s, v in pairs:
        for _ in range(8):  # Newton on F1 = zp + s zq − z(v), F2 = A s² + B s + C − ρ(v)²
            r_v = poly.polyval(v, rho)
            f1 = zp + s * zq - poly.polyval(v, height)
            f2 = (a * s + b) * s + c - r_v * r_v
            j11, j12 = zq, -poly.polyval(v, d_height)
            j21, j22 = 2.0 * a * s + b, -2.0 * r_v * poly.polyval(v, d_rho)
            det = j11 * j22 - j12 * j21
            if det == 0.0:
                break
            ds = (-f1 * j22 + f2 * j12) / det
            dv = (-f2 * j11 + f1 * j21) / det
            s, v = s + ds, v + dv
            if abs(ds) < 1e-15 * (1.0 + abs(s)) and abs(dv) < 1e-15:
                break
        if not v0 - _PARAMETER_SLACK <= v <= v1 + _PARAMETER_SLACK:
            continue
        r_v = poly.polyval(v, rho)
        if r_v < -_ON_FACE:
            continue  # the profile's mirror image through the axis, not the surface
        line_r = math.sqrt(max(0.0, (a * s + b) * s + c))
        if math.hypot(zp + s * zq - poly.polyval(v, height), line_r - r_v) <= _ON_FACE:
            found.append(float(s))
    return found


def _inside(solid, point):
    """Whether ``point`` lies inside the bowed solid: a ray from it crosses the solid's faces
    an odd number of times. The ray runs along the wafer's axis (it crosses one of the two
    paraboloids from inside, both or none from outside; never the rim cylinder, which is
    parallel to it), or across the wafer for a point within 1 mm of the axis, whose ray would
    pass through the paraboloids' poles."""
    placement = solid.Placement
    local = placement.inverse().multVec(App.Vector(*point))
    ray = App.Vector(0, 0, 1) if local.x ** 2 + local.y ** 2 >= 1.0 else App.Vector(1, 0, 0)
    ray = placement.Rotation.multVec(ray)
    ahead = [s for s in _crossings(solid, point, (ray.x, ray.y, ray.z)) if s > 0.0]
    return len(ahead) % 2 == 1


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
    return features.make_wafer(doc, label, radius, thickness, BowedWafer)
