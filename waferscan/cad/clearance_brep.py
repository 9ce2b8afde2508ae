"""SPEC §15's clearance confirmed with FreeCAD's B-rep (``waferscan crosscheck``, issue 29).

For every motion's least distance (a core ``Closest``: coal's, ``waferscan/robot/clearance.py``)
the moving geometry is placed at the reported position as Part solids — the robot's URDF
collision boxes, cylinders and spheres where the body's own ``parts_at`` puts them (Pinocchio's
frames, the same that coal was given), or the scanner's head spheres — and OpenCASCADE's
``distToShape`` measures them against every obstacle's solid from the document (a bowed wafer's
solid of revolution: bowed_solid.py; the scanned carrier's solids when coal checked them). The
verdict:

- coal's model exact (a flat wafer is a coal cylinder): |B-rep - coal| <= ``TOLERANCE``;
- coal's model conservative (a bowed wafer is a grown convex hull, see ``hull_bound``):
  B-rep >= coal - ``TOLERANCE`` and B-rep - coal <= the hull's bound;
- overlapping (coal < -``TOLERANCE``): ``distToShape`` says 0, and the Boolean common of coal's
  part and the obstacle has a volume; coal's depth is reported, not re-measured;
- a carrier solid that is not a box (coal has its 0.1 mm tessellation): |B-rep - coal| <=
  ``CARRIER_MESH`` + ``TOLERANCE``;
- and no other obstacle is nearer the moving geometry, by B-rep, than coal's least minus
  ``TOLERANCE`` (coal's least must be the least over every obstacle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import FreeCAD as App
import Part

from .bowed_solid import bowed_wafer_solid
from .document_scan import carrier_shapes

TOLERANCE = 1e-3  # mm: SPEC §15, "confirms each least distance with FreeCAD's B-rep to 1e-3 mm"
# Below this a B-rep distance is "touching": OpenCASCADE's confusion, with room.
TOUCHING = 1e-6
# Another wafer is measured only when its bounding box comes this near the moving geometry's
# (beyond coal's least distance): a bounding box gap is never more than the solids' gap.
_BOX_MARGIN = 1.0


@dataclass(frozen=True)
class ClearanceCheck:
    """One motion's least distance (``closest``, coal's) against OpenCASCADE's at the same
    position: ``brep`` the least distance (mm) between every moving part and the obstacle,
    ``brep_part`` the part it is from; ``overlap`` the volume (mm³) of coal's part in common
    with the obstacle when coal says they overlap; ``bound`` (mm) how far B-rep may exceed coal
    where coal's model is knowingly conservative (None: exact), with ``bound_reason``;
    ``nearer`` (part, obstacle, B-rep distance) when another obstacle is nearer than coal's
    least; ``brep_obstacle`` the obstacle OpenCASCADE found nearest."""

    closest: object
    brep: float
    brep_part: str
    overlap: float | None = None
    bound: float | None = None
    bound_reason: str = ""
    nearer: tuple | None = None
    brep_obstacle: str = ""

    @property
    def overlapping(self):
        """coal says the part and the obstacle overlap and OpenCASCADE says they touch."""
        return self.closest.distance < -TOLERANCE and self.brep <= TOUCHING

    @property
    def difference(self):
        """B-rep minus coal (mm); None when overlapping (B-rep has no depth to compare)."""
        return None if self.overlapping else self.brep - self.closest.distance

    @property
    def ok(self):
        if self.nearer is not None:
            return False
        if self.overlapping:
            return self.overlap is not None and self.overlap > 0.0
        if self.bound is not None:
            return self._low <= self.difference <= self.bound
        return abs(self.difference) <= TOLERANCE

    @property
    def _low(self):
        """The least B-rep - coal allowed where coal is conservative: -TOLERANCE; a tessellated
        carrier solid may be measured nearer or further by its chords (``CARRIER_MESH``)."""
        return -TOLERANCE - (self.bound if self.bound_reason.startswith("a carrier") else 0.0)

    def verdict(self):
        """Why it is OK or FAIL, in words."""
        if self.nearer is not None:
            part, obstacle, distance = self.nearer
            return (f"FAIL: B-rep finds {part} {distance:.6f} mm from {obstacle}, nearer than "
                    "coal's least")
        if self.overlapping:
            volume = self.overlap or 0.0
            return (f"{'OK' if self.ok else 'FAIL'}: overlapping, {volume:.3f} mm³ in common; "
                    f"coal's depth {-self.closest.distance:.3f} mm")
        if self.bound is not None:
            return (f"{'OK' if self.ok else 'FAIL'}: coal conservative ({self.bound_reason}): "
                    f"{self._low:g} <= B-rep - coal <= {self.bound:.4f} mm")
        return f"{'OK' if self.ok else 'FAIL'}: |B-rep - coal| <= {TOLERANCE:g} mm" if self.ok \
            else f"FAIL: |B-rep - coal| > {TOLERANCE:g} mm"


@dataclass(frozen=True)
class ClearanceCrossCheck:
    """Every motion's check (``checks``), or why there are none (``note``)."""

    checks: tuple = ()
    note: str = ""

    @property
    def ok(self):
        return all(c.ok for c in self.checks)

    @property
    def largest_difference(self):
        """The largest |B-rep - coal| (mm) over the motions coal's model is exact for."""
        return max((abs(c.difference) for c in self.checks
                    if c.bound is None and c.difference is not None), default=0.0)


