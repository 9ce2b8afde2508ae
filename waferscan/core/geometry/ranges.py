"""The closed-form range of lift translations over which a beam meets a wafer, once for one
wafer (``translation_range``, on Python floats) and once over arrays of wafers
(``translation_ranges``, numpy): the same expressions in the same order, so that where the array
form answers it gives the scalar function's floats bit for bit (tests/core/test_translation_ranges.py
holds them so), and where it cannot promise that it says so and the caller asks the scalar one.

The points emitter + lam*e + tau*axis, 0 <= lam <= L, that lie in the (convex) wafer form a convex
region of the (lam, tau) plane bounded by straight lines (the beam's ends, the two faces) and by a
conic (the rim). A linear function's extremes over such a region lie at a corner of two
boundaries, where a line crosses the conic, or where the conic is tangent to a line tau = const.
A level wafer lifted along its axis is a rectangle (its faces bound tau, its rim lam); a level
bowed wafer's range is its bottom's lowest and its top's highest point over the beam's chord
(core/geometry/bow.py).
"""

from __future__ import annotations

import math

from .beam import TOUCH_TOLERANCE, ArrayOps, rim_roots, rim_span
from .bow import bowed_translation_range, bowed_translation_ranges

__all__ = ["merged_ranges", "translation_range", "translation_ranges"]

# Where |det| of two boundary lines lies within this relative distance of ``_solve_lines``'s
# parallel test (1e-14 times the lines' norms, taken with math.hypot, which np.hypot may miss by
# the last bit), the array form leaves the wafer to the scalar function.
EDGE_OF_PARALLEL = 1e-9
# The feasibility test's slack (mm) for rounding, in both forms.
SLACK = 1e-9


