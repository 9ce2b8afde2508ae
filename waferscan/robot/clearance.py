"""The distances of SPEC §15's clearance check, with coal (the collision library that ships with
pin): the robot's collision geometry from its URDF (Pinocchio's COLLISION geometry model, placed
by the joints) or, without a robot, the scanner's heads; the wafers (and, when given, the
carrier's solids) as coal solids.

Lengths here are millimetres: the URDF's shapes and placements are scaled once, when the body is
made. The motions and the search along them are ``core/scan/clearance.py``'s; this module only
answers its questions (``nearest``, ``path``, ``swept``), so ``waferscan/core`` stays numpy-only.

- A flat wafer is a coal ``Cylinder``. A bowed wafer (core/geometry/bow.py) is the convex hull of
  its rim circles and its two surfaces sampled on rings, each ring's polygon circumscribing its
  circle and each surface point raised outwards by the sampling's sagitta, so the hull holds the
  solid: a distance to it is never more than the true one (conservative, by at most ~0.05 mm for
  a 300 mm wafer). The hull is that of a dome or a bowl: from its open side (above a
  bowl, below a dome) it reaches up to the bow nearer than the solid.
- A translation along the lift (a fast stroke, a pocket's Z steps) is answered exactly in one
  piece (``swept``): a box, cylinder or sphere that moves along its own Z axis sweeps a longer
  box, cylinder or a capsule, and the least distance to it is the least along the motion. When
  the swept shapes overlap a wafer the core's Lipschitz search answers instead, so that a
  contact's distance is the signed distance at one position.
- The jab and the sweep turn links: ``path`` bounds how far any point moves (the sweep: the
  wrist's turn times the fork's reach, exact; the jab: each arm joint's change times the reach
  from its axis, taken at the jab's ends plus twice its length, joint values taken to move
  monotonically between the search's samples), and the core's Lipschitz refinement does the
  rest.
- The carrier's solids (``carrier=``: closed triangle meshes in the world, plain arrays
  ``(vertices, triangles, name)``, which the CAD layer tessellates from the document) are
  obstacles too (``carrier_obstacle``): a coal ``Box`` where the mesh is a box (a built carrier's
  walls and ledges: exact), a ``Convex`` where it is convex, else a ``BVHModelOBBRSS`` with an
  inside test (a BVH is only a surface: a part wholly inside it would read as apart). A swept
  translation stays exact against any of them: the distance from a moving part's swept shape to
  a fixed solid is the least along the motion, whatever the solid's shape.
"""

from __future__ import annotations

import math
import os
import struct
import xml.etree.ElementTree as ElementTree

import numpy as np

from ..addon import require_pinocchio

require_pinocchio()  # coal ships with pin: the same clear error when it is missing
import coal  # noqa: E402
import pinocchio as pin  # noqa: E402

from ..core.scan import clearance as core  # noqa: E402
from ..core.scan import slow_scan  # noqa: E402
from .kinematics import FORK, MM, WaferRobot, bundled_urdf  # noqa: E402

HEAD_RADIUS = 3.0  # mm: the scanner's emitter and receiver heads (cad/features.ScannerBeam)
BOW_RINGS = 24  # rings of a bowed wafer's surfaces
BOW_SIDES = 128  # points on each ring (coal's hull allows a vertex at most 255 neighbours)


# _nearest: with more obstacles than NEAR_BAND_FROM, those within NEAR_BAND mm of the parts
# along Z are weighed first (the answer when one is nearer than that).
NEAR_BAND_FROM = 200
NEAR_BAND = 100.0
# _nearest_among: how far beyond the least distance found a pair's boxes must lie apart to be
# passed over unmeasured (far more than coal's error and the boxes' rounding, ~1e-12 mm).
APART_SLACK = 0.01


def _frame_z(axis):
    """A rotation whose third column is the unit ``axis`` (scalar arithmetic: numpy's cross
    costs more than the rest of a wafer's set-up)."""
    ax, ay, az = (float(v) for v in axis)
    n = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / n, ay / n, az / n
    if abs(ax) < 0.9:  # x = (1, 0, 0) x z
        x = (0.0, -az, ay)
    else:  # x = (0, 1, 0) x z
        x = (az, 0.0, -ax)
    m = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
    x = (x[0] / m, x[1] / m, x[2] / m)
    y = (ay * x[2] - az * x[1], az * x[0] - ax * x[2], ax * x[1] - ay * x[0])
    return np.array([[x[0], y[0], ax], [x[1], y[1], ay], [x[2], y[2], az]])


def _bowed_hull(wafer):
    """coal Convex holding a bowed wafer, in the wafer's frame (origin: the rim's bottom
    centre, Z: its normal); and its bounding radius about that origin."""
    radius, bow, t = wafer.radius, wafer.bow, wafer.thickness
    k = bow / (radius * radius)
    grow = 1.0 / math.cos(math.pi / BOW_SIDES)  # the polygon circumscribes each ring
    dr = radius / BOW_RINGS
    sagitta = abs(k) * dr * dr / 4.0  # a chord between rings lies this far inside the surface
    angles = np.linspace(0.0, 2.0 * math.pi, BOW_SIDES, endpoint=False)
    points = coal.StdVec_Vec3s()
    for i in range(BOW_RINGS + 1):
        r = dr * i
        w = bow * (1.0 - r * r / (radius * radius))
        for z in (w - sagitta, w + t + sagitta):
            # The centre as a small ring (a single point would neighbour every point of the
            # first ring); the sagitta covers the height it misses.
            r_ring = 0.25 * dr if i == 0 else r
            for x, y in zip(r_ring * grow * np.cos(angles), r_ring * grow * np.sin(angles)):
                points.append(np.array([x, y, z]))
    hull = coal.Convex.convexHull(points, False, "")
    bound = math.hypot(radius * grow, abs(bow) + t + sagitta)
    return hull, bound


def _norms(vectors):
    """The Euclidean norms of vectors given component by component along the first axis
    (x, y, z): ``np.linalg.norm``'s own arithmetic (the squares summed by ``add.reduce``, x
    plus y, then plus z, then the root), the same floats, without its checks (the nearest pair
    is looked for at every pose of a search). Components first, the sum is two additions of
    whole arrays: along a short last axis, numpy's reduction took a tenth of a slow scan's
    clearance for the same floats."""
    return np.sqrt(np.add.reduce(vectors * vectors, axis=0))


