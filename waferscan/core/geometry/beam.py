"""Beam-wafer geometry: the exact segment-disc test, the paper's mid-plane test, the accessibility
check and the closed-form range of scan positions over which a beam hits a wafer.

The exact test runs on Python floats (the ``loop`` engine, step by step as the paper does) and on
numpy arrays (the ``vector`` engine). The beam's frame and the rim's roots are one formulation
shared by both; the thickness band is spelled out in each with the same arithmetic in the same
order, so they give bit-identical answers; a test keeps them so.
"""

from __future__ import annotations

import math

from .bow import beam_hits_bowed_wafer

# Touching counts as blocked: the wafer is inflated by this much (mm) in every test (SPEC §2).
TOUCH_TOLERANCE = 1e-9


def beam_hits_wafer(emitter, beam, wafer, tol=TOUCH_TOLERANCE):
    """True when the segment [emitter, emitter + length*direction] meets the wafer solid.

    The solid is {c + u : 0 <= u.n <= t, |u - (u.n) n| <= R}, grown by ``tol``. Along the beam
    (parameter lam in mm) the thickness band and the radius each allow one interval of lam; the
    beam hits when those and [0, L] overlap.

    A level 300 mm wafer 0.775 mm thick seated at z = 300, and a level beam across it:

    >>> from waferscan.core.model import Beam, Wafer
    >>> wafer = Wafer("W1", (0.0, 0.0, 300.0), (0.0, 0.0, 1.0), 300.0, 0.775)
    >>> beam = Beam((-200.0, 0.0, 300.4), (1.0, 0.0, 0.0), 400.0)
    >>> beam_hits_wafer(beam.emitter, beam, wafer)
    True
    >>> beam_hits_wafer((-200.0, 0.0, 301.0), beam, wafer)  # 0.225 mm above the top face
    False
    """
    if wafer.bow:
        return beam_hits_bowed_wafer(emitter, beam, wafer, tol)  # SPEC §10: not a disc
    wn, en, qq, pq, c = _beam_across_wafer(emitter, beam.direction, wafer.center,
                                           wafer.normal, wafer.radius, tol)
    lo = -tol
    hi = beam.length + tol
    # Thickness band: -tol <= wn + lam*en <= t + tol.
    if en == 0.0:
        if wn < -tol or wn > wafer.thickness + tol:
            return False
    else:
        a = (-tol - wn) / en
        b = (wafer.thickness + tol - wn) / en
        lo = max(lo, min(a, b))
        hi = min(hi, max(a, b))
    # Radius: |p + lam*q|^2 <= (R + tol)^2 (see _beam_across_wafer).
    span = rim_span(qq, pq, c)
    if span is None:
        return False
    return max(lo, span[0]) <= min(hi, span[1])


def _beam_across_wafer(emitter, direction, center, normal, radius, tol):
    """The beam in the wafer's frame, for the scalar and the numpy test alike (floats or
    arrays that broadcast; the same operations in the same order, so both give bit-identical
    answers). With w the emitter's offset from the centre and e the beam's direction:
    wn = w.n and en = e.n (along the normal); p and q the parts of w and e across the normal,
    qq = q.q, pq = p.q and c = p.p - (R + tol)^2. Returns (wn, en, qq, pq, c)."""
    ox, oy, oz = emitter
    ex, ey, ez = direction
    cx, cy, cz = center
    nx, ny, nz = normal
    wx = ox - cx
    wy = oy - cy
    wz = oz - cz
    wn = wx * nx + wy * ny + wz * nz
    en = ex * nx + ey * ny + ez * nz
    px = wx - wn * nx
    py = wy - wn * ny
    pz = wz - wn * nz
    qx = ex - en * nx
    qy = ey - en * ny
    qz = ez - en * nz
    qq = qx * qx + qy * qy + qz * qz
    pq = px * qx + py * qy + pz * qz
    r = radius + tol
    c = px * px + py * py + pz * pz - r * r
    return wn, en, qq, pq, c


