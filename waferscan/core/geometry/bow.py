"""Bowed wafers (SPEC §10): the bottom surface is the paraboloid w(r) = bow (1 - r²/R²) above
the plane of the rim's bottom circle (positive bow: centre up), the top surface t above it along
the normal. The wafer's frame origin (``Wafer.center``) is the centre of that rim circle.

The solid is not convex, so the flat wafer's closed forms do not apply as they stand:

- ``beam_hits_bowed_wafer``: along the beam (parameter lam) the rim, the bottom and the top
  surface are each a quadratic inequality in lam; the beam meets the solid where all three hold
  on [0, L]. Their roots cut [0, L] into pieces on which each holds or fails throughout, so
  testing each piece's ends and middle is exact.
- ``bowed_translation_range``: when the lift moves along the wafer's normal (a seated wafer
  scanned straight up, the usual case) the chord the beam cuts through the rim stays put and
  only the height changes: the range of lift translations is the lowest bottom and highest top
  over the chord, each a quadratic in lam, in closed form. Otherwise (a tilted bowed wafer) the
  range is bracketed by sampling the exact test across the range of a flat wafer that holds the
  bowed one, and its ends are bisected to 1e-10 mm.
"""

from __future__ import annotations

import math
from dataclasses import replace

# Samples of the exact test across the hull's range when no closed form applies.
HULL_SAMPLES = 256
BISECTION_TOLERANCE = 1e-10


def _quadratic_roots(a, b, c):
    """Real roots of a x² + b x + c = 0 (a linear or constant equation when a = 0)."""
    if a == 0.0:
        return [] if b == 0.0 else [-c / b]
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return []
    s = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    roots = [s / a]
    if s != 0.0:
        roots.append(c / s)
    return roots


def _frame(emitter, direction, wafer):
    """(wn, en, p, q): the emitter's height above the rim plane and the beam's rate of climb;
    the emitter's offset and the direction across the normal."""
    ex, ey, ez = direction
    nx, ny, nz = wafer.normal
    cx, cy, cz = wafer.center
    wx, wy, wz = emitter[0] - cx, emitter[1] - cy, emitter[2] - cz
    wn = wx * nx + wy * ny + wz * nz
    en = ex * nx + ey * ny + ez * nz
    p = (wx - wn * nx, wy - wn * ny, wz - wn * nz)
    q = (ex - en * nx, ey - en * ny, ez - en * nz)
    return wn, en, p, q


def beam_hits_bowed_wafer(emitter, beam, wafer, tol=1e-9):
    """True when the segment [emitter, emitter + L e] meets the bowed wafer solid, grown by
    ``tol`` (the rim by tol, the surfaces by tol along the normal)."""
    wn, en, p, q = _frame(emitter, beam.direction, wafer)
    pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
    pq = p[0] * q[0] + p[1] * q[1] + p[2] * q[2]
    qq = q[0] * q[0] + q[1] * q[1] + q[2] * q[2]
    radius = wafer.radius
    k = wafer.bow / (radius * radius)
    r = radius + tol
    # Rim: qq lam² + 2 pq lam + pp - r² <= 0.
    rim = (qq, 2.0 * pq, pp - r * r)
    # Above the bottom: wn + lam en - bow + k |rho|² + tol >= 0.
    bottom = (k * qq, 2.0 * k * pq + en, k * pp + wn - wafer.bow + tol)
    # Below the top: bow + t - k |rho|² + tol - wn - lam en >= 0.
    top = (-k * qq, -2.0 * k * pq - en, wafer.bow + wafer.thickness - k * pp + tol - wn)
    lo, hi = -tol, beam.length + tol
    cuts = {lo, hi}
    for a, b, c in (rim, bottom, top):
        cuts.update(x for x in _quadratic_roots(a, b, c) if lo < x < hi)
    points = sorted(cuts)
    candidates = points + [0.5 * (a + b) for a, b in zip(points, points[1:])]
    slack = 1e-12
    for lam in candidates:
        if (rim[0] * lam + rim[1]) * lam + rim[2] > slack * r * r:
            continue
        if (bottom[0] * lam + bottom[1]) * lam + bottom[2] < -slack:
            continue
        if (top[0] * lam + top[1]) * lam + top[2] < -slack:
            continue
        return True
    return False


def _chord(p, q, pp, pq, qq, r, length, tol):
    """The lam interval of the beam segment within the rim (radius r), or None."""
    lo, hi = -tol, length + tol
    if qq == 0.0:
        return (lo, hi) if pp <= r * r else None
    disc = pq * pq - qq * (pp - r * r)
    if disc < 0.0:
        return None
    root = math.sqrt(disc)
    a, b = (-pq - root) / qq, (-pq + root) / qq
    lo, hi = max(lo, a), min(hi, b)
    return (lo, hi) if lo <= hi else None


def _extremes(a, b, c, lo, hi):
    """(min, max) of a x² + b x + c over [lo, hi]."""
    values = [(a * lo + b) * lo + c, (a * hi + b) * hi + c]
    if a != 0.0:
        vertex = -b / (2.0 * a)
        if lo < vertex < hi:
            values.append((a * vertex + b) * vertex + c)
    return min(values), max(values)


