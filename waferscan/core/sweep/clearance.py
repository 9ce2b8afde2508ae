"""A sweep's ``[clearance]`` report (SPEC §12, §15): the rate of drawn layouts in which some motion
of the scan comes closer than ``clearance_min`` to a wafer, over arrays, in closed form.

The exact check of one layout (``waferscan.robot.clearance.clearance_for``) asks coal for the
distances, ~ms a layout. Here the body is reduced once, by the layer that knows it, to numbers:
over a fast scan's strokes every part that moves with the (vertical) lift sweeps a vertical
prism, and a part that does not move stands still, so each part becomes a ``PrismPart``: a
plan-view rectangle (a point for a cylinder's or a sphere's axis) rounded by a radius, times the
Z range it occupies during the strokes (``waferscan.robot.sweep_clearance.stroke_body`` for a
robot; ``scanner_body`` here for the scanner's heads). A box turned about Z is a rectangle with
no rounding, a vertical cylinder a point rounded by its radius (a disc), a sphere swept
vertically a vertical segment rounded by a ball (a capsule).

Each wafer is held in a cylinder along its normal: its rim circle's radius R, its height h = t +
|bow| from its lowest to its highest point along the normal, its Z extent mid_z ± (R sin(tilt) +
h/2 cos(tilt)). The least distance between a prism and a wafer is at least sqrt(d_plan² + d_z²),
d_z the gap of the Z ranges and d_plan a lower bound of the plan views' gap: along d, the
direction from the wafer's centre to the nearest point of the part's rectangle, the wafer's
plan view reaches R sqrt(1 - a²) + h/2 a from its centre, a = sin(tilt) |d . the tilt's
direction| (a separating axis). A prism and a level cylinder are both a plan region times a Z
range, so:

- exact for a level flat wafer, and for a level bowed one whenever the prism spans its Z range
  (a stroke through the carrier: the bow does not change the plan view);
- for a tilted wafer (a drawn tilt, a cross-slotted wafer) never more than the true distance;
  the separating axis is not quite the nearest direction, by a second-order amount: against
  coal on 1,000 drawn layouts with cross-slotted wafers and 0.2° tilts, at most 1.5e-5 mm less
  (tests/robot/test_sweep_clearance_coal.py).

Overlapping solids give 0 (a contact; no depth is measured). Every layout's least distance is
a float of its own block's arrays: the same floats in any partition, in any process.
"""

from __future__ import annotations

from dataclasses import dataclass

HEAD_RADIUS = 3.0  # mm: the scanner's emitter and receiver heads (robot/clearance.py's)

METHOD = ("closed form over the drawn arrays: the body's parts swept over the fast scan's "
          "strokes as vertical prisms (from its collision geometry, reduced once), each wafer "
          "held in a cylinder along its normal; exact for level wafers, never more than the "
          "true distance for tilted and cross-slotted ones (a separating axis); 0 when they "
          "overlap")


@dataclass(frozen=True)
class ClearanceStudy:
    """A tolerance file's ``[clearance]`` table: report the rate of layouts with a contact;
    ``clearance_min`` (mm) replaces the layout's ``[mapping] clearance_min`` when given."""

    clearance_min: float | None = None


@dataclass(frozen=True)
class PrismPart:
    """One part of the body over the scan's motions: the plan-view rectangle centred at
    ``center`` (x, y mm), its first side along the unit ``axis`` (x, y), half-sides ``half``
    (mm, 0 for a point), rounded by ``radius`` mm (``ball``: by a ball, a capsule's rounding,
    else by a disc, a vertical cylinder's), over ``z`` (low, high mm, on the scan's scale)."""

    name: str
    center: tuple
    axis: tuple
    half: tuple
    radius: float
    ball: bool
    z: tuple


@dataclass(frozen=True)
class StrokeBody:
    """What moves in a fast scan, reduced to prisms: ``body`` ("robot" or "scanner"),
    ``motions`` (the strokes' phases in words), ``parts`` (PrismPart, ...)."""

    body: str
    motions: tuple
    parts: tuple