def rim_span(qq, pq, c):
    """Where along the beam's line (lam) it is within the wafer's rim, the inflated cylinder:
    (low, high), infinite for a line along the axis inside it; None when never. With p and q the
    emitter's offset and the beam's direction projected on the wafer's plane: qq = q.q,
    pq = p.q, c = p.p - r^2."""
    if qq == 0.0:
        return None if c > 0.0 else (-math.inf, math.inf)
    disc = pq * pq - qq * c
    if disc < 0.0:
        return None
    return rim_roots(qq, pq, c, disc, FloatOps)


class FloatOps:
    """The operations ``rim_roots`` needs, for Python floats."""
    sqrt = staticmethod(math.sqrt)
    copysign = staticmethod(math.copysign)
    minimum = staticmethod(min)
    maximum = staticmethod(max)

    @staticmethod
    def ratio_or_zero(num, den):
        return num / den if den != 0.0 else 0.0


class ArrayOps:
    """The operations ``rim_roots`` needs, for numpy arrays (made when first needed: importing
    numpy costs ~70 ms that the loop engine need not pay)."""

    def __init__(self, np):
        self.sqrt = np.sqrt
        self.copysign = np.copysign
        self.minimum = np.minimum
        self.maximum = np.maximum
        self.ratio_or_zero = lambda num, den: np.where(den != 0.0, num / den, 0.0)


def rim_roots(qq, pq, c, disc, ops):
    """The roots (low, high) of qq*lam^2 + 2*pq*lam + c = 0, disc = pq^2 - qq*c >= 0 and qq != 0
    (where not, the caller masks the answer), for floats (``ops`` = FloatOps) and numpy arrays
    (an ArrayOps) alike: the one formulation both tests use, so they agree bit for bit."""
    # The root pair without cancellation: q/qq and c/q.
    s = -pq - ops.copysign(ops.sqrt(disc), pq)
    r1 = s / qq
    r2 = ops.ratio_or_zero(c, s)
    return (ops.minimum(r1, r2), ops.maximum(r1, r2))


def beam_hits_wafers(ox, oy, oz, beam, cx, cy, cz, nx, ny, nz, radius, thickness,
                     tol=TOUCH_TOLERANCE):
    """``beam_hits_wafer`` over numpy arrays that broadcast (e.g. steps x wafers).

    Emitter coordinates ``ox, oy, oz`` and wafer columns ``cx ... thickness`` are arrays; the
    beam's direction and length are shared. Returns a boolean array.
    """
    import numpy as np  # only the vector engine needs it; importing it costs ~70 ms

    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        wn, en, qq, pq, c = _beam_across_wafer((ox, oy, oz), beam.direction, (cx, cy, cz),
                                               (nx, ny, nz), radius, tol)
        lo = np.full(np.broadcast(wn, en).shape, -tol)
        hi = np.full(lo.shape, beam.length + tol)
        en_zero = en == 0.0
        ok = ~en_zero | ((wn >= -tol) & (wn <= thickness + tol))
        a = (-tol - wn) / en
        b = (thickness + tol - wn) / en
        lo = np.where(en_zero, lo, np.maximum(lo, np.minimum(a, b)))
        hi = np.where(en_zero, hi, np.minimum(hi, np.maximum(a, b)))
        qq_zero = qq == 0.0
        disc = pq * pq - qq * c
        ok &= np.where(qq_zero, c <= 0.0, disc >= 0.0)
        rim_lo, rim_hi = rim_roots(qq, pq, c, np.maximum(disc, 0.0), ArrayOps(np))
        lo = np.where(qq_zero, lo, np.maximum(lo, rim_lo))
        hi = np.where(qq_zero, hi, np.minimum(hi, rim_hi))
        return ok & (lo <= hi)