def _dot(a, b):
    """a.b of 3-vectors of floats or of numpy arrays alike."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross_norm2(a, b):
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    z = a[0] * b[1] - a[1] * b[0]
    return x * x + y * y + z * z


def _solve_lines(l1, l2):
    a1, b1, c1 = l1
    a2, b2, c2 = l2
    det = a1 * b2 - a2 * b1
    scale = math.hypot(a1, b1) * math.hypot(a2, b2)
    if scale == 0.0 or abs(det) <= 1e-14 * scale:
        return None
    return ((c1 * b2 - c2 * b1) / det, (a1 * c2 - a2 * c1) / det)


def _line_meets_circle(line, p, q, g, r2):
    """Points (lam, tau) of the line alpha*lam + beta*tau = gamma where |p + lam q + tau g| = r."""
    alpha, beta, gamma = line
    nn = alpha * alpha + beta * beta
    if nn == 0.0:
        return []
    lam0, tau0 = gamma * alpha / nn, gamma * beta / nn
    dlam, dtau = -beta, alpha
    p0 = tuple(pi + lam0 * qi + tau0 * gi for pi, qi, gi in zip(p, q, g))
    v = tuple(dlam * qi + dtau * gi for qi, gi in zip(q, g))
    vv = _dot(v, v)
    if vv == 0.0:
        return []
    pv = _dot(p0, v)
    c = _dot(p0, p0) - r2
    disc = pv * pv - vv * c
    if disc < 0.0:
        return []
    root = math.sqrt(disc)
    return [(lam0 + s * dlam, tau0 + s * dtau) for s in ((-pv - root) / vv, (-pv + root) / vv)]


def _frame(emitter, direction, center, normal, axis):
    """The beam and the lift in the wafer's frame, for floats and numpy arrays alike (each
    argument a 3-tuple of floats or of arrays): with w the emitter's offset from the centre, e
    the beam's direction, a the lift axis and n the normal, (w.n, e.n, a.n, p, q, g) where p,
    q and g are w, e and a across the normal. Scalars, not generators: this runs once per
    wafer of every analytic scan."""
    ox, oy, oz = emitter
    ex, ey, ez = direction
    cx, cy, cz = center
    nx, ny, nz = normal
    ax, ay, az = axis
    wx, wy, wz = ox - cx, oy - cy, oz - cz
    wn = wx * nx + wy * ny + wz * nz
    en = ex * nx + ey * ny + ez * nz
    an = ax * nx + ay * ny + az * nz
    return (wn, en, an, (wx - wn * nx, wy - wn * ny, wz - wn * nz),
            (ex - en * nx, ey - en * ny, ez - en * nz), (ax - an * nx, ay - an * ny, az - an * nz))


def translation_range(emitter, beam, axis, wafer, tol=TOUCH_TOLERANCE):
    """Closed form: the range [tau_lo, tau_hi] of translations tau along ``axis`` (a unit vector)
    for which the beam moved to ``emitter + tau*axis`` meets the wafer; None if there is none.

    The points emitter + lam*e + tau*axis, 0 <= lam <= L, that lie in the (convex) wafer form a
    convex region of the (lam, tau) plane bounded by straight lines (the beam's ends, the two
    faces) and by a conic (the rim). A linear function's extremes over such a region lie at a
    corner of two boundaries, where a line crosses the conic, or where the conic is tangent to a
    line tau = const; all those candidates are listed and the feasible ones kept.

    A level beam 1 mm below a level wafer's bottom face, lifted straight up, meets the wafer
    from 1 mm to 1.775 mm of travel (grown by the touching tolerance, 1e-9 mm, each way):

    >>> from waferscan.core.model import Beam, Wafer
    >>> wafer = Wafer("W1", (0.0, 0.0, 300.0), (0.0, 0.0, 1.0), 300.0, 0.775)
    >>> beam = Beam((-200.0, 0.0, 299.0), (1.0, 0.0, 0.0), 400.0)
    >>> low, high = translation_range(beam.emitter, beam, (0.0, 0.0, 1.0), wafer)
    >>> round(low, 6), round(high, 6)
    (1.0, 1.775)
    """
    if wafer.bow:
        # SPEC §10; the flat range (of the flat wafer holding the bowed one) is this function's,
        # given to bow.py so that it need not import this module.
        return bowed_translation_range(emitter, beam, axis, wafer, tol, translation_range)
    wn, en, an, p, q, g = _frame(emitter, beam.direction, wafer.center, wafer.normal, axis)
    r = wafer.radius + tol
    r2 = r * r
    t = wafer.thickness

    if en == 0.0 and an != 0.0 and g[0] == 0.0 and g[1] == 0.0 and g[2] == 0.0:
        return _level_wafer_range(wn, an, p, q, r2, t, beam.length, tol)
    bounds = _boundary_lines(wn, en, an, p, q, g, r2, t, beam.length, tol)
    if bounds is None:
        return None
    lines, conic = bounds
    candidates = _corner_candidates(lines, conic, p, q, g, r2)
    return _feasible_range(candidates, wn, en, an, p, q, g, r, r2, t, beam.length, tol)


def _level_wafer_range(wn, an, p, q, r2, t, length, tol):
    """``translation_range``'s common case: a level wafer, the beam parallel to its faces, the
    lift along its axis (an = axis.n != 0, nothing of the axis across the normal). The region is
    a rectangle: the faces bound tau, the rim bounds lam alone. p and q: the emitter's offset and
    the beam's direction across the normal; r2 the inflated radius squared."""
    px, py, pz = p
    qx, qy, qz = q
    span = rim_span(qx * qx + qy * qy + qz * qz, px * qx + py * qy + pz * qz,
                     px * px + py * py + pz * pz - r2)
    if span is None or span[1] < -tol or span[0] > length + tol:
        return None
    low, high = (-tol - wn) / an, (t + tol - wn) / an
    return (min(low, high), max(low, high))


def _boundary_lines(wn, en, an, p, q, g, r2, t, length, tol):
    """The straight boundaries of ``translation_range``'s (lam, tau) region, as lines
    alpha*lam + beta*tau = gamma: the beam's two ends, the two faces (unless the beam and the
    axis both run along them), and the rim when it degenerates to two parallel lines. Returns
    (lines, conic), conic True when the rim is a true conic still to be intersected; None when
    the region is empty. p, q, g: the emitter's offset, the beam's direction and the axis across
    the normal; wn, en, an their parts along it."""
    lines = [(1.0, 0.0, -tol), (1.0, 0.0, length + tol)]
    if en == 0.0 and an == 0.0:
        if not -tol <= wn <= t + tol:
            return None
    else:
        lines += [(en, an, -tol - wn), (en, an, t + tol - wn)]

    qq, gg = _dot(q, q), _dot(g, g)
    conic = False
    if qq == 0.0 and gg == 0.0:
        if _dot(p, p) > r2:
            return None
    elif _cross_norm2(q, g) <= 1e-20 * qq * gg:
        # Beam and axis cross the normal along one line: the rim bounds one combination
        # m = lam*qu + tau*gu between two roots, i.e. two parallel lines.
        big = q if qq >= gg else g
        norm = math.sqrt(_dot(big, big))
        u = tuple(b / norm for b in big)
        qu, gu, pu = _dot(q, u), _dot(g, u), _dot(p, u)
        disc = pu * pu - (_dot(p, p) - r2)
        if disc < 0.0:
            return None
        root = math.sqrt(disc)
        lines += [(qu, gu, -pu - root), (qu, gu, -pu + root)]
    else:
        conic = True
    return lines, conic