# --- coal's geometry as Part solids ----------------------------------------------------------

def part_solid(geometry, rotation, translation):
    """The Part solid of a coal Box, Cylinder or Sphere (mm, centred on its frame's origin, a
    cylinder along its Z), placed by ``rotation`` (3x3) and ``translation`` (mm) in the world."""
    kind = type(geometry).__name__
    if kind == "Box":
        hx, hy, hz = (float(v) for v in geometry.halfSide)
        solid = Part.makeBox(2.0 * hx, 2.0 * hy, 2.0 * hz, App.Vector(-hx, -hy, -hz))
    elif kind == "Cylinder":
        half = float(geometry.halfLength)
        solid = Part.makeCylinder(float(geometry.radius), 2.0 * half, App.Vector(0, 0, -half))
    elif kind == "Sphere":
        solid = Part.makeSphere(float(geometry.radius))
    else:
        raise ValueError(f"no Part solid for coal's {kind}")
    r = [[float(rotation[i][j]) for j in range(3)] for i in range(3)]
    t = [float(v) for v in translation]
    matrix = App.Matrix(r[0][0], r[0][1], r[0][2], t[0],
                        r[1][0], r[1][1], r[1][2], t[1],
                        r[2][0], r[2][1], r[2][2], t[2],
                        0.0, 0.0, 0.0, 1.0)
    solid.Placement = App.Placement(matrix)
    return solid


def hull_bound(wafer):
    """How far (mm) coal's convex hull of a bowed wafer (robot/clearance.py ``_bowed_hull``)
    reaches beyond the solid on its convex side: each ring's polygon circumscribes its circle
    (R (1/cos(pi/sides) - 1) radially) and each surface point is raised by the sampling's
    sagitta. About 0.045 mm for a 300 mm wafer (docs/tutorials/clearance.md: "about 0.05 mm")."""
    from ..robot.clearance import BOW_RINGS, BOW_SIDES

    radius = wafer.radius
    sagitta = abs(wafer.bow) / (radius * radius) * (radius / BOW_RINGS) ** 2 / 4.0
    return radius * (1.0 / math.cos(math.pi / BOW_SIDES) - 1.0) + sagitta


def _on_open_side(wafer, point):
    """Whether ``point`` (world, mm) lies where a bowed wafer's hull fills its hollow: within
    the rim's cylinder, under a dome's underside (bow > 0) or above a bowl's top (bow < 0)."""
    n = App.Vector(*wafer.normal)
    n.normalize()
    d = App.Vector(*point) - App.Vector(*wafer.center)
    z = d.dot(n)
    r = math.sqrt(max(0.0, d.dot(d) - z * z))
    if r >= wafer.radius:
        return False
    surface = wafer.bow * (1.0 - r * r / (wafer.radius * wafer.radius))
    return z < surface if wafer.bow > 0.0 else z > surface + wafer.thickness


def _box_gap(a, b):
    """The gap (mm) between two bounding boxes: never more than their shapes'."""
    dx = max(0.0, a.XMin - b.XMax, b.XMin - a.XMax)
    dy = max(0.0, a.YMin - b.YMax, b.YMin - a.YMax)
    dz = max(0.0, a.ZMin - b.ZMax, b.ZMin - a.ZMax)
    return math.sqrt(dx * dx + dy * dy + dz * dz)


# --- the check ---------------------------------------------------------------------------------

# How far (mm) coal's mesh of a carrier solid that is not a box may lie from the solid either way:
# the CAD layer tessellates it to 0.1 mm (document_scan.with_clearance).
CARRIER_MESH = 0.1