def _in_gap_order(gaps, bound, apart=None):
    """(index, gap) of the flat ``gaps`` in the order of their stable argsort (equal gaps by
    index, NaN last), for a loop that stops at the first gap no less than ``bound()``, a bound
    that never grows. The least gap first (argmin's first, the sort's first but for a NaN);
    then, sorted the same way, only the gaps below ``bound()`` as read after the first: the
    loop stops at any other, as the bound only falls. So the loop weighs the same pairs as
    with the whole sort, which took ~5 % of a slow scan's clearance to weigh ~6 pairs of ~540.
    With a NaN gap, the whole sort.

    ``apart`` (flat, as ``gaps``): also left out after the first, the pairs the loop passes
    over unmeasured at that bound (``_nearest_among``: boxes more than APART_SLACK apart, by
    at least the bound plus APART_SLACK), the same test in the same floats: as the bound only
    falls, the loop would pass over them wherever they came (or stop at one, and then at the
    next pair, whose gap is no less). The same pairs are measured, without stepping over the
    others one by one."""
    if not len(gaps):
        return
    first = int(gaps.argmin())
    least = float(gaps[first])
    if least != least:  # NaN: argmin's answer wherever a gap is NaN
        below = np.ones(len(gaps), dtype=bool)
    else:
        yield first, least
        limit = bound()
        below = ~(gaps >= limit)  # not <: a NaN bound stops nothing
        if apart is not None:
            below &= ~((apart > APART_SLACK) & (apart - APART_SLACK >= limit))
        below[first] = False
    indices = below.nonzero()[0]
    order = indices[gaps[indices].argsort(kind="stable")]
    yield from zip(order.tolist(), gaps[order].tolist())


def _bound_radius(geometry):
    """Radius of a sphere about the shape's origin that holds it."""
    if isinstance(geometry, coal.Box):
        x, y, z = (float(v) for v in geometry.halfSide)
        return math.sqrt(x * x + y * y + z * z)
    if isinstance(geometry, coal.Cylinder):
        return math.hypot(geometry.radius, geometry.halfLength)
    if isinstance(geometry, coal.Capsule):
        return geometry.radius + geometry.halfLength
    return geometry.radius  # Sphere


def _half_length(geometry):
    if isinstance(geometry, coal.Box):
        return float(geometry.halfSide[2])
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        return geometry.halfLength
    return 0.0


def _swept_along_z(geometry, travel):
    """The shape moved ``travel`` mm along its own Z: a longer box or cylinder, or a capsule."""
    if isinstance(geometry, coal.Box):
        sx, sy, sz = 2.0 * geometry.halfSide
        return coal.Box(sx, sy, sz + travel)
    if isinstance(geometry, coal.Cylinder):
        return coal.Cylinder(geometry.radius, 2.0 * geometry.halfLength + travel)
    if isinstance(geometry, coal.Capsule):
        return coal.Capsule(geometry.radius, 2.0 * geometry.halfLength + travel)
    return coal.Capsule(geometry.radius, travel)  # Sphere


def _box_halves(geometry):
    """(hx, hy, hz, r): the shape lies in the box of half sides (hx, hy, hz) in its own frame
    grown by r (a capsule's and a sphere's radius); None for another shape. What
    ``_nearest_among`` bounds a swept part's distances by (``swept``)."""
    if isinstance(geometry, coal.Box):
        x, y, z = (float(v) for v in geometry.halfSide)
        return x, y, z, 0.0
    if isinstance(geometry, coal.Cylinder):
        return geometry.radius, geometry.radius, geometry.halfLength, 0.0
    if isinstance(geometry, coal.Capsule):
        return 0.0, 0.0, geometry.halfLength, geometry.radius
    if isinstance(geometry, coal.Sphere):
        return 0.0, 0.0, 0.0, geometry.radius
    return None


_SWEPT_MADE = {}  # (id of a shape, travel) -> (the shape, _swept_shape's answer)


def _swept_shape(geometry, travel):
    """(``_swept_along_z(geometry, travel)``, its ``_bound_radius``, its ``_box_halves``),
    made once for the same shape (a robot's own, kept by ``collision_model``) and travel: a
    stroke scanned again sweeps the same shapes as far, and making 7 coal shapes and their
    radii each time was a tenth of a fast scan's ``swept``. The same shape, so the same
    distances."""
    key = (id(geometry), travel)
    made = _SWEPT_MADE.get(key)
    if made is None or made[0] is not geometry:
        if len(_SWEPT_MADE) >= 256:
            _SWEPT_MADE.clear()
        shape = _swept_along_z(geometry, travel)
        made = _SWEPT_MADE[key] = (geometry, (shape, _bound_radius(shape), _box_halves(shape)))
    return made[1]


CONVEX_TEST_TRIANGLES = 4000  # a larger mesh is taken for non-convex (the test is O(V x T))


def _box_of(vertices, triangles, normals):
    """(half sides, rotation, centre) when the closed mesh is a box, else None: its faces' normals
    take three orthogonal directions, its vertices two values along each, and its volume is
    the box's."""
    axes = [normals[0]]
    for n in normals[1:]:
        if all(abs(n @ a) < 1e-9 for a in axes):
            axes.append(n)
            if len(axes) == 2:
                break
    if len(axes) < 2:
        return None
    rotation = np.column_stack([axes[0], axes[1], np.cross(axes[0], axes[1])])
    if np.any(np.max(np.abs(normals @ rotation), axis=1) < 1.0 - 1e-9):
        return None  # a face not square to the three axes
    local = vertices @ rotation
    low, high = local.min(axis=0), local.max(axis=0)
    sides = high - low
    tolerance = 1e-6 * max(1.0, float(sides.max()))
    if np.any(np.minimum(np.abs(local - low), np.abs(local - high)) > tolerance):
        return None
    if abs(abs(_volume(vertices, triangles)) - float(np.prod(sides))) > 1e-6 * float(
            np.prod(sides)) + tolerance ** 3:
        return None  # not closed, or not the whole box
    return 0.5 * sides, rotation, rotation @ (0.5 * (low + high))


def _volume(vertices, triangles):
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0