def _corner_candidates(lines, conic, p, q, g, r2):
    """The points (lam, tau) where the region's extremes in tau may lie: every crossing of two
    boundary lines and, when the rim is a conic, where each line crosses it and where it is
    tangent to a line tau = const."""
    candidates = []
    for i, first in enumerate(lines):
        a1, b1 = first[0], first[1]
        for second in lines[i + 1:]:
            # Two lines of one direction (the beam's ends, the faces, the rim's two), or two with
            # beta 0 (the beam's ends and a rim along the beam): det is exactly 0 (or NaN, never
            # feasible), never a corner; _solve_lines is not asked.
            if (second[0] == a1 and second[1] == b1) or (b1 == 0.0 and second[1] == 0.0):
                continue
            point = _solve_lines(first, second)
            if point is not None:
                candidates.append(point)
    if conic:
        for line in lines:
            candidates += _line_meets_circle(line, p, q, g, r2)
        # Where the rim is tangent to tau = const: d/dlam |p + lam q + tau g|^2 = 0.
        candidates += _line_meets_circle((_dot(q, q), _dot(q, g), -_dot(q, p)), p, q, g, r2)
    return candidates


def _feasible_range(candidates, wn, en, an, p, q, g, r, r2, t, length, tol):
    """(lowest, highest) tau among the candidates that lie in the region (on the beam, between
    the faces, within the rim, each with 1e-9 mm of slack for rounding); None if none does."""
    slack = SLACK
    low, lam_high, h_high = -tol - slack, length + tol + slack, t + tol + slack
    rim = r2 + 2.0 * r * slack
    px, py, pz = p
    qx, qy, qz = q
    gx, gy, gz = g
    feasible = []
    for lam, tau in candidates:
        if not low <= lam <= lam_high:
            continue
        h = wn + lam * en + tau * an
        if not low <= h <= h_high:
            continue
        # |p + lam q + tau g|^2, term by term in _dot's order (this runs for every corner of
        # every tilted wafer of an analytic scan)
        x, y, z = px + lam * qx + tau * gx, py + lam * qy + tau * gy, pz + lam * qz + tau * gz
        if x * x + y * y + z * z > rim:
            continue
        feasible.append(tau)
    if not feasible:
        return None
    return (min(feasible), max(feasible))


def merged_ranges(ranges):
    """The union of closed intervals (low, high): a sorted list of disjoint ones, those that
    overlap or touch joined."""
    out = []
    for low, high in sorted(ranges):
        if out and low <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], high))
        else:
            out.append((low, high))
    return out


# --- over arrays -------------------------------------------------------------------------------