@dataclass(frozen=True)
class ClearanceCheck:
    """What a sweep's blocks need for the report: the reduced ``body``, ``clearance_min`` (mm)
    and the wafers' ``radius`` (mm)."""

    body: StrokeBody
    clearance_min: float
    radius: float


def stroke_motions(layout):
    """The fast scan's strokes (core.scan.clearance.scan_motions); ValueError for a slow scan,
    whose jabs and sweeps turn the arm (not reduced to prisms: see ``clearance_for``)."""
    from ..scan.clearance import STROKE, scan_motions

    if layout.scan.mode == "slow":
        raise ValueError("[clearance]: a sweep's clearance report covers a fast scan's strokes; "
                         "a slow scan's jabs and sweeps are not reduced yet (check single "
                         "layouts with waferscan scan)")
    motions = scan_motions(layout)
    if any(m.kind != STROKE for m in motions):
        raise ValueError("[clearance]: only a fast scan's strokes are reduced")
    return motions


def scanner_body(layout):
    """Without a robot (SPEC §15): the scanner's emitter and receiver heads, spheres of
    HEAD_RADIUS, swept along the lift over the strokes (vertical capsules); placed by the
    INPUT's beam (a drawn beam_tilt turns the beam, not the heads)."""
    from ..scan.slow_scan import beam_at

    motions = stroke_motions(layout)
    ends = []
    for m in motions:
        for s in (m.start, m.end):
            emitter, beam = beam_at(layout, s)
            ends.append((tuple(emitter), tuple(beam.receiver)))
    parts = []
    for k, name in enumerate(("emitter head", "receiver head")):
        points = [e[k] for e in ends]
        if any(abs(p[0] - points[0][0]) > 1e-9 or abs(p[1] - points[0][1]) > 1e-9
               for p in points):
            raise ValueError("[clearance]: the lift is not vertical; the scanner's heads do not "
                             "sweep vertical prisms")
        zs = [p[2] for p in points]
        parts.append(PrismPart(name, (points[0][0], points[0][1]), (1.0, 0.0), (0.0, 0.0),
                               HEAD_RADIUS, True, (min(zs), max(zs))))
    return StrokeBody("scanner", tuple(m.phase for m in motions), tuple(parts))


def clearance_check(layout, tolerances, body=None):
    """The ClearanceCheck of a sweep, or None when its tolerances ask for no [clearance]
    report. ``body``: the reduced StrokeBody (a robot's from waferscan.robot.sweep_clearance;
    None: the scanner's heads, which needs no robot)."""
    study = getattr(tolerances, "clearance", None)
    if study is None:
        return None
    if body is None:
        if layout.robot is not None:
            raise ValueError("[clearance]: the layout has a robot; its collision geometry is "
                             "reduced by waferscan.robot.sweep_clearance.stroke_body(layout), "
                             "pass it as the sweep's clearance body")
        body = scanner_body(layout)
    limit = study.clearance_min
    if limit is None:
        limit = layout.mapping.clearance_min
    return ClearanceCheck(body, float(limit), 0.5 * layout.scanned_carrier.wafer_diameter)