def _is_convex(vertices, triangles, normals):
    """Whether every vertex lies on or behind every face's plane (normals outward)."""
    if len(triangles) > CONVEX_TEST_TRIANGLES:
        return False
    offsets = np.einsum("ij,ij->i", normals, vertices[triangles[:, 0]])
    size = float(np.ptp(vertices, axis=0).max())
    return bool(np.all(vertices @ normals.T - offsets <= 1e-6 * max(1.0, size)))


class _Inside:
    """Whether a point lies inside a closed triangle mesh (the parity of a ray's crossings)."""

    RAY = np.array([0.5773502691896258, 0.5773502691896257, 0.5773502691896259]) + \
        np.array([1e-3, -2e-3, 0.0])  # skew: along no edge or face of a built solid

    def __init__(self, vertices, triangles):
        self.low, self.high = vertices.min(axis=0), vertices.max(axis=0)
        self.a = vertices[triangles[:, 0]]
        self.e1 = vertices[triangles[:, 1]] - self.a
        self.e2 = vertices[triangles[:, 2]] - self.a

    def __call__(self, point):
        point = np.asarray(point, dtype=float)
        if np.any(point < self.low) or np.any(point > self.high):
            return False
        p = np.cross(self.RAY, self.e2)  # Moller-Trumbore, every triangle at once
        det = np.einsum("ij,ij->i", self.e1, p)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        t = point - self.a
        u = np.einsum("ij,ij->i", t, p) * inv
        q = np.cross(t, self.e1)
        v = (q @ self.RAY) * inv
        w = np.einsum("ij,ij->i", self.e2, q) * inv
        hits = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (w > 0.0)
        return bool(np.count_nonzero(hits) % 2)


def _corners_box(points):
    """(half sides, rotation, centre) when the 8 points are the corners of a box, else None."""
    if len(points) != 8:
        return None
    edges = points[1:] - points[0]
    lengths = np.linalg.norm(edges, axis=1)
    if lengths.min() <= 0.0:
        return None
    # A corner's three edges are the three of its seven lines to the others that are square to
    # each other (its nearest corners are not: a long, thin box's face diagonal is shorter than
    # its long side).
    units = edges / lengths[:, None]
    square = np.abs(units @ units.T) <= 1e-9
    order = next(((i, j, k) for i in range(7) for j in range(i + 1, 7) for k in range(j + 1, 7)
                  if square[i, j] and square[i, k] and square[j, k]), None)
    if order is None:
        return None
    order = list(order)
    axes = units[order]
    rotation = np.column_stack([axes[0], axes[1], np.cross(axes[0], axes[1])])
    local = (points - points[0]) @ rotation
    low, high = local.min(axis=0), local.max(axis=0)
    tolerance = 1e-6 * max(1.0, float(lengths.max()))
    corners = np.abs(local[:, None, :] - np.stack([low, high])[None, :, :]).min(axis=1)
    if np.any(corners > tolerance) or len(
            {tuple(c) for c in np.round((local - low) / (high - low)).tolist()}) != 8:
        return None
    return 0.5 * (high - low), rotation, points[0] + rotation @ (0.5 * (low + high))


def _hull(points):
    hull_points = coal.StdVec_Vec3s()
    for point in points:
        hull_points.append(point)
    return coal.Convex.convexHull(hull_points, False, "")


def carrier_obstacle(vertices, triangles):
    """(coal geometry, rotation, translation, inside) of one solid given as a closed triangle
    mesh in the world (mm): a Box where it is one (exact), a Convex where it is convex, else a
    BVHModelOBBRSS and ``inside(point)``, its inside test (None for the first two: coal's
    distance to a box or a convex is signed already). ``triangles`` None: the solid is the
    convex hull of ``vertices`` (a Box when they are a box's eight corners)."""
    vertices = np.ascontiguousarray(vertices, dtype=float).reshape(-1, 3)
    if triangles is None:
        box = _corners_box(vertices)
        if box is not None:
            half, rotation, centre = box
            return coal.Box(*(2.0 * half)), rotation, centre, None
        return _hull(vertices), np.eye(3), np.zeros(3), None
    triangles = np.ascontiguousarray(triangles, dtype=np.int64).reshape(-1, 3)
    cross = np.cross(vertices[triangles[:, 1]] - vertices[triangles[:, 0]],
                     vertices[triangles[:, 2]] - vertices[triangles[:, 0]])
    lengths = np.linalg.norm(cross, axis=1)
    keep = lengths > 1e-12 * max(1.0, float(lengths.max(initial=0.0)))
    triangles, cross, lengths = triangles[keep], cross[keep], lengths[keep]
    if not len(triangles):
        raise ValueError("a carrier solid without faces")
    if _volume(vertices, triangles) < 0.0:  # faces inwards: turn them out
        triangles, cross = triangles[:, ::-1], -cross
    normals = cross / lengths[:, None]
    box = _box_of(vertices, triangles, normals)
    if box is not None:
        half, rotation, centre = box
        return coal.Box(*(2.0 * half)), rotation, centre, None
    used = vertices[np.unique(triangles)]
    if _is_convex(used, triangles, normals):
        try:
            return _hull(used), np.eye(3), np.zeros(3), None
        except (RuntimeError, ValueError):
            pass  # qhull refused it (e.g. a vertex with too many neighbours): a mesh instead
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(triangles), len(vertices))
    model.addVertices(vertices)
    model.addTriangles(triangles)
    model.endModel()
    return model, np.eye(3), np.zeros(3), _Inside(vertices, triangles)


def _wafer_box(wafer, rotation, centre):
    """The world's axis-aligned box about a wafer (a flat one exactly; a bowed one its bound)."""
    if wafer.bow:
        return None
    n = np.abs(rotation[:, 2])
    reach = wafer.radius * np.sqrt(np.clip(1.0 - n * n, 0.0, 1.0)) + 0.5 * wafer.thickness * n
    return centre - reach, centre + reach


_WAFERS_MADE = []  # [(the scanned carrier, the wafers, their obstacle items)]