class _Obstacles:
    """Every obstacle of the clearance check as an OpenCASCADE solid, made once: each wafer's
    (the document's own shape of a flat wafer, the solid of revolution of a bowed one, as
    ``crosscheck`` does) and, when coal checked the carrier, the scanned carrier's solids from
    the document. ``items``: [(name, solid, wafer or None)]."""

    def __init__(self, scene, layout, carrier=False):
        self.layout = layout
        self.index = {w.name: i for i, w in enumerate(layout.wafers)}
        self.items = []
        for i, wafer in enumerate(layout.wafers):
            solid = bowed_wafer_solid(wafer) if wafer.bow else scene.wafers[i].shape()
            self.items.append((wafer.name, solid, wafer))
        if carrier:
            # The same solids, by the same names, as the clearance check read (document_scan).
            self.items += [(name, solid, None) for name, solid in carrier_shapes(scene, layout)]

    def wafer(self, name):
        i = self.index.get(name)
        return None if i is None else self.layout.wafers[i]

    def solid(self, name):
        return next(solid for item, solid, _ in self.items if item == name)


def _is_box(solid):
    return len(solid.Faces) == 6 and len(solid.Vertexes) == 8 and all(
        f.Surface.__class__.__name__ == "Plane" for f in solid.Faces)


def _least(parts, items):
    """(distance, (part index, item index), the witness point on the part, [pairs touching]) of
    the nearest pair of ``parts`` [(name, solid)] and ``items`` [(name, solid, wafer)]: pairs
    taken nearest bounding boxes first, until a pair's boxes lie further apart than the least
    distance found (a box gap is never more than the solids')."""
    pairs = sorted((_box_gap(solid.BoundBox, obstacle.BoundBox), i, j)
                   for i, (_, solid) in enumerate(parts)
                   for j, (_, obstacle, _) in enumerate(items))
    best, nearest, witness, touching = math.inf, None, None, []
    for gap, i, j in pairs:
        if gap > max(best, TOUCHING):
            break
        distance, witness_ij = _distance(parts[i][1], items[j][1])
        if distance <= TOUCHING:
            touching.append((i, j))
        if distance < best:
            best, nearest, witness = distance, (i, j), witness_ij
    return best, nearest, witness, touching


def _distance(part, obstacle):
    """(OpenCASCADE's least distance between a moving part's solid and an obstacle's, the
    witness point on the part). A sphere is measured from its centre, less its radius:
    OpenCASCADE's extrema between a sphere's face and a tilted disc's can settle on a local
    minimum (0.475 mm too far on one random layout), its distance from a point cannot."""
    if len(part.Faces) == 1 and type(part.Faces[0].Surface).__name__ == "Sphere":
        surface = part.Faces[0].Surface
        centre, radius = surface.Center, surface.Radius
        distance, points, _ = Part.Vertex(centre).distToShape(obstacle)
        toward = points[0][1] - centre
        witness = centre + toward * (radius / toward.Length) if toward.Length > 0 else centre
        return max(distance - radius, 0.0), witness
    distance, points, _ = part.distToShape(obstacle)
    return distance, points[0][0]


def check_closest(body, obstacles, closest):
    """The ``ClearanceCheck`` of one motion's least distance (module doc): OpenCASCADE's least
    distance between every moving part and every obstacle at coal's position."""
    parts = [(name, part_solid(geometry, rotation, translation))
             for name, geometry, rotation, translation, _
             in body.parts_at(closest.motion, closest.position)]
    brep, nearest, witness, touching = _least(parts, obstacles.items)
    if nearest is None:
        return ClearanceCheck(closest, math.inf, "")
    coal = closest.distance
    brep_part = parts[nearest[0]][0]
    brep_obstacle = obstacles.items[nearest[1]][0]
    overlap = None
    if coal < -TOLERANCE and brep <= TOUCHING:
        # The volume coal's part has in common with what it touches.
        overlap = sum(parts[i][1].common(obstacles.items[j][1]).Volume for i, j in touching
                      if parts[i][0] == closest.part) or None
    bound, reason = None, ""
    wafer = obstacles.wafer(closest.obstacle)
    if wafer is not None and wafer.bow:
        bound, reason = hull_bound(wafer), "a bowed wafer's grown convex hull"
        if obstacles.items[nearest[1]][0] != closest.obstacle:
            named = [item for item in obstacles.items if item[0] == closest.obstacle]
            witness = _least(parts, named)[2]
        if _on_open_side(wafer, witness):
            bound += abs(wafer.bow)
            reason += (", filling the dome's underside" if wafer.bow > 0
                       else ", filling the bowl's top") + f" (bow {abs(wafer.bow):g} mm)"
    elif wafer is None and obstacles.items[nearest[1]][2] is None and \
            not _is_box(obstacles.items[nearest[1]][1]):
        # coal measured a carrier solid that is not a box by its tessellation: either way.
        bound, reason = CARRIER_MESH, f"a carrier solid tessellated to {CARRIER_MESH:g} mm"
    elif not closest.exact:
        bound, reason = math.inf, "the search's budget ran out: coal's is a lower bound"
    nearer = None
    if brep_obstacle != closest.obstacle and brep < coal - TOLERANCE:
        nearer = (brep_part, brep_obstacle, float(brep))
    return ClearanceCheck(closest, float(brep), brep_part, overlap, bound, reason, nearer,
                          brep_obstacle)