def translation_ranges(emitter, direction, axis, center, normal, radius, thickness, length, tol,
                       bow=None):
    """``translation_range`` over n wafers at once (numpy).

    ``emitter`` is one point or (n, 3), ``direction``, ``center`` and ``normal`` (n, 3) arrays,
    ``radius``, ``thickness`` and ``bow`` (n,) in mm (``bow`` None: every wafer flat), ``axis``
    a unit 3-tuple, ``length`` and ``tol`` floats (mm). Returns (lo, hi, hit, covered), each
    (n,): where ``covered``, ``hit`` says whether the beam meets the wafer and (lo, hi) is then
    ``translation_range``'s answer bit for bit; where not covered (a tilted bowed wafer, the
    degenerate rims, a pair of boundary lines on the edge of the parallel test) the caller asks
    the scalar function.
    """
    import numpy as np

    emitter = np.asarray(emitter, dtype=float)
    if emitter.ndim == 1:
        emitter = tuple(float(v) for v in emitter)
    else:
        emitter = (emitter[:, 0], emitter[:, 1], emitter[:, 2])
    n = len(center)
    lo = np.full(n, np.nan)
    hi = np.full(n, np.nan)
    hit = np.zeros(n, dtype=bool)
    covered = np.zeros(n, dtype=bool)
    if n == 0:
        return lo, hi, hit, covered
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        wn, en, an, p, q, g = _frame(emitter, tuple(direction.T), tuple(center.T),
                                     tuple(normal.T), axis)
        (qx, qy, qz), (gx, gy, gz) = q, g
        r = radius + tol
        r2 = r * r
        t = thickness
        flat = np.ones(n, dtype=bool) if bow is None else bow == 0.0
        qq, gg = _dot(q, q), _dot(g, g)

        # A level wafer lifted along its axis (_level_wafer_range): the faces bound tau, the rim
        # lam alone (rim_span over arrays).
        level = flat & (en == 0.0) & (an != 0.0) & (gx == 0.0) & (gy == 0.0) & (gz == 0.0)
        if level.any():
            rows = _rows(level)
            pq = _dot(p, q)[rows]
            qqr = qq[rows]
            c = _dot(p, p)[rows] - r2[rows]
            disc = pq * pq - qqr * c
            span_lo, span_hi = rim_roots(qqr, pq, c, np.maximum(disc, 0.0), ArrayOps(np))
            along = qqr == 0.0
            span_lo = np.where(along, -np.inf, span_lo)
            span_hi = np.where(along, np.inf, span_hi)
            meets = np.where(along, ~(c > 0.0), ~(disc < 0.0))
            meets &= ~((span_hi < -tol) | (span_lo > length + tol))
            low = (-tol - wn[rows]) / an[rows]
            high = (t[rows] + tol - wn[rows]) / an[rows]
            lo[rows], hi[rows] = np.minimum(low, high), np.maximum(low, high)
            hit[rows] = meets
            covered[rows] = True

        # A level bowed wafer lifted along its normal (bow.bowed_translation_ranges).
        bowed = ~flat & (an != 0.0) & (gg <= 1e-24)
        if bowed.any():
            rows = _rows(bowed)
            lo[rows], hi[rows], hit[rows] = bowed_translation_ranges(
                wn[rows], en[rows], an[rows], tuple(x[rows] for x in p),
                tuple(x[rows] for x in q), radius[rows], t[rows], bow[rows], length, tol)
            covered[rows] = True

        # A level wafer lifted along its axis, the beam tilted out of its faces (a sweep's
        # [beam_tilt]): the general region's corners, worked out without its zero terms.
        slanted = (flat & (en != 0.0) & (an != 0.0) & (qq != 0.0)
                   & (gx == 0.0) & (gy == 0.0) & (gz == 0.0))
        # Where most rows are slanted (a sweep's, nearly all), worked out over every row and
        # kept where slanted: the other rows' answers (nan, inf, whatever) cost less than
        # gathering a dozen columns of the slanted ones. A few are gathered.
        count = np.count_nonzero(slanted)
        if count:
            rows = slice(None) if 4 * count >= n else np.flatnonzero(slanted)
            edge, low, high, empty = _slanted_extremes(
                wn[rows], en[rows], an[rows], tuple(x[rows] for x in p),
                tuple(x[rows] for x in q), r[rows], r2[rows], t[rows], length, tol)
            for out, value in ((lo, low), (hi, high), (hit, (low <= high) & ~empty),
                               (covered, ~edge)):
                if isinstance(rows, slice):
                    np.copyto(out, value, where=slanted)
                else:
                    out[rows] = value

        # The general region (_boundary_lines, _corner_candidates, _feasible_range), but for its
        # degenerate cases (beam and axis both along the faces, or both without a part across
        # the normal), which the scalar function takes.
        general = (flat & ~level & ~slanted & ~((en == 0.0) & (an == 0.0))
                   & ~((qq == 0.0) & (gg == 0.0)))
        if general.any():  # (none in a sweep of level wafers)
            cross = ((qy * gz - qz * gy) ** 2 + (qz * gx - qx * gz) ** 2
                     + (qx * gy - qy * gx) ** 2)
            # Beam and axis across the normal along one line: the rim is two parallel lines
            # m = lam*qu + tau*gu between two roots; elsewhere a conic.
            parallel = cross <= 1e-20 * qq * gg
            for rows, rim_lines in ((np.flatnonzero(general & parallel), True),
                                    (np.flatnonzero(general & ~parallel), False)):
                if not len(rows):
                    continue
                pr, qr, gr = (tuple(x[rows] for x in v) for v in (p, q, g))
                rim = None
                empty = np.zeros(len(rows), dtype=bool)
                if rim_lines:
                    qqr, ggr = qq[rows], gg[rows]
                    big = tuple(np.where(qqr >= ggr, qi, gi) for qi, gi in zip(qr, gr))
                    norm = np.sqrt(_dot(big, big))
                    unit = tuple(b / norm for b in big)
                    qu, gu, pu = _dot(qr, unit), _dot(gr, unit), _dot(pr, unit)
                    disc = pu * pu - (_dot(pr, pr) - r2[rows])
                    empty = disc < 0.0
                    rim = (qu, gu, pu, np.sqrt(np.maximum(disc, 0.0)))
                edge, low, high = _extremes(wn[rows], en[rows], an[rows], pr, qr, gr, r[rows],
                                            r2[rows], t[rows], length, tol, rim)
                lo[rows], hi[rows] = low, high
                hit[rows] = (low <= high) & ~empty
                covered[rows] = ~edge
    hit &= covered
    return lo, hi, hit, covered