def _wafer_items(scanned, wafers):
    """Obstacle items of the ``wafers`` (Wafers; ``scanned``: the scanned carrier, which names
    their slots), made once for the same wafers: a document scanned again (the MCS link's
    commands, the bench's rounds) has the same, and making their coal solids was a third of
    the paper's clearance check. (name, slot, geometry, transform, centre, radius, low, high,
    None)."""
    for carrier, known, items in _WAFERS_MADE:
        if carrier == scanned and (known is wafers or known == wafers):
            return items
    items = []
    for wafer in wafers:
        rotation = _frame_z(wafer.normal)
        if wafer.bow:
            geometry, bound = _bowed_hull(wafer)
            origin = np.asarray(wafer.center, dtype=float)
            centre = origin + rotation[:, 2] * 0.5 * (wafer.bow + wafer.thickness)
        else:
            geometry = coal.Cylinder(wafer.radius, wafer.thickness)
            origin = centre = np.asarray(wafer.mid_center, dtype=float)
            bound = math.hypot(wafer.radius, 0.5 * wafer.thickness)
        low, high = _wafer_box(wafer, rotation, centre) or (centre - bound, centre + bound)
        items.append((wafer.name, _slot_of(scanned, wafer), geometry,
                      coal.Transform3s(rotation, origin), centre, bound, low, high, None))
    items = tuple(items)
    _WAFERS_MADE[:] = [(scanned, wafers, items)] + _WAFERS_MADE[:1]
    return items


_CARRIER_MADE = []  # [(the carrier solids given, their key, their obstacle items)]


def _solids_key(solids):
    """What the carrier's solids are, to compare (each scan of a document reads them again:
    the same solids make the same coal objects once)."""
    return tuple((str(name), np.asarray(vertices, dtype=float).tobytes(),
                  None if triangles is None else np.asarray(triangles, dtype=np.int64).tobytes())
                 for vertices, triangles, name in solids)


def _carrier_items(solids):
    """Obstacle items of the carrier's solids, made once for the same solids (the same object,
    or the same names, vertices and triangles): (name, None, geometry, transform, centre,
    radius, low, high, inside)."""
    for given, _, items in _CARRIER_MADE:
        if given is solids:
            return items
    key = _solids_key(solids)
    for given, known, items in _CARRIER_MADE:
        if known == key:
            return items
    items = []
    for vertices, triangles, name in solids:
        geometry, rotation, translation, inside = carrier_obstacle(vertices, triangles)
        points = np.asarray(vertices, dtype=float).reshape(-1, 3)
        low, high = points.min(axis=0), points.max(axis=0)
        centre = 0.5 * (low + high)
        radius = float(np.linalg.norm(points - centre, axis=1).max())
        items.append((str(name), None, geometry, coal.Transform3s(rotation, translation),
                      centre, radius, low, high, inside))
    _CARRIER_MADE[:] = [(solids, key, items)] + _CARRIER_MADE[:3]
    return items


_BOUNDS_MADE = []  # [(wafer items, carrier items, their arrays)] (``Obstacles._bounds``)


def _bounds_of(wafers, carrier):
    """``Obstacles._bounds``' arrays of the items ``wafers + carrier`` (the tuples or lists
    ``_wafer_items`` and ``_carrier_items`` keep), made once for the same objects."""
    for known_wafers, known_carrier, made in _BOUNDS_MADE:
        if known_wafers is wafers and known_carrier is carrier:
            return made
    items = list(wafers) + list(carrier)
    centres = np.array([item[4] for item in items]).reshape(-1, 3)
    radii = np.array([item[5] for item in items])
    lows = np.array([item[6] for item in items]).reshape(-1, 3)
    highs = np.array([item[7] for item in items]).reshape(-1, 3)
    # For _nearest: the same, components first (``_norms``).
    by_axis = tuple(np.ascontiguousarray(a.T) for a in (centres, lows, highs))
    # For within_z: the boxes by their bottoms, and the tallest box's height.
    by_bottom = np.argsort(lows[:, 2], kind="stable")
    bottoms = lows[by_bottom, 2]
    tallest = float(np.max(highs[:, 2] - lows[:, 2])) if items else 0.0
    for array in (centres, radii, lows, highs, by_bottom, bottoms) + by_axis:
        array.flags.writeable = False  # shared by every body that holds these items
    made = (centres, radii, lows, highs, by_axis, by_bottom, bottoms, tallest)
    # Kept with the items they are made of (whose identity is the key): the wafers alone and
    # with the carrier's solids, for a document or two.
    _BOUNDS_MADE[:] = [(wafers, carrier, made)] + _BOUNDS_MADE[:3]
    return made


class Obstacles:
    """The layout's wafers as coal solids, and the carrier's solids when given (``carrier``:
    [(vertices (n, 3) mm, triangles (m, 3) indices, name)], closed meshes in the world; triangles
    None for a convex solid given by its corners, ``carrier_obstacle``):
    items (name, slot, geometry, transform, centre, radius, low, high, inside)."""

    def __init__(self, layout, carrier=()):
        self._wafer_items = _wafer_items(layout.scanned_carrier, layout.wafers)
        self._carrier_items = ()
        self.items = list(self._wafer_items)
        self.carrier, self.carrier_count = (), 0
        if not carrier:  # else add_carrier makes them
            self._bounds()
        self.add_carrier(carrier)

    def add_carrier(self, solids):
        """Take the carrier's ``solids`` (as ``carrier`` above) for obstacles too, in place of
        those taken before; nothing new when they are the same object."""
        if solids is self.carrier or (not solids and not self.carrier):
            return
        wafers = len(self.items) - self.carrier_count
        self._carrier_items = _carrier_items(solids) if solids else ()
        self.items = self.items[:wafers] + list(self._carrier_items)
        self.carrier, self.carrier_count = solids, len(self.items) - wafers
        self._bounds()

    def _bounds(self):
        """The arrays ``_nearest`` and ``within_z`` weigh the items by, made once for the same
        items (``_wafer_items``' and ``_carrier_items``' own, which a document scanned again
        gives again: ~a tenth of the paper's clearance check): the same arrays of the same
        floats, read only, shared by the bodies that hold those items."""
        made = _bounds_of(self._wafer_items, self._carrier_items)
        (self.centres, self.radii, self.lows, self.highs, self.by_axis, self._by_bottom,
         self._bottoms, self._tallest) = made

    def within_z(self, bottom, top):
        """The indices (ascending) of the obstacles whose boxes reach into (bottom, top) along Z:
        a bisection of the boxes' bottoms (no box is taller than the tallest), not a pass over
        them all."""
        first = int(np.searchsorted(self._bottoms, bottom - self._tallest, side="left"))
        last = int(np.searchsorted(self._bottoms, top, side="left"))
        found = self._by_bottom[first:last]
        return np.sort(found[self.highs[found, 2] > bottom])


