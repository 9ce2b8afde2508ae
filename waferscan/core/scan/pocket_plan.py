"""A pocket seen from above (SPEC §13): where a slow scan's beam met the wafer in the jab and the
sweep. Plain geometry for the GUI's plan view (gui/plan_view.py) and the ``--plot`` panel
(plots/signal.py): both draw it, neither computes it.

Coordinates are the carrier's own, in mm, seen from above: ``u`` across the opening, from the
carrier's left support to its right one (``Carrier.lateral``), and ``v`` into the carrier
(against its ``front``), both from the carrier's centre. The robot stands at negative ``v``.

Where the beam met a wafer: at a blocking edge (the jab's first contact, the sweep's first and
last blocked angle) the beam's segment touches the wafer's disc at one point; seen from above
that is the segment's point nearest the wafer's centre, which is what ``contact`` holds. For a
level wafer (the wrist's axis is its axis) this is exact; for a tilted one (cross-slotted, a few
degrees) it is the plan's approximation, the outline drawn as the wafer's circle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..mapping import POSITION_ERROR, PROTRUDING
from . import slow_scan

# The beams a plan shows, in the order they are drawn.
START, FRONT, DEEPEST, SWEEP_FIRST, SWEEP_LAST = ("start", "front", "deepest", "sweep first",
                                                  "sweep last")


@dataclass(frozen=True)
class PlanBeam:
    """One position of the beam: ``role`` (START, FRONT…), its two ends (u, v) in mm, the point
    (u, v) where it meets a wafer's rim or None, and a label (the advance or the angle)."""

    role: str
    ends: tuple
    contact: tuple | None
    label: str


@dataclass(frozen=True)
class PlanDisc:
    """A wafer's outline seen from above: its name, centre (u, v) and radius, mm."""

    name: str
    center: tuple
    radius: float


@dataclass(frozen=True)
class PlanArc:
    """A tine's path during the sweep where it is inside a wafer (a real fork would strike it):
    ``tine`` ("emitter" or "receiver" end of the beam), the wrist angles (low, high) in degrees,
    ``points`` (u, v) in mm along the arc about the wrist, at most STRIKE_ARC_STEP_DEG apart,
    and a label."""

    tine: str
    angles: tuple
    points: tuple
    label: str


STRIKE_ARC_STEP_DEG = 0.25


@dataclass(frozen=True)
class PocketPlan:
    """One pocket's jab and sweep seen from above. ``seated``: where a wafer seated in the slot
    would be; ``wafers``: the wafers the beam can reach at the pocket's height; ``beams``: the
    beam at the start pose, at the jab's first contact and deepest point and at the sweep's
    first and last blocked angles (those that were made and met something); ``wrist``: (u, v)
    of the wrist axis for the sweep, or None; ``title``: one line saying what was found;
    ``strikes``: the tines' paths inside a wafer during the sweep (PlanArc), if any."""

    slot: int
    z: float
    seated: PlanDisc
    wafers: tuple
    beams: tuple
    wrist: tuple | None
    title: str
    strikes: tuple = ()

    def beam(self, role):
        """The beam of that role, or None."""
        return next((b for b in self.beams if b.role == role), None)


def _frame(carrier):
    """(to_local(x, y) -> (u, v)) for the carrier: u along lateral, v against front."""
    cx, cy = carrier.center
    lx, ly = carrier.lateral
    fx, fy = carrier.front
    norm = math.hypot(fx, fy)
    ix, iy = -fx / norm, -fy / norm
    ln = math.hypot(lx, ly)
    lx, ly = lx / ln, ly / ln

    def to_local(x, y):
        dx, dy = x - cx, y - cy
        return (dx * lx + dy * ly, dx * ix + dy * iy)

    return to_local


def _nearest_on_segment(a, b, p):
    """The point of segment a-b nearest p (2D)."""
    ux, uy = b[0] - a[0], b[1] - a[1]
    length2 = ux * ux + uy * uy
    t = 0.0 if length2 == 0.0 else ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / length2
    t = min(1.0, max(0.0, t))
    return (a[0] + t * ux, a[1] + t * uy)


def _contact(ends, discs):
    """Where a beam at a blocking edge meets a wafer: the segment's point nearest the centre of
    the disc it comes closest to entering (least distance minus radius)."""
    best = None
    for disc in discs:
        point = _nearest_on_segment(ends[0], ends[1], disc.center)
        gap = math.hypot(point[0] - disc.center[0], point[1] - disc.center[1]) - disc.radius
        if best is None or gap < best[0]:
            best = (gap, point)
    return None if best is None else best[1]