def wafer_columns(wafers):
    """The wafers as numpy columns for ``beam_hits_wafers``: (cx, cy, cz, nx, ny, nz, R, t)."""
    import numpy as np

    if not wafers:
        empty = np.zeros(0)
        return (empty,) * 8
    data = np.array([(*w.center, *w.normal, w.radius, w.thickness) for w in wafers], dtype=float)
    return tuple(data[:, i] for i in range(8))


def paper_beam_hits_wafer(emitter, beam, wafer):
    """The paper's test (eqs. 1-5): where the beam line meets the wafer's mid-plane, is it
    closer than R to the centre? For a beam parallel to the wafer (e.n = 0), equation 2 would
    divide by zero: then s = (r_c - r0).e and the emitter must lie within the thickness band.
    Thickness is otherwise ignored, as in the paper. The band has the touching tolerance of the
    exact test, so that a face exactly on a step counts the same at the top as at the bottom.

    >>> import math
    >>> from waferscan.core.model import Beam, Wafer
    >>> wafer = Wafer("W1", (0.0, 0.0, 300.0), (0.0, 0.0, 1.0), 300.0, 0.775)
    >>> level = Beam((-200.0, 0.0, 300.4), (1.0, 0.0, 0.0), 400.0)
    >>> paper_beam_hits_wafer(level.emitter, level, wafer)
    True
    >>> up = Beam((-400.0, 0.0, 200.0), (math.sqrt(0.5), 0.0, math.sqrt(0.5)), 300.0)
    >>> paper_beam_hits_wafer(up.emitter, up, wafer)  # meets the mid-plane at x = -299.6
    False
    """
    rc = wafer.mid_center
    n = wafer.normal
    e = beam.direction
    r0c = tuple(c - o for c, o in zip(rc, emitter))  # eq. 1
    en = sum(a * b for a, b in zip(e, n))
    if abs(en) < 1e-12:
        height = sum((o - c) * k for o, c, k in zip(emitter, wafer.center, n))
        if not -TOUCH_TOLERANCE <= height <= wafer.thickness + TOUCH_TOLERANCE:
            return False
        s = sum(a * b for a, b in zip(r0c, e))  # eq. 3
    else:
        s = sum(a * b for a, b in zip(r0c, n)) / en  # eq. 2
    if not 0.0 <= s <= beam.length:
        return False
    ri = tuple(o + s * d for o, d in zip(emitter, e))  # eq. 4
    dr = tuple(a - b for a, b in zip(ri, rc))  # eq. 5
    return math.sqrt(sum(d * d for d in dr)) < wafer.radius


def wafer_bounds(wafer):
    """Axis-aligned bounds of the wafer solid: ((xmin, ymin, zmin), (xmax, ymax, zmax)).

    >>> from waferscan.core.model import Wafer
    >>> wafer_bounds(Wafer("W1", (0.0, 0.0, 300.0), (0.0, 0.0, 1.0), 300.0, 0.775))
    ((-150.0, -150.0, 300.0), (150.0, 150.0, 300.775))
    """
    mid = wafer.mid_center
    half = []
    for k in wafer.normal:
        # A bowed wafer reaches |bow| further along its normal, either way (bounds only grow).
        half.append(wafer.radius * math.sqrt(max(0.0, 1.0 - k * k))
                    + (0.5 * wafer.thickness + abs(wafer.bow)) * abs(k))
    return (tuple(m - h for m, h in zip(mid, half)), tuple(m + h for m, h in zip(mid, half)))


def _distance_to_segment_xy(point, a, b):
    px, py = point[0] - a[0], point[1] - a[1]
    dx, dy = b[0] - a[0], b[1] - a[1]
    dd = dx * dx + dy * dy
    f = 0.0 if dd == 0.0 else min(1.0, max(0.0, (px * dx + py * dy) / dd))
    return math.hypot(px - f * dx, py - f * dy)