def _slot_of(carrier, wafer):
    """The wafer's slot: the one it was loaded into, else the seat nearest its lowest point when
    it lies in the scanned carrier (None otherwise)."""
    if wafer.slot is not None and wafer.carrier in (None, carrier.name):
        return wafer.slot
    cx, cy = carrier.center
    if math.hypot(wafer.center[0] - cx, wafer.center[1] - cy) > carrier.wafer_diameter / 2.0:
        return None
    low = wafer.center[2] - wafer.radius * math.hypot(wafer.normal[0], wafer.normal[1])
    slot = round((low - carrier.first_slot_z) / carrier.pitch) + 1
    return slot if 1 <= slot <= carrier.slot_count else None


class _Body:
    """What robot and scanner share: the nearest pair at a pose, and the swept translation."""

    lift_axis = (0.0, 0.0, 1.0)

    def __init__(self, layout, carrier=()):
        self.layout = layout
        self.obstacles = Obstacles(layout, carrier)
        self.request = coal.DistanceRequest()
        self.result = coal.DistanceResult()
        self.lift_axis = np.asarray(layout.lift_axis, dtype=float)
        self._radii = {}  # id(shape) -> (shape, its bounding radius): the body's own shapes

    def add_carrier(self, solids):
        """The carrier's solids (``Obstacles``) as obstacles too, for a body made without them;
        returns the body."""
        self.obstacles.add_carrier(solids)
        return self

    # parts_at(motion, s) -> [(name, geometry, rotation, translation mm, moves_with_lift)]

    def _distance(self, geometry, transform, index):
        item = self.obstacles.items[index]
        self.result.clear()
        d = coal.distance(geometry, transform, item[2], item[3], self.request, self.result)
        inside = item[8]
        if inside is not None and d > 0.0 and inside(transform.getTranslation()):
            # A mesh is a surface: a part clear of it but within it overlaps the solid.
            return -d
        return d

    def _holds(self, shapes):
        """Keep the bounding radius of each of the body's own ``shapes`` (they are asked for
        at every pose of a search: ~20 % of a slow scan's clearance)."""
        self._radii = {id(shape): (shape, _bound_radius(shape)) for shape in shapes}

    def _radius(self, geometry):
        """``_bound_radius`` of a part's shape: kept for the body's own (``_holds``)."""
        known = self._radii.get(id(geometry))
        if known is not None and known[0] is geometry:
            return known[1]
        return _bound_radius(geometry)  # a swept shape, made for one question

    def _nearest(self, parts, centres=None, radii=None, extents=None):
        """(distance, part, obstacle, slot, witness on the part) of the closest pair: the
        pairs in the order of their bounding spheres' distance, until that is no less than the
        least distance found. First among the obstacles within NEAR_BAND mm of the parts
        along Z, which is the answer when it is nearer than that; else among them all.
        ``centres`` ((n, 3): the parts' translations) and ``radii`` (their shapes' bounding
        radii), when the caller has them as arrays already; made from the parts when None.
        ``extents`` ((3, n), or None): the half sides of boxes about the parts' translations,
        square to the world, that hold them (``_nearest_among`` passes over a pair whose boxes
        lie apart by more than the least distance found)."""
        best = (math.inf, "", "", None, None)
        if not self.obstacles.items or not parts:
            return best
        obstacles = self.obstacles
        if centres is None:
            centres = np.array([part[3] for part in parts])
        if radii is None:
            radii = np.array([self._radius(part[1]) for part in parts])
        if len(obstacles.items) > NEAR_BAND_FROM:
            # A stocker's 10,000 wafers: the parts meet a few of them at a time, and every pair
            # weighed at every pose made a scan's clearance quadratic in the wafers (254 s of
            # a 10,000-wafer scan). An obstacle whose box lies NEAR_BAND mm or more above or
            # below every part's bounding sphere is at least that far from the parts.
            bottom = float(np.min(centres[:, 2] - radii)) - NEAR_BAND
            top = float(np.max(centres[:, 2] + radii)) + NEAR_BAND
            best = self._nearest_among(parts, centres, radii, obstacles.within_z(bottom, top),
                                       best, extents)
            if best[0] < NEAR_BAND:
                return best
            best = (math.inf, "", "", None, None)
        return self._nearest_among(parts, centres, radii, None, best, extents)

    def _nearest_among(self, parts, centres, radii, among, best, extents=None):
        """``_nearest`` over the obstacles ``among`` (indices, ascending; None: all).

        With ``extents``, a pair whose boxes (the part's, the obstacle's: both hold their
        shapes) lie apart by more than APART_SLACK, and by at least the least distance found
        plus APART_SLACK, is passed over, not measured. The shapes are then apart (so coal's
        distance is not a depth, nor a mesh's inside test turns it: the part's origin lies
        outside the mesh's box), and coal's distance of shapes apart is the length of a
        point of their Minkowski difference, never below the true distance but by rounding,
        itself no less than the boxes' gap: it would not have been less than the least found.
        The pairs are still weighed in the same order and stopped at the same pair, so the
        least distance, part, obstacle and witness are the same, to the last bit, for fewer
        of coal's distances (a swept stroke's long shapes lie far within their bounding
        spheres: 28 of the paper's 48 were the carrier's walls and ledges, 5 to 76 mm away,
        measured because of them)."""
        obstacles = self.obstacles
        (o_centres, lows, highs), o_radii = obstacles.by_axis, obstacles.radii
        if among is not None:
            if not len(among):
                return best
            o_centres, o_radii, lows, highs = (o_centres[:, among], o_radii[among],
                                               lows[:, among], highs[:, among])
        # Components first (``_norms``): [axis, part, obstacle].
        o_centres, lows, highs = o_centres[:, None, :], lows[:, None, :], highs[:, None, :]
        ends = centres.T[:, :, None]
        gaps = _norms(ends - o_centres) - radii[:, None] - o_radii[None, :]
        if obstacles.carrier_count:
            # A wall or a floor is long and thin: its box bounds it far better than a sphere.
            outside = np.maximum(np.maximum(lows - ends, ends - highs), 0.0)
            gaps = np.maximum(gaps, _norms(outside) - radii[:, None])
        count = gaps.shape[1]
        apart = None
        if extents is not None:
            near, far = ends - extents[:, :, None], ends + extents[:, :, None]
            apart = _norms(np.maximum(np.maximum(lows - far, near - highs), 0.0)).ravel()
        transforms = {}
        # Stable: pairs whose bounds tie are weighed in the order of the obstacles, the same
        # order whichever obstacles are among them.
        for flat, gap in _in_gap_order(gaps.ravel(), lambda: best[0], apart):
            if gap >= best[0]:
                break
            if apart is not None:
                boxes = float(apart[flat])
                if boxes > APART_SLACK and boxes - APART_SLACK >= best[0]:
                    continue  # at least as far as the least found: it would not replace it
            i, column = divmod(flat, count)
            index = column if among is None else int(among[column])
            name, geometry, rotation, translation, _ = parts[i]
            if i not in transforms:
                transforms[i] = coal.Transform3s(rotation, translation)
            d = self._distance(geometry, transforms[i], index)
            if d < best[0]:
                obstacle, slot = self.obstacles.items[index][:2]
                best = (d, name, obstacle, slot, np.array(self.result.getNearestPoint1()))
        return best

    def _posed(self, motion, s):
        """``_nearest``'s arguments at the motion's s: the parts (``parts_at``'s), and their
        centres and radii when the body has them as arrays already (None: made from the
        parts). ``nearest`` asks this, not ``parts_at``: a body that places its parts
        otherwise overrides both."""
        return self.parts_at(motion, s), None, None

    def nearest(self, motion, s):
        d, part, obstacle, slot, _ = self._nearest(*self._posed(motion, s))
        return d, part, obstacle, slot

    def swept(self, motion):
        """The exact Closest of a translation along the lift (stroke, steps), or None."""
        if motion.kind not in (core.STROKE, core.STEPS):
            return None
        axis = self.lift_axis
        travel = abs(motion.end - motion.start) / abs(axis[2])
        sign = 1.0 if motion.end >= motion.start else -1.0
        direction = sign * axis
        # ``translation + 0.5 * travel * direction`` makes its right side first: made once,
        # the same floats for every part.
        shift = 0.5 * travel * direction
        start = self.parts_at(motion, motion.start)
        swept, halves, radii, boxes = [], {}, [], []
        for name, geometry, rotation, translation, moves in start:
            if not moves or travel == 0.0:
                swept.append((name, geometry, rotation, translation, moves))
                radii.append(self._radius(geometry))
                boxes.append(_box_halves(geometry))
                continue
            if isinstance(geometry, coal.Sphere):
                rotation = _frame_z(axis)
            elif abs(abs(rotation[:, 2] @ axis) - 1.0) > 1e-12 or not isinstance(
                    geometry, (coal.Box, coal.Cylinder, coal.Capsule)):
                return None  # not along its own axis: the Lipschitz search instead
            shape, radius, box = _swept_shape(geometry, travel)
            swept.append((name, shape, rotation, translation + shift, moves))
            radii.append(radius)
            boxes.append(box)
            halves[name] = (translation, _half_length(geometry))
        extents = None
        if swept and all(box is not None for box in boxes):
            # Each part's box square to the world: |R| times its own half sides, plus its
            # rounding (a capsule's, a sphere's radius).
            boxes = np.array(boxes)
            turned = np.abs(np.array([part[2] for part in swept])) @ boxes[:, :3, None]
            extents = (turned[:, :, 0] + boxes[:, 3:]).T
        # ``_nearest``'s radii, as it would make them: each shape's ``_radius``.
        d, part, obstacle, slot, witness = self._nearest(swept, None, np.array(radii), extents)
        if d <= 0.0:
            # Overlapping: a swept shape's depth is not the least depth at one position, so
            # the Lipschitz search answers (its contact is a position's own signed distance).
            return None
        position = motion.start
        if part in halves and witness is not None:
            origin, half = halves[part]
            w = float((witness - origin) @ direction)  # along the motion, from the start
            low, high = max(0.0, w - half), min(travel, w + half)
            tau = 0.5 * (low + high) if low <= high else min(max(w, 0.0), travel)
            position = motion.start + sign * tau * abs(axis[2])
        return core.Closest(motion, float(d), float(position), part, obstacle,
                            motion.slot if slot is None else slot)


