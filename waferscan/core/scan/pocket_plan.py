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