def pocket_plan(result, slot):
    """The plan of one probed pocket of a ScanResult, or None when the slot was not probed
    (no jab or sweep, or not scanned)."""
    probe = next((p for p in result.pockets if p.slot == slot), None)
    if probe is None:
        return None
    layout = result.layout
    carrier = layout.scanned_carrier
    to_local = _frame(carrier)
    seated = slow_scan.seated_wafer(carrier, slot)
    discs = tuple(PlanDisc(w.name, to_local(w.center[0], w.center[1]), w.radius)
                  for w in slow_scan.wafers_near(layout, probe.z))
    seated_disc = PlanDisc(seated.name, to_local(seated.center[0], seated.center[1]),
                           seated.radius)

    def ends_at(advance=0.0, turn=0.0):
        emitter, beam = slow_scan.beam_at(layout, probe.z, advance, turn)
        far = [e + beam.length * d for e, d in zip(emitter, beam.direction)]
        return (to_local(emitter[0], emitter[1]), to_local(far[0], far[1]))

    scan = layout.scan
    beams = [PlanBeam(START, ends_at(), None, "start pose")]
    words = []
    if scan.jab > 0.0:
        if probe.front is not None:
            ends = ends_at(probe.front)
            beams.append(PlanBeam(FRONT, ends, _contact(ends, discs),
                                  f"front {probe.front:.3f} mm"))
            words.append(f"front {probe.front:.3f} mm")
        else:
            words.append("jab met nothing")
        if probe.expected_front is not None:
            words[-1] += f" (seated {probe.expected_front:.3f})"
        beams.append(PlanBeam(DEEPEST, ends_at(probe.depth), None,
                              f"jab {probe.depth:g} mm"))
    wrist = None
    if scan.sweep > 0.0:
        wx, wy = slow_scan.wrist_axis(layout, probe.z, probe.depth)
        wrist = to_local(wx, wy)
        if probe.sweep is not None:
            for role, angle in ((SWEEP_FIRST, probe.sweep[0]), (SWEEP_LAST, probe.sweep[1])):
                ends = ends_at(probe.depth, angle)
                beams.append(PlanBeam(role, ends, _contact(ends, discs), f"{angle:+.3f}°"))
            words.append(f"sweep {probe.sweep[0]:+.3f}° to {probe.sweep[1]:+.3f}°")
            if probe.shift is not None:
                words[-1] += f", shift {probe.shift:+.3f} mm"
        else:
            words.append("sweep met nothing")
    title = f"slot {slot} at Z {probe.z:.3f} mm: " + "; ".join(words)
    strikes = _strike_arcs(layout, probe, to_local) if probe.strike else ()
    return PocketPlan(slot, probe.z, seated_disc, discs, tuple(beams), wrist, title, strikes)


def _strike_arcs(layout, probe, to_local):
    """Each tine's path inside a wafer during the sweep, as arcs in the plan (PlanArc)."""
    arcs = []
    by_tine = slow_scan.tine_strikes(layout, probe.z, probe.depth, layout.scan.sweep)
    for end, (tine, spans) in enumerate(zip(("emitter", "receiver"), by_tine)):
        for low, high in spans:
            count = max(2, int(math.ceil((high - low) / STRIKE_ARC_STEP_DEG)) + 1)
            points = []
            for i in range(count):
                angle = low + (high - low) * i / (count - 1)
                x, y, _ = slow_scan.tine_points(layout, probe.z, probe.depth, angle)[end]
                points.append(to_local(x, y))
            arcs.append(PlanArc(tine, (low, high), tuple(points),
                                f"{tine} tine in the wafer {low:+.3f}° to {high:+.3f}°"))
    return tuple(arcs)


def chosen_slots(result, most=4):
    """The probed pockets worth a look first: those judged protruding or off position by the jab
    or the sweep (their slot reads 6 or 5), then the others the beam met, in slot order; at most
    ``most``."""
    states = {s.slot: s.state for s in result.slot_map.slots}
    judged = [p.slot for p in result.pockets if states.get(p.slot) in (POSITION_ERROR, PROTRUDING)]
    met = [p.slot for p in result.pockets
           if p.slot not in judged and (p.front is not None or p.sweep is not None)]
    return (judged + met)[:most]


# --- where the fork went (SPEC §15 in the plan) -------------------------------------------------