class RobotBody(_Body):
    """The robot's collision geometry (its URDF's <collision> boxes, cylinders and spheres) as
    its joints move through a scan of the layout. ``urdf`` (None: the bundled robot), ``base``
    ((x, y, z) mm, yaw deg)
    and ``start`` (the taught start pose's joint values) default to the layout's [robot];
    ``carrier``: the carrier's solids as meshes (``Obstacles``), obstacles beside the wafers."""

    def __init__(self, layout, urdf=None, base=None, start=None, carrier=()):
        super().__init__(layout, carrier)
        spec = layout.robot
        if urdf is None and spec is not None:
            urdf = spec.urdf
        self.robot, self.geometry, self.geometry_data, self.parts = collision_model(urdf)
        radii, self._part_radii, moves, self.joint_index = self._of_model()
        self._radii = radii  # ``_holds``' of the parts' shapes
        if base is None:
            base = (tuple(spec.base), spec.base_yaw) if spec is not None \
                else ((0.0, 0.0, 0.0), 0.0)
        self.base = base
        self.start = dict(start) if start is not None else self.robot.teach_start_pose(
            base, layout.beam.emitter, layout.beam.direction)
        yaw = math.radians(base[1])
        c, s = math.cos(yaw), math.sin(yaw)
        self.turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        self.offset = np.asarray(base[0], dtype=float)
        self.z0, self.axis = self._beam_height_and_lift()
        self.lift_axis = np.asarray(self.axis, dtype=float)
        # A part moves with the lift when the lift joint is among its joint's ancestors.
        self.moves = list(moves)
        self.wrist = "wrist"
        self._advanced = {}
        self._joints_at = {}  # (motion, s) -> joint values: nearest and path ask for the same
        self._reach_for = (None, None)

    def _of_model(self):
        """What depends on the collision model only, made once for it (``_MODEL_MADE``): the
        shapes' bounding radii (``_holds``' dict and the parts' array, read only), whether
        each part moves with the lift, and each joint's index."""
        for parts, made in _MODEL_MADE:
            if parts is self.parts:
                return made
        self._holds([shape for _, shape, _ in self.parts])
        part_radii = np.array([self._radius(shape) for _, shape, _ in self.parts])
        part_radii.flags.writeable = False
        lift_index = self.robot.joint_names.index(self.robot.lift_joint) + 1
        moves = tuple(self._downstream(joint, lift_index) for _, _, joint in self.parts)
        joint_index = {name: i + 1 for i, name in enumerate(self.robot.joint_names)}
        made = (self._radii, part_radii, moves, joint_index)
        _MODEL_MADE[:] = [(self.parts, made)] + _MODEL_MADE[:3]
        return made

    def _beam_height_and_lift(self):
        """(the beam's height in the start pose, the lift's axis in the world): the robot's
        forward kinematics at the start pose and base, made once for the same model, start
        pose and base (``_POSE_MADE``; a document scanned again gives the same: a third of
        the body's making). Keyed by the values' bits, not by their equality (-0.0 == 0.0,
        yet a yaw of -0.0 may give zeros of another sign): the same bits, the same
        arithmetic, the same floats."""
        names = tuple(self.start)
        try:
            key = (names, struct.pack(f"{len(names) + 4}d", *self.start.values(),
                                      *self.base[0], self.base[1]))
        except (struct.error, TypeError, ValueError):
            key = None  # not plain numbers: made afresh
        for parts, known, made in _POSE_MADE:
            if key is not None and parts is self.parts and known == key:
                return made
        made = (self.robot.beam(self.start, self.base)[0][2], self.robot.lift_axis(self.base))
        if key is not None:
            _POSE_MADE[:] = [(self.parts, key, made)] + _POSE_MADE[:3]
        return made

    def _downstream(self, joint, ancestor):
        parents = self.robot.model.parents
        while joint > 0:
            if joint == ancestor:
                return True
            joint = parents[joint]
        return False

    def joints_at(self, z, advance=0.0):
        """Joint values with the beam at scan position z, the fork advanced ``advance`` mm."""
        if advance:
            if advance not in self._advanced:
                self._advanced[advance] = self.robot.straight_advance(self.start, self.base,
                                                                       advance)
            joints = dict(self._advanced[advance])
        else:
            joints = dict(self.start)
        lift = self.robot.lift_joint
        joints[lift] = joints.get(lift, 0.0) + (z - self.z0) / self.axis[2]
        return joints

    def _motion_joints(self, motion, s):
        if motion.kind in (core.STROKE, core.STEPS):
            return self.joints_at(s, motion.advance)
        if motion.kind == core.JAB:
            return self.robot.straight_advance(self.joints_at(motion.z), self.base, s)
        joints = self.joints_at(motion.z, motion.advance)  # SWEEP
        joints[self.wrist] = joints[self.wrist] + s
        return joints

    def _placed(self, joints):
        """(rotations (n, 3, 3), translations (n, 3) mm) in the world of the collision parts
        at the joint values: each part's ``turn @ R`` and ``turn @ (t * MM) + offset``, all
        parts in one stacked product. numpy's matmul makes each stacked product with the BLAS
        call it makes for one part alone (the same floats), and the parts one by one cost
        twice as much (a pose of every search)."""
        model, data = self.robot.model, self.robot.data
        pin.forwardKinematics(model, data, self.robot._to_q(joints))
        pin.updateGeometryPlacements(model, data, self.geometry, self.geometry_data)
        placed = self.geometry_data.oMg.tolist()  # a tenth of list()'s time
        rotations = np.array([m.rotation for m in placed]).reshape(-1, 3, 3)
        translations = np.array([m.translation for m in placed]).reshape(-1, 3, 1) * MM
        return self.turn @ rotations, (self.turn @ translations)[:, :, 0] + self.offset

    def placements(self, joints):
        """[(R, t mm)] in the world of each collision part at the joint values."""
        return list(zip(*self._placed(joints)))

    def _posed(self, motion, s):
        rotations, translations = self._placed(self.motion_joints(motion, s))
        parts = [(name, shape, rotation, translation, moves)
                 for (name, shape, _), rotation, translation, moves
                 in zip(self.parts, rotations, translations, self.moves)]
        return parts, translations, self._part_radii

    def parts_at(self, motion, s):
        return self._posed(motion, s)[0]

    def _reach(self, joints, joint):
        """The farthest any part downstream of ``joint`` lies from its (vertical) axis, mm."""
        placements = self.placements(joints)
        axis_at = self.turn @ (np.asarray(self.robot.data.oMi[joint].translation) * MM) \
            + self.offset
        reach = 0.0
        for (_, shape, parent), (_, t) in zip(self.parts, placements):
            if self._downstream(parent, joint):
                reach = max(reach, math.hypot(*(t - axis_at)[:2]) + _bound_radius(shape))
        return reach

    def _reaches(self, motion):
        """Per turning joint, a bound on the reach from its axis over the whole motion: the
        reach at the motion's ends, plus (a jab) twice its length, as far as any point of the
        fork, moved straight, can get further from an axis. Kept for the motion."""
        if self._reach_for[0] != motion:
            start = self.motion_joints(motion, motion.start)
            end = self.motion_joints(motion, motion.end)
            margin = 2.0 * abs(motion.end - motion.start) if motion.kind == core.JAB else 0.0
            self._reach_for = (motion, {
                name: max(self._reach(start, self.joint_index[name]),
                          self._reach(end, self.joint_index[name])) + margin
                for name in ("shoulder", "elbow", "wrist")})
        return self._reach_for[1]

    def motion_joints(self, motion, s):
        key = (motion, s)
        joints = self._joints_at.get(key)  # one hash of the motion, not two
        if joints is None:
            if len(self._joints_at) > 4096:
                self._joints_at.clear()
            joints = self._joints_at[key] = self._motion_joints(motion, s)
        return joints

    def path(self, motion, s0, s1):
        """How far any point moves between s0 and s1: the lift's travel; or each turning
        joint's change (rad) times its reach (``_reaches``), the joints taken to move
        monotonically between the two."""
        if motion.kind in (core.STROKE, core.STEPS):
            return abs(s1 - s0) / abs(self.axis[2])
        a, b = self.motion_joints(motion, s0), self.motion_joints(motion, s1)
        reaches = self._reaches(motion)
        return sum(math.radians(abs(b[name] - a[name])) * reaches[name]
                   for name in ("shoulder", "elbow", "wrist"))