def _rows(mask):
    """The rows where ``mask`` holds, for indexing: all of them as a slice (views, not
    copies, of the columns: a sweep's wafers are commonly all of one kind)."""
    import numpy as np

    rows = np.flatnonzero(mask)
    return slice(None) if len(rows) == len(mask) else rows


def _slanted_extremes(wn, en, an, p, q, r, r2, t, length, tol):
    """``_extremes`` over rows of level wafers lifted along their axis (g = 0) with the beam
    out of their faces (en != 0): the rim is the two lines lam*qu = -pu -+ root, parallel to
    the beam's ends, so the corners are the beam's ends and the rim's lines on each face. The
    same floats as ``_extremes``: each term it multiplies by g's zeros or by the beam's ends'
    (1, 0) is left out where leaving it out is exact (x*1 = x, x - (+-0) = x for x != 0,
    hypot(x, +-0) = |x|, and a quotient's two signs cancel exactly). Returns (edge, lo, hi,
    empty): ``empty`` where the beam's line misses the rim."""
    import numpy as np

    qq = _dot(q, q)
    norm = np.sqrt(qq)
    unit = tuple(b / norm for b in q)
    qu, pu = _dot(q, unit), _dot(p, unit)
    disc = pu * pu - (_dot(p, p) - r2)
    empty = disc < 0.0
    root = np.sqrt(np.maximum(disc, 0.0))
    faces = (-tol - wn, t + tol - wn)
    hyp = np.hypot(en, an)
    # The beam's ends against the faces: det = 1*an - en*0 = an.
    limit = 1e-14 * hyp
    edge = np.abs(np.abs(an) - limit) <= EDGE_OF_PARALLEL * limit
    valid = ~((hyp == 0.0) | (np.abs(an) <= limit))
    # Each line across the faces gives both faces one lam: what depends on lam alone (on the
    # beam, within the rim, wn + lam*en) is worked out once a line (_reach), not once a corner.
    lam_range = (-tol - SLACK, length + tol + SLACK)
    rim_limit = r2 + 2.0 * r * SLACK
    ends = [(end, _reach((end * an) / an, valid, wn, en, p, q, rim_limit, lam_range))
            for end in (-tol, length + tol)]
    candidates = [((face - en * end) / an, reach) for end, reach in ends for face in faces]
    # The faces against the rim's lines: det = en*0 - qu*an = -(qu*an).
    det = -(qu * an)
    limit = 1e-14 * (hyp * np.abs(qu))
    edge |= np.abs(np.abs(det) - limit) <= EDGE_OF_PARALLEL * limit
    valid = ~((hyp * np.abs(qu) == 0.0) | (np.abs(det) <= limit))
    rims = [(rim, _reach((rim * an) / (qu * an), valid, wn, en, p, q, rim_limit, lam_range))
            for rim in (-pu - root, -pu + root)]
    candidates += [((en * rim - qu * face) / det, reach) for face in faces for rim, reach in rims]
    # _feasible_range, with x = p + lam*q (tau*g is a zero); lo and hi taken in the same
    # order of candidates, in place.
    lo = np.full(wn.shape, np.inf)
    hi = np.full(wn.shape, -np.inf)
    h_lo, h_hi = -tol - SLACK, t + tol + SLACK
    for tau, (ok, base) in candidates:
        h = base + tau * an
        ok = ok & (h_lo <= h) & (h <= h_hi)
        np.minimum(lo, tau, out=lo, where=ok)
        np.maximum(hi, tau, out=hi, where=ok)
    return edge, lo, hi, empty