def least_distances(check, draws):
    """Per layout of a block (``Draws``), the least distance (mm, 0: overlapping) between the
    body over its strokes and the block's wafers, with the part and the slot (1-based) of the
    closest pair: three arrays (m,). inf (part and slot -1) for a layout without a wafer."""
    import numpy as np

    R = check.radius
    n = draws.normal
    sin_t = np.hypot(n[..., 0], n[..., 1])
    cos_t = n[..., 2]
    bow = draws.bow
    h = draws.thickness + np.abs(bow)
    along = np.minimum(bow, 0.0) + 0.5 * h
    mid = draws.center + n * along[..., None]
    reach_z = R * sin_t + 0.5 * h * cos_t
    w_low, w_high = mid[..., 2] - reach_z, mid[..., 2] + reach_z
    qx, qy = mid[..., 0], mid[..., 1]
    nx, ny = n[..., 0], n[..., 1]
    m, S, K = draws.exists.shape
    least = np.full((m, S, K), np.inf)
    which = np.full((m, S, K), -1, dtype=np.int64)
    for p, part in enumerate(check.body.parts):
        dx, dy = qx - part.center[0], qy - part.center[1]
        ux, uy = part.axis
        a_local, b_local = dx * ux + dy * uy, dy * ux - dx * uy
        lx = np.maximum(np.abs(a_local) - part.half[0], 0.0)
        ly = np.maximum(np.abs(b_local) - part.half[1], 0.0)
        to_rect = np.hypot(lx, ly)
        # The wafer's plan view seen along d, the direction from its centre to the
        # rectangle's nearest point: its half-width there is R sqrt(1 - a²) + h/2 a, a =
        # sin(tilt) |d . tilt direction| (a separating axis: a lower bound, ~exact).
        gx = np.sign(a_local) * lx * ux - np.sign(b_local) * ly * uy
        gy = np.sign(a_local) * lx * uy + np.sign(b_local) * ly * ux
        a = np.divide(np.abs(gx * nx + gy * ny), to_rect, out=np.zeros_like(to_rect),
                      where=to_rect > 0.0)
        half_width = R * np.sqrt(np.maximum(1.0 - a * a, 0.0)) + 0.5 * h * a
        dz = np.maximum(np.maximum(w_low - part.z[1], part.z[0] - w_high), 0.0)
        if part.ball:
            d = np.maximum(np.hypot(np.maximum(to_rect - half_width, 0.0), dz) - part.radius,
                           0.0)
        else:
            d = np.hypot(np.maximum(to_rect - part.radius - half_width, 0.0), dz)
        closer = d < least
        least = np.where(closer, d, least)
        which = np.where(closer, p, which)
    least = np.where(draws.exists, least, np.inf)
    flat = least.reshape(m, S * K)
    at = np.argmin(flat, axis=1)
    rows = np.arange(m)
    distance = flat[rows, at]
    part = which.reshape(m, S * K)[rows, at]
    slot = at // K + 1
    empty = ~np.isfinite(distance)
    return distance, np.where(empty, -1, part), np.where(empty, -1, slot)


def block_clearance(check, draws, slots):
    """What a block adds to the report: the layouts' least distances (finite ones, for the
    distribution), and integer counts: layouts, contacts, and the contacts by closest part and
    by slot (``slots`` of the carrier)."""
    import numpy as np

    distance, part, slot = least_distances(check, draws)
    contact = distance < check.clearance_min
    parts = len(check.body.parts)
    return {
        "least": distance[np.isfinite(distance)],
        "layouts": int(len(distance)),
        "contacts": int(contact.sum()),
        "by_part": np.bincount(part[contact], minlength=parts).astype(np.int64),
        "by_slot": np.bincount(slot[contact] - 1, minlength=slots).astype(np.int64),
    }


def format_clearance(report):
    """The text summary's lines of the report."""
    rate, (low, high) = report["contact_rate"], report["contact_rate_95"]
    lines = [f"clearance ({report['body']}, {', '.join(report['motions'])}): "
             f"{report['contacts']:,} of {report['layouts']:,} layouts with a contact under "
             f"{report['clearance_min']:g} mm: {100 * rate:.2f} % [{100 * low:.2f}, "
             f"{100 * high:.2f}]"]
    least = report["least_distance"]
    if least:
        lines.append(f"least distance (mm): min {least['min']:.4f}, p1 {least['p1']:.4f}, "
                     f"median {least['p50']:.4f}")
    if report["contacts_by_part"]:
        ranked = sorted(report["contacts_by_part"].items(), key=lambda kv: -kv[1])
        lines.append("contacts by closest part: " + ", ".join(f"{name} {count:,}"
                                                              for name, count in ranked))
    return lines