_MODELS = {}  # (URDF path, its mtime) -> collision_model's answer: coal objects made once
_MODEL_MADE = []  # [(a collision model's parts, RobotBody._of_model's answer)]
_POSE_MADE = []  # [(a collision model's parts, start pose and base, RobotBody's z0 and axis)]


def collision_model(urdf=None):
    """(WaferRobot, Pinocchio GeometryModel and GeometryData of its <collision> elements,
    [(name, coal shape in mm, parent joint)]) of a URDF (None: the bundled robot), made once per
    file version and kept: a scan's clearance check then costs its distances only."""
    path = urdf or _bundled_urdf()
    key = (str(path), os.path.getmtime(path))
    if key not in _MODELS:
        robot = WaferRobot(path)
        geometry = pin.buildGeomFromUrdf(robot.model, robot.urdf, pin.GeometryType.COLLISION)
        names = _collision_names(robot.urdf)
        parts = []
        for i, obj in enumerate(geometry.geometryObjects):
            shape = obj.geometry
            if isinstance(shape, coal.Box):
                scaled = coal.Box(*(2.0 * MM * np.asarray(shape.halfSide)))
            elif isinstance(shape, coal.Cylinder):
                scaled = coal.Cylinder(MM * shape.radius, 2.0 * MM * shape.halfLength)
            elif isinstance(shape, coal.Sphere):
                scaled = coal.Sphere(MM * shape.radius)
            else:
                raise ValueError(f"{robot.urdf}: collision geometry {obj.name} is not a "
                                 "box, a cylinder or a sphere")
            parts.append((names[i] if i < len(names) else obj.name, scaled, obj.parentJoint))
        _MODELS[key] = (robot, geometry, pin.GeometryData(geometry), parts)
    return _MODELS[key]