def bowed_translation_range(emitter, beam, axis, wafer, tol, flat_range):
    """The range [tau_lo, tau_hi] of translations along the unit ``axis`` over which the beam
    meets the bowed wafer, or None. ``flat_range`` is geometry.translation_range (for the flat
    wafer that holds the bowed one, when the range is not closed form)."""
    wn, en, p, q = _frame(emitter, beam.direction, wafer)
    nx, ny, nz = wafer.normal
    ax, ay, az = axis
    an = ax * nx + ay * ny + az * nz
    g = (ax - an * nx, ay - an * ny, az - an * nz)
    if an != 0.0 and g[0] * g[0] + g[1] * g[1] + g[2] * g[2] <= 1e-24:
        pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
        pq = p[0] * q[0] + p[1] * q[1] + p[2] * q[2]
        qq = q[0] * q[0] + q[1] * q[1] + q[2] * q[2]
        radius = wafer.radius
        chord = _chord(p, q, pp, pq, qq, radius + tol, beam.length, tol)
        if chord is None:
            return None
        k = wafer.bow / (radius * radius)
        # Height of the bottom surface above the emitter's, less the beam's climb, per lam:
        # bow - k |p + lam q|² - tol - wn - lam en = A lam² + B lam + C.
        a = -k * qq
        b = -2.0 * k * pq - en
        c = wafer.bow - k * pp - tol - wn
        low = _extremes(a, b, c, *chord)
        high = _extremes(a, b, c + wafer.thickness + 2.0 * tol, *chord)
        if an > 0.0:
            return (low[0] / an, high[1] / an)
        return (high[1] / an, low[0] / an)
    return _sampled_range(emitter, beam, axis, wafer, tol, flat_range)


def bowed_translation_ranges(wn, en, an, p, q, radius, thickness, bow, length, tol):
    """``bowed_translation_range``'s closed form over arrays (numpy), for level bowed wafers
    lifted along their normal: the beam's frame per wafer (wn, en, an and the offsets p, q
    across the normal, as geometry/ranges.py computes them), ``radius``, ``thickness`` and
    ``bow`` (n,) in mm. Returns (lo, hi, hit): the same floats as the scalar function where
    ``hit``."""
    import numpy as np

    px, py, pz = p
    qx, qy, qz = q
    pp = px * px + py * py + pz * pz
    pq = px * qx + py * qy + pz * qz
    qq = qx * qx + qy * qy + qz * qz
    # _chord
    r = radius + tol
    disc = pq * pq - qq * (pp - r * r)
    root = np.sqrt(np.maximum(disc, 0.0))
    a, b = (-pq - root) / qq, (-pq + root) / qq
    c_lo = np.where(qq == 0.0, -tol, np.maximum(-tol, a))
    c_hi = np.where(qq == 0.0, length + tol, np.minimum(length + tol, b))
    hit = np.where(qq == 0.0, pp <= r * r, disc >= 0.0) & (c_lo <= c_hi)
    k = bow / (radius * radius)
    qa = -k * qq
    qb = -2.0 * k * pq - en
    qc = bow - k * pp - tol - wn

    def extremes(c):
        # _extremes over arrays: the ends of the chord, and the vertex where it lies inside
        v1 = (qa * c_lo + qb) * c_lo + c
        v2 = (qa * c_hi + qb) * c_hi + c
        vertex = -qb / (2.0 * qa)
        inside = (qa != 0.0) & (c_lo < vertex) & (vertex < c_hi)
        v3 = (qa * vertex + qb) * vertex + c
        small, big = np.minimum(v1, v2), np.maximum(v1, v2)
        return np.where(inside, np.minimum(small, v3), small), \
            np.where(inside, np.maximum(big, v3), big)

    low = extremes(qc)[0]
    high = extremes(qc + thickness + 2.0 * tol)[1]
    lo = np.where(an > 0.0, low / an, high / an)
    hi = np.where(an > 0.0, high / an, low / an)
    return lo, hi, hit


def _sampled_range(emitter, beam, axis, wafer, tol, flat_range):
    bow = wafer.bow
    nx, ny, nz = wafer.normal
    # A flat wafer holding the bowed one: from min(0, bow) to max(0, bow) + t along the normal.
    shift = min(0.0, bow)
    hull = replace(wafer, center=tuple(c + shift * k for c, k in zip(wafer.center, wafer.normal)),
                   thickness=wafer.thickness + abs(bow), bow=0.0)
    span = flat_range(emitter, beam, axis, hull, tol)
    if span is None:
        return None

    def hit(tau):
        moved = tuple(o + tau * a for o, a in zip(emitter, axis))
        return beam_hits_bowed_wafer(moved, beam, wafer, tol)

    lo, hi = span
    samples = [lo + (hi - lo) * i / HULL_SAMPLES for i in range(HULL_SAMPLES + 1)]
    hits = [i for i, tau in enumerate(samples) if hit(tau)]
    if not hits:
        return None

    def bisect(miss, inside):
        while abs(inside - miss) > BISECTION_TOLERANCE:
            middle = 0.5 * (miss + inside)
            if hit(middle):
                inside = middle
            else:
                miss = middle
        return inside

    first, last = hits[0], hits[-1]
    low = samples[first] if first == 0 else bisect(samples[first - 1], samples[first])
    high = samples[last] if last == HULL_SAMPLES else bisect(samples[last + 1], samples[last])
    return (low, high)