def _reach(lam, valid, wn, en, p, q, rim_limit, lam_range):
    """(ok, base) for ``_slanted_extremes``' corners on one line of lam: ok where the line's
    corners are ``valid``, lam lies in ``lam_range`` (the beam, with ``_feasible_range``'s
    slack) and p + lam*q within the rim (|x|^2 <= rim_limit); base = wn + lam*en, the first sum
    of a corner's height over the bottom face."""
    px, py, pz = p
    qx, qy, qz = q
    x, y, z = px + lam * qx, py + lam * qy, pz + lam * qz
    ok = valid & (lam_range[0] <= lam) & (lam <= lam_range[1])
    ok &= ~(x * x + y * y + z * z > rim_limit)
    return ok, wn + lam * en


def _extremes(wn, en, an, p, q, g, r, r2, t, length, tol, rim):
    """The general region's corner candidates and feasible extremes in tau over rows of one
    kind: ``rim`` (qu, gu, pu, root) where the rim is two parallel lines, None where it is a
    conic. Returns (edge, lo, hi): ``edge`` where the parallel test of two lines is too close to
    call; lo > hi where no candidate is feasible."""
    import numpy as np

    one, zero = np.ones_like(wn), np.zeros_like(wn)
    lines = [(one, zero, np.full(wn.shape, -tol)), (one, zero, np.full(wn.shape, length + tol)),
             (en, an, -tol - wn), (en, an, t + tol - wn)]
    if rim is not None:
        qu, gu, pu, root = rim
        lines += [(qu, gu, -pu - root), (qu, gu, -pu + root)]
    edge = np.zeros(wn.shape, dtype=bool)
    candidates = []
    # The lines come in pairs of one direction (the beam's ends, the faces, the rim's two): such
    # a pair's det is a product less itself, exactly 0, never a corner. A beam's end and a rim
    # line are parallel too where gu = 0 (a level wafer lifted along its axis).
    family = (0, 0, 1, 1, 2, 2)
    rim_along_beam = rim is not None and not np.any(rim[1])
    for i, (a1, b1, c1) in enumerate(lines):
        for j in range(i + 1, len(lines)):
            if family[i] == family[j] or (rim_along_beam and family[i] == 0 and family[j] == 2):
                continue
            a2, b2, c2 = lines[j]
            # _solve_lines
            det = a1 * b2 - a2 * b1
            scale = np.hypot(a1, b1) * np.hypot(a2, b2)
            limit = 1e-14 * scale
            edge |= np.abs(np.abs(det) - limit) <= EDGE_OF_PARALLEL * limit
            valid = ~((scale == 0.0) | (np.abs(det) <= limit))
            candidates.append(((c1 * b2 - c2 * b1) / det, (a1 * c2 - a2 * c1) / det, valid))
    if rim is None:
        tangent = (_dot(q, q), _dot(q, g), -_dot(q, p))
        for alpha, beta, gamma in lines + [tangent]:
            # _line_meets_circle
            nn = alpha * alpha + beta * beta
            lam0, tau0 = gamma * alpha / nn, gamma * beta / nn
            dlam, dtau = -beta, alpha
            p0 = tuple(pi + lam0 * qi + tau0 * gi for pi, qi, gi in zip(p, q, g))
            v = tuple(dlam * qi + dtau * gi for qi, gi in zip(q, g))
            vv = _dot(v, v)
            pv = _dot(p0, v)
            c = _dot(p0, p0) - r2
            disc = pv * pv - vv * c
            root = np.sqrt(np.maximum(disc, 0.0))
            valid = (nn != 0.0) & (vv != 0.0) & ~(disc < 0.0)
            for s in ((-pv - root) / vv, (-pv + root) / vv):
                candidates.append((lam0 + s * dlam, tau0 + s * dtau, valid))
    # _feasible_range
    lo = np.full(wn.shape, np.inf)
    hi = np.full(wn.shape, -np.inf)
    for lam, tau, valid in candidates:
        ok = valid & (-tol - SLACK <= lam) & (lam <= length + tol + SLACK)
        h = wn + lam * en + tau * an
        ok &= (-tol - SLACK <= h) & (h <= t + tol + SLACK)
        x = tuple(pi + lam * qi + tau * gi for pi, qi, gi in zip(p, q, g))
        ok &= ~(_dot(x, x) > r2 + 2.0 * r * SLACK)
        lo = np.where(ok, np.minimum(lo, tau), lo)
        hi = np.where(ok, np.maximum(hi, tau), hi)
    return edge, lo, hi