_BUNDLED = []  # [bundled_urdf()]


def _bundled_urdf():
    """``bundled_urdf()``, made once: the addon's folder does not move, and its path
    arithmetic cost a body more than the rest of ``collision_model``."""
    if not _BUNDLED:
        _BUNDLED.append(bundled_urdf())
    return _BUNDLED[0]


def _collision_names(urdf):
    """The URDF's collision elements' names in Pinocchio's order (link by link), ``link_i``
    where unnamed."""
    names = []
    for link in ElementTree.parse(urdf).getroot().iter("link"):
        for i, element in enumerate(link.findall("collision")):
            names.append(element.get("name") or f"{link.get('name')}_{i}")
    return names


class ScannerBody(_Body):
    """Without a robot (SPEC §15), the scanner's solid stands in: its emitter and receiver heads,
    spheres of HEAD_RADIUS (the beam itself is meant to cross the wafers)."""

    def __init__(self, layout, carrier=()):
        super().__init__(layout, carrier)
        self.sphere = coal.Sphere(HEAD_RADIUS)
        self._holds([self.sphere])

    def ends(self, motion, s):
        if motion.kind in (core.STROKE, core.STEPS):
            emitter, beam = slow_scan.beam_at(self.layout, s, motion.advance)
        elif motion.kind == core.JAB:
            emitter, beam = slow_scan.beam_at(self.layout, motion.z, s)
        else:
            emitter, beam = slow_scan.beam_at(self.layout, motion.z, motion.advance, s)
        return np.asarray(emitter, dtype=float), np.asarray(beam.receiver, dtype=float)

    def parts_at(self, motion, s):
        emitter, receiver = self.ends(motion, s)
        return [("emitter head", self.sphere, np.eye(3), emitter, True),
                ("receiver head", self.sphere, np.eye(3), receiver, True)]

    def path(self, motion, s0, s1):
        if motion.kind in (core.STROKE, core.STEPS):
            return abs(s1 - s0) / abs(self.lift_axis[2])
        if motion.kind == core.JAB:
            return abs(s1 - s0)
        wx, wy = slow_scan.wrist_axis(self.layout, motion.z, motion.advance)
        reach = max(math.hypot(p[0] - wx, p[1] - wy) for p in self.ends(motion, 0.0))
        return math.radians(abs(s1 - s0)) * reach


def fork_footprints(body):
    """[(part, [(x, y) …])]: each collision box of the robot's fork (the link that carries the
    scanner), its eight corners seen from above (world X, Y in mm) in the scan's start pose;
    empty for the scanner's heads (no robot). What ``core.scan.pocket_plan.fork_swept``
    sweeps for the GUI's pocket plan."""
    if not isinstance(body, RobotBody):
        return []
    model = body.robot.model
    frame = model.frames[model.getFrameId(FORK)]
    fork_joint = getattr(frame, "parentJoint", getattr(frame, "parent", None))
    corners = np.array([[sx, sy, sz] for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)
                        for sz in (-1.0, 1.0)])
    found = []
    for (name, shape, joint), (rotation, translation) in zip(body.parts,
                                                             body.placements(body.start)):
        if joint == fork_joint and isinstance(shape, coal.Box):
            points = (corners * np.asarray(shape.halfSide, dtype=float)) @ rotation.T \
                + translation
            found.append((name, [(float(x), float(y)) for x, y in points[:, :2]]))
    return found


def body_for(layout, carrier=()):
    """The body that makes the layout's scan: its robot's, else the scanner's heads."""
    return RobotBody(layout, carrier=carrier) if layout.robot is not None \
        else ScannerBody(layout, carrier)


def carrier_note(layout, body):
    """The report's ``carrier``: how many of the scanned carrier's solids the body checked."""
    count = body.obstacles.carrier_count
    if not count:
        return core.CARRIER_NOT_CHECKED
    others = [c.name for c in layout.carriers if c.name != layout.carrier]
    return (f"checked: {count} solid{'s' if count != 1 else ''} of {layout.carrier}"
            + (f" (not those of {', '.join(others)})" if others else ""))


def clearance_for(layout, body=None, pockets=None, carrier=()):
    """SPEC §15's ClearanceReport of a scan of the layout (``core.check_clearance``), by its
    robot when it has one, else by the scanner's heads; ``carrier``: the scanned carrier's
    solids as meshes (``Obstacles``) for a body made here (a given body has its own)."""
    body = body or body_for(layout, carrier)
    return core.check_clearance(layout, body, pockets,
                                body_name="robot" if isinstance(body, RobotBody) else "scanner",
                                carrier=carrier_note(layout, body))