FORK_STEP_DEG = 1.0  # the sweep's outlines at most this far apart (see PlanSwept)


@dataclass(frozen=True)
class PlanSwept:
    """Where one part of the fork went during a pocket's jab and sweep, seen from above, in the
    plan's (u, v) mm. ``part``: its name (the URDF's collision element); ``pieces``: convex
    polygons whose union is the region it swept: the jab's (the hull of its outline at the
    start pose and at the jab's deepest point: a straight advance sweeps exactly that) and the
    sweep's (the hulls of consecutive outlines at most FORK_STEP_DEG apart; a point between two
    turns lies on an arc whose chord the hull holds, so the union misses at most the arc's
    sagitta, r (1 - cos(step / 2)): 0.01 mm at 275 mm from the wrist); ``outlines``: its
    outline (convex, counter-clockwise) at the start pose, the jab's deepest point and the
    sweep's two ends, as (what, polygon) pairs; ``angles``: the wrist angles (low, high) the
    sweep turned, or None; ``advance``: the jab's depth (mm)."""

    part: str
    pieces: tuple
    outlines: tuple
    angles: tuple | None
    advance: float


def convex_hull(points):
    """The convex hull of 2D points, counter-clockwise, without repeated or collinear points
    (Andrew's monotone chain)."""
    pts = sorted(set((float(x), float(y)) for x, y in points))
    if len(pts) <= 2:
        return tuple(pts)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0.0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0.0:
            upper.pop()
        upper.append(p)
    return tuple(lower[:-1] + upper[:-1])


def fork_pose(layout, z, advance=0.0, turn=0.0):
    """f(x, y) -> (x, y): where the fork's rigid motion takes a point seen from above (world X,
    Y mm) given in the start pose: advanced ``advance`` mm along the heading, then turned by
    ``turn`` degrees about the wrist axis, as ``slow_scan.beam_at`` moves the beam."""
    hx, hy, _ = slow_scan.heading(layout)
    wx, wy = slow_scan.wrist_axis(layout, z, advance)
    a = math.radians(turn)
    c, s = math.cos(a), math.sin(a)

    def moved(x, y):
        dx, dy = x + advance * hx - wx, y + advance * hy - wy
        return (wx + c * dx - s * dy, wy + s * dx + c * dy)

    return moved


def sweep_angles(layout, probe):
    """The wrist angles (low, high) a pocket's sweep turned: the probe's ``reached`` when it
    says (SPEC §13 amended: each side stops short of clearance_min), else the whole
    ±sweep; None without a sweep."""
    sweep = layout.scan.sweep
    if sweep <= 0.0:
        return None
    reached = getattr(probe, "reached", None)
    return (float(reached[0]), float(reached[1])) if reached else (-sweep, sweep)


def fork_swept(result, slot, parts, step_deg=FORK_STEP_DEG):
    """The region each part of the fork swept at a probed pocket (a tuple of PlanSwept), or ()
    when the slot was not probed. ``parts``: [(name, [(x, y) …])], each part's points seen from
    above (world X, Y in mm; its outline is their convex hull) with the robot in the scan's
    start pose (the robot layer gives them: its URDF's collision boxes)."""
    probe = next((p for p in result.pockets if p.slot == slot), None)
    if probe is None or not parts:
        return ()
    layout = result.layout
    to_local = _frame(layout.scanned_carrier)
    depth = probe.depth
    angles = sweep_angles(layout, probe)
    swept = []
    for name, points in parts:
        outline = convex_hull(points)

        def at(advance, turn, outline=outline):
            move = fork_pose(layout, probe.z, advance, turn)
            return convex_hull([to_local(*move(x, y)) for x, y in outline])

        start, deepest = at(0.0, 0.0), at(depth, 0.0)
        outlines = [("start", start)]
        pieces = []
        if depth > 0.0:
            pieces.append(convex_hull(start + deepest))
            outlines.append(("deepest", deepest))
        if angles is not None and angles[1] > angles[0]:
            low, high = angles
            count = max(1, int(math.ceil((high - low) / step_deg)))
            turns = [at(depth, low + (high - low) * i / count) for i in range(count + 1)]
            pieces += [convex_hull(a + b) for a, b in zip(turns, turns[1:])]
            outlines += [("sweep low", turns[0]), ("sweep high", turns[-1])]
        if not pieces:
            pieces.append(start)
        swept.append(PlanSwept(name, tuple(pieces), tuple(outlines), angles, depth))
    return tuple(swept)