def accessible(layout, wafer, z_from, z_to, tol=TOUCH_TOLERANCE):
    """The paper's accessibility check: can the beam, swept from scan position z_from to z_to,
    reach the wafer at all? Looks at the XY plane and at Z separately, with bounds that only
    ever over-estimate the reach, so a wafer the beam can hit is never dropped."""
    beam = layout.beam
    lo_z, hi_z = min(z_from, z_to), max(z_from, z_to)
    (_, _, wz0), (_, _, wz1) = wafer_bounds(wafer)
    margin = 10.0 * tol
    # Z: the emitter's z is the scan position; the receiver is length*ez above or below it.
    rise = beam.length * beam.direction[2]
    if hi_z + max(0.0, rise) < wz0 - margin or lo_z + min(0.0, rise) > wz1 + margin:
        return False
    # XY: distance from the wafer's centre to the beam's footprint at the start, less the
    # sideways drift of a tilted lift axis over the whole travel.
    start = layout.emitter_at(lo_z)
    end = tuple(o + beam.length * d for o, d in zip(start, beam.direction))
    mid = wafer.mid_center
    nx, ny, _ = wafer.normal
    # Every point of the solid is mid + (in-plane part, |.| <= R) + (along n, |.| <= t/2).
    reach_xy = wafer.radius + (0.5 * wafer.thickness + abs(wafer.bow)) * math.hypot(nx, ny)
    ax, ay, az = layout.lift_axis
    drift = math.hypot(ax, ay) / az * (hi_z - lo_z)
    return _distance_to_segment_xy(mid, start, end) <= reach_xy + drift + margin


LEVEL = (0.0, 0.0, 1.0)  # a level wafer's normal
# How much wider (mm) ``accessible_wafers``' box around the beam is than the beam: far above the
# rounding of coordinates under a few metres (1e-12 mm), so that the box leaves out only what
# the exact distance test would.
PRE_REJECT_SLACK = 1e-6


def sweep_reach(layout, z_from, z_to, tol=TOUCH_TOLERANCE):
    """What ``accessible`` reads of the beam swept from scan position z_from to z_to, worked out
    once for all wafers (``accessible_wafers``, and the analytic engine's level loop): (margin,
    z_top, z_bottom, sx, sy, dx, dy, dd, drift, x_low, x_high, y_low, y_high). The beam's
    footprint at the start runs from (sx, sy) by (dx, dy), dd = dx² + dy²; the box
    [x_low, x_high] x [y_low, y_high] holds it: a level wafer whose centre is further from the
    box, in X or Y alone, than its reach (and far more than any rounding) cannot pass the
    distance test, and is left out with two subtractions (a fab's other carriers)."""
    beam = layout.beam
    lo_z, hi_z = min(z_from, z_to), max(z_from, z_to)
    margin = 10.0 * tol
    rise = beam.length * beam.direction[2]
    z_top, z_bottom = hi_z + max(0.0, rise), lo_z + min(0.0, rise)
    sx, sy, sz = layout.emitter_at(lo_z)
    ex, ey = sx + beam.length * beam.direction[0], sy + beam.length * beam.direction[1]
    dx, dy = ex - sx, ey - sy
    dd = dx * dx + dy * dy
    ax, ay, az = layout.lift_axis
    drift = math.hypot(ax, ay) / az * (hi_z - lo_z)
    x_low, x_high = min(sx, ex) - PRE_REJECT_SLACK, max(sx, ex) + PRE_REJECT_SLACK
    y_low, y_high = min(sy, ey) - PRE_REJECT_SLACK, max(sy, ey) + PRE_REJECT_SLACK
    return (margin, z_top, z_bottom, sx, sy, dx, dy, dd, drift, x_low, x_high, y_low, y_high)