def crosscheck_clearance(scene, result):
    """The ``ClearanceCrossCheck`` of the scan ``result``'s clearance report (SPEC §15), its
    motions measured again in the document ``scene`` the scan read."""
    from ..core.scan.clearance import CARRIER_NOT_CHECKED
    from .document_scan import clearance_body

    report = result.clearance
    if report is None:
        return ClearanceCrossCheck(note="not checked: the scan has no clearance report "
                                        "(coal, which ships with pin, is missing)")
    if not report.closest:
        return ClearanceCrossCheck(note="no motions to check")
    body = clearance_body(scene, result.layout)
    obstacles = _Obstacles(scene, result.layout, report.carrier != CARRIER_NOT_CHECKED)
    checks = [check_closest(body, obstacles, c) for c in report.closest if c.obstacle]
    return ClearanceCrossCheck(tuple(checks))


# --- output ---------------------------------------------------------------------------------

_UNIT = {"z": ("z", "mm"), "advance": ("advance", "mm"), "angle": ("angle", "deg")}


def _position(closest):
    name, unit = _UNIT[closest.motion.unit]
    return f"{name} {closest.position:.3f} {unit}"


def check_dict(check):
    """One motion's check in ``crosscheck --json``'s ``clearance``."""
    c = check.closest
    return {"phase": c.motion.phase, "motion": c.motion.kind, "unit": c.motion.unit,
            "position": c.position, "part": c.part, "obstacle": c.obstacle, "slot": c.slot,
            "coal": c.distance, "brep": check.brep, "brep_part": check.brep_part,
            "brep_obstacle": check.brep_obstacle,
            "difference": check.difference, "overlapping": check.overlapping,
            "overlap_volume": check.overlap, "bound": check.bound,
            "bound_reason": check.bound_reason or None,
            "nearer": None if check.nearer is None else
            {"part": check.nearer[0], "obstacle": check.nearer[1], "brep": check.nearer[2]},
            "ok": check.ok}


def clearance_dict(clearance):
    """``crosscheck --json``'s ``clearance``: every motion's check, the verdict and the
    largest |B-rep - coal| where coal's model is exact."""
    return {"ok": clearance.ok, "tolerance": TOLERANCE, "note": clearance.note or None,
            "largest_difference": clearance.largest_difference,
            "motions": [check_dict(c) for c in clearance.checks]}


def format_clearance(clearance):
    """The clearance part of the cross-check as text: one line per motion."""
    lines = ["clearance (SPEC §15): each motion's least distance, coal's against FreeCAD's B-rep "
             "at the same position"]
    if clearance.note:
        return "\n".join(lines + [clearance.note])
    lines.append(f"{'motion':<18} {'position':<20} {'parts':<28} {'coal (mm)':>10} "
                 f"{'B-rep (mm)':>11} {'diff (mm)':>10}  verdict")
    for check in clearance.checks:
        c = check.closest
        diff = "—" if check.difference is None else f"{check.difference:+.2e}"
        lines.append(f"{c.motion.phase:<18} {_position(c):<20} "
                     f"{c.part + ' – ' + c.obstacle:<28} {c.distance:10.6f} {check.brep:11.6f} "
                     f"{diff:>10}  {check.verdict()}")
    failed = sum(not c.ok for c in clearance.checks)
    exact = any(c.bound is None and c.difference is not None for c in clearance.checks)
    lines.append((f"largest |B-rep - coal| {clearance.largest_difference:.3e} mm where coal's "
                  f"model is exact (allowed {TOLERANCE:g} mm); " if exact else "")
                 + ("every motion confirmed by FreeCAD's B-rep geometry" if not failed
                    else f"{failed} motion(s) NOT confirmed by FreeCAD's B-rep geometry"))
    return "\n".join(lines)