def level_near(reach, cx, cy, diameter):
    """``accessible``'s test in X and Y of a level wafer centred at (cx, cy) against the beam
    swept as ``reach`` (``sweep_reach``) says: first the box about the beam's footprint, then the
    distance to it. (A level wafer passes ``accessible`` when this and its Z test pass.)"""
    margin, _, _, sx, sy, dx, dy, dd, drift, x_low, x_high, y_low, y_high = reach
    bound = (diameter / 2.0 + drift) + margin
    if cx - x_high > bound or x_low - cx > bound or cy - y_high > bound or y_low - cy > bound:
        return False
    # The general lines of accessible_wafers with n = (0, 0, 1), which give these values exactly
    # (h*0 = 0, x + 0 = x, radius*sqrt(0) = 0, x*1 = x).
    px, py = cx - sx, cy - sy
    along = 0.0 if dd == 0.0 else (px * dx + py * dy) / dd
    along = along if along > 0.0 else 0.0
    f = along if along < 1.0 else 1.0
    return math.hypot(px - f * dx, py - f * dy) <= bound


def accessible_wafers(layout, wafers, z_from, z_to, tol=TOUCH_TOLERANCE):
    """Indices of the ``wafers`` that pass ``accessible(layout, wafer, z_from, z_to)``: the same
    bounds in the same arithmetic, so the same answers, with what depends on the beam alone
    worked out once instead of once per wafer (``sweep_reach``)."""
    reach = sweep_reach(layout, z_from, z_to, tol)
    margin, z_top, z_bottom, sx, sy, dx, dy, dd, drift = reach[:9]
    hypot, sqrt = math.hypot, math.sqrt
    found = []
    # The last level wafer's normal, centre X and Y and diameter (the objects), and whether it
    # passed the XY test, which depends on these alone: a carrier's seated wafers share them
    # (a scenario's are made from the carrier's numbers), and the next wafer with the same
    # objects, so the same numbers bit for bit, takes its answer without the arithmetic.
    same_normal = same_x = same_y = same_diameter = None
    near = False
    for index, wafer in enumerate(wafers):
        (cx, cy, cz), normal, diameter = wafer.center, wafer.normal, wafer.diameter
        if normal is same_normal and cx is same_x and cy is same_y and diameter is same_diameter:
            if not near:
                continue
        elif normal == LEVEL:
            # A level wafer (most of a fab's): XY first, which leaves out most of a fab's
            # wafers (those of the other carriers) before their thickness and bow are read.
            # Both tests must pass: their order changes no answer.
            same_normal, same_x, same_y, same_diameter = normal, cx, cy, diameter
            near = level_near(reach, cx, cy, diameter)
            if not near:
                continue
        else:
            thickness = wafer.thickness
            radius = diameter / 2.0  # wafer.radius, without the property's call
            h = thickness / 2.0
            nx, ny, nz = normal
            bow = abs(wafer.bow)  # 0 but for a bowed wafer (SPEC §10), which reaches further
            mid_z = cz + h * nz
            half_z = radius * sqrt(max(0.0, 1.0 - nz * nz)) + (0.5 * thickness + bow) * abs(nz)
            if z_top < (mid_z - half_z) - margin or z_bottom > (mid_z + half_z) + margin:
                continue
            px, py = (cx + h * nx) - sx, (cy + h * ny) - sy
            reach_xy = radius + (0.5 * thickness + bow) * hypot(nx, ny)
            # min(1, max(0, along)) as comparisons (the same choices, ties and NaN included),
            # as this runs for every wafer at the beam's height.
            along = 0.0 if dd == 0.0 else (px * dx + py * dy) / dd
            along = along if along > 0.0 else 0.0
            f = along if along < 1.0 else 1.0
            if hypot(px - f * dx, py - f * dy) <= reach_xy + drift + margin:
                found.append(index)
            continue
        # A level wafer whose XY passed: Z
        thickness = wafer.thickness
        mid_z = cz + thickness / 2.0
        half_z = 0.5 * thickness + abs(wafer.bow)
        if z_top < (mid_z - half_z) - margin or z_bottom > (mid_z + half_z) + margin:
            continue
        found.append(index)
    return found
