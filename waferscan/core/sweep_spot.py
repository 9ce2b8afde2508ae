"""A sweep with a beam spot (SPEC §12 with §10): the spot's column ranges of a whole block of
sampled layouts in numpy, then each layout through the scalar spot engine (core/sensing.py),
which finds them precomputed instead of computing them one ``translation_range`` at a time.

With a tilted beam every column of the spot (and every strip's middle column, where the spot
engine checks its limits are linear) is a general ``translation_range``: the corners of a
(lam, tau) region bounded by the beam's ends, the faces and the rim (core/geometry.py),
~40 µs each in Python, ~1,200 a layout of 25 slots. ``translation_ranges`` here is that
function over arrays with the same arithmetic in the same order, so it gives the same floats
bit for bit (tests/core/test_sweep_spot.py holds it so); where it cannot promise that (a bowed
wafer, a level wafer's closed form, the degenerate rims, a pair of lines on the edge of
``_solve_lines``'s parallel test) it says so and those ranges are left to the scalar function.

The precomputed ranges are handed to core/spot.py as a table keyed by the wafer and the
column's offset (``spot.precomputed_ranges``): a range the table lacks (a strip halved beyond
its middle column, an uncovered wafer) the spot engine computes itself. The answers are the
scalar path's by construction: the table holds only the same floats it would have computed.
"""

from __future__ import annotations

from . import spot as spot_module

# Where |det| of two boundary lines lies within this relative distance of _solve_lines's
# parallel test (1e-14 * the lines' norms, with math.hypot) the scalar function decides.
_EDGE_OF_PARALLEL = 1e-9


def translation_ranges(emitter, direction, axis, center, normal, radius, thickness, length,
                       tol):
    """``geometry.translation_range`` of flat wafers over arrays: ``emitter``, ``direction``,
    ``center`` and ``normal`` are (n, 3) arrays (or broadcast to them), ``radius`` and
    ``thickness`` (n,) in mm, ``axis`` a unit 3-tuple, ``length`` and ``tol`` floats (mm).
    Returns (lo, hi, hit, covered): where ``covered`` the range (lo, hi), or no range where
    ``hit`` is False, is the scalar function's bit for bit; elsewhere ask the scalar function."""
    import numpy as np

    ox, oy, oz = emitter[:, 0], emitter[:, 1], emitter[:, 2]
    ex, ey, ez = direction[:, 0], direction[:, 1], direction[:, 2]
    nx, ny, nz = normal[:, 0], normal[:, 1], normal[:, 2]
    cx, cy, cz = center[:, 0], center[:, 1], center[:, 2]
    ax, ay, az = axis
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # The same expressions, in the same order, as translation_range's.
        wx, wy, wz = ox - cx, oy - cy, oz - cz
        wn = wx * nx + wy * ny + wz * nz
        en = ex * nx + ey * ny + ez * nz
        an = ax * nx + ay * ny + az * nz
        px, py, pz = wx - wn * nx, wy - wn * ny, wz - wn * nz
        qx, qy, qz = ex - en * nx, ey - en * ny, ez - en * nz
        gx, gy, gz = ax - an * nx, ay - an * ny, az - an * nz
        r = radius + tol
        r2 = r * r
        t = thickness
        p, q, g = (px, py, pz), (qx, qy, qz), (gx, gy, gz)

        def dot(a, b):
            return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

        level = (en == 0.0) & (an != 0.0) & (gx == 0.0) & (gy == 0.0) & (gz == 0.0)
        qq, gg = dot(q, q), dot(g, g)
        cross_x = q[1] * g[2] - q[2] * g[1]
        cross_y = q[2] * g[0] - q[0] * g[2]
        cross_z = q[0] * g[1] - q[1] * g[0]
        cross = cross_x * cross_x + cross_y * cross_y + cross_z * cross_z
        # Covered: the general path, four boundary lines and the rim as a conic or (beam and
        # axis across the normal along one line, ``parallel``: a level wafer) two more lines.
        covered = ~level & ~((en == 0.0) & (an == 0.0)) & ~((qq == 0.0) & (gg == 0.0))
        parallel = cross <= 1e-20 * qq * gg
        # _boundary_lines's parallel rim: m = lam*qu + tau*gu between two roots.
        big = tuple(np.where(qq >= gg, qi, gi) for qi, gi in zip(q, g))
        norm = np.sqrt(dot(big, big))
        unit = tuple(b / norm for b in big)
        qu, gu, pu = dot(q, unit), dot(g, unit), dot(p, unit)
        rim_disc = pu * pu - (dot(p, p) - r2)
        empty = parallel & (rim_disc < 0.0)
        rim_root = np.sqrt(np.maximum(rim_disc, 0.0))

        one = np.ones_like(wn)
        zero = np.zeros_like(wn)
        lines = [(one, zero, np.full(wn.shape, -tol)), (one, zero, np.full(wn.shape, length + tol)),
                 (en, an, -tol - wn), (en, an, t + tol - wn),
                 (qu, gu, -pu - rim_root), (qu, gu, -pu + rim_root)]
        rows = [True, True, True, True, parallel, parallel]
        candidates = []
        for i, (a1, b1, c1) in enumerate(lines):
            for j in range(i + 1, len(lines)):
                a2, b2, c2 = lines[j]
                det = a1 * b2 - a2 * b1
                scale = np.hypot(a1, b1) * np.hypot(a2, b2)
                limit = 1e-14 * scale
                # np.hypot may differ from math.hypot in the last bit: on the test's edge the
                # scalar function decides.
                rows_ij = rows[i] & rows[j]
                covered &= ~(rows_ij & (np.abs(np.abs(det) - limit) <= _EDGE_OF_PARALLEL * limit))
                valid = ~((scale == 0.0) | (np.abs(det) <= limit)) & rows_ij
                candidates.append(((c1 * b2 - c2 * b1) / det, (a1 * c2 - a2 * c1) / det, valid))
        tangent = (dot(q, q), dot(q, g), -dot(q, p))
        for alpha, beta, gamma in lines[:4] + [tangent]:
            # _line_meets_circle
            nn = alpha * alpha + beta * beta
            lam0, tau0 = gamma * alpha / nn, gamma * beta / nn
            dlam, dtau = -beta, alpha
            p0 = tuple(pi + lam0 * qi + tau0 * gi for pi, qi, gi in zip(p, q, g))
            v = tuple(dlam * qi + dtau * gi for qi, gi in zip(q, g))
            vv = dot(v, v)
            pv = dot(p0, v)
            c = dot(p0, p0) - r2
            disc = pv * pv - vv * c
            root = np.sqrt(np.maximum(disc, 0.0))
            valid = (nn != 0.0) & (vv != 0.0) & ~(disc < 0.0) & ~parallel
            for s in ((-pv - root) / vv, (-pv + root) / vv):
                candidates.append((lam0 + s * dlam, tau0 + s * dtau, valid))
        # _feasible_range
        slack = 1e-9
        lo = np.full(wn.shape, np.inf)
        hi = np.full(wn.shape, -np.inf)
        for lam, tau, valid in candidates:
            ok = valid & (-tol - slack <= lam) & (lam <= length + tol + slack)
            h = wn + lam * en + tau * an
            ok &= (-tol - slack <= h) & (h <= t + tol + slack)
            x = tuple(pi + lam * qi + tau * gi for pi, qi, gi in zip(p, q, g))
            ok &= ~(dot(x, x) > r2 + 2.0 * r * slack)
            lo = np.where(ok, np.minimum(lo, tau), lo)
            hi = np.where(ok, np.maximum(hi, tau), hi)
    hit = (lo <= hi) & ~empty
    return lo, hi, hit, covered


def column_offsets(spot, columns=spot_module.COLUMNS):
    """The offsets s (mm) across the spot at which the spot engine asks for a column's range
    first: its columns and the middle of each strip between two (the same floats it computes)."""
    positions = spot_module._column_positions(spot, columns)
    middles = [0.5 * (positions[i] + positions[i + 1]) for i in range(columns)]
    return positions + middles


def range_table(layouts, spot, columns=spot_module.COLUMNS):
    """The centre-ray ranges (tol 0) of every flat wafer of ``layouts`` (each with its own
    beam, the same lift axis and emitter) at ``column_offsets``: {(id(wafer), id(beam), s):
    (lo, hi) or None}, only the entries the array formulas cover bit for bit."""
    import numpy as np

    offsets = column_offsets(spot, columns)
    table = {}
    if not layouts:
        return table
    axis = layouts[0].lift_axis
    rows = []  # (wafer, beam, u, direction)
    for layout in layouts:
        if layout.lift_axis != axis:
            raise ValueError("range_table: the layouts must share one lift axis")
        beam = layout.beam
        u = spot_module.spot_frame(beam.direction, axis)[0]
        for wafer in layout.wafers:
            if not wafer.bow:
                rows.append((wafer, beam, u))
    if not rows:
        return table
    n, k = len(rows), len(offsets)
    s = np.array(offsets, dtype=float)
    emit = np.array([beam.emitter for _, beam, _ in rows], dtype=float)
    u = np.array([u for _, _, u in rows], dtype=float)
    # emitter + s u, per coordinate as spot.py computes it: ox + s * u[0].
    emitter = (emit[:, None, :] + s[None, :, None] * u[:, None, :]).reshape(n * k, 3)
    direction = np.repeat(np.array([beam.direction for _, beam, _ in rows], dtype=float), k,
                          axis=0)
    center = np.repeat(np.array([w.center for w, _, _ in rows], dtype=float), k, axis=0)
    normal = np.repeat(np.array([w.normal for w, _, _ in rows], dtype=float), k, axis=0)
    radius = np.repeat(np.array([w.radius for w, _, _ in rows], dtype=float), k)
    thickness = np.repeat(np.array([w.thickness for w, _, _ in rows], dtype=float), k)
    lengths = {beam.length for _, beam, _ in rows}
    if len(lengths) != 1:
        raise ValueError("range_table: the layouts' beams must be of one length")
    lo, hi, hit, covered = translation_ranges(emitter, direction, axis, center, normal, radius,
                                              thickness, lengths.pop(), 0.0)
    lo, hi = lo.tolist(), hi.tolist()
    hit, covered = hit.tolist(), covered.tolist()
    j = 0
    for wafer, beam, _ in rows:
        w_id, b_id = id(wafer), id(beam)
        for offset in offsets:
            if covered[j]:
                table[(w_id, b_id, offset)] = (lo[j], hi[j]) if hit[j] else None
            j += 1
    return table


def spot_block(base, draws, peaks=None):
    """``sweep.scalar_block``'s answer (states, thickness, bottom; ``peaks`` as there) for a
    layout with a beam spot: the block's column ranges over arrays first (``range_table``),
    then each layout through the scalar path, which finds them there. The same answers as
    ``scalar_block``, bit for bit."""
    import numpy as np

    from .sweep import sample_layout, scalar_layout_states

    layout = base.layout
    spot = layout.spot
    m, S = draws.truth.shape
    layouts = [sample_layout(base, draws, i) for i in range(m)]
    table = range_table(layouts, spot) if spot is not None and not spot.ideal else {}
    states = np.zeros((m, S), dtype=np.int8)
    thickness = np.full((m, S), np.nan)
    bottom = np.full((m, S), np.nan)
    with spot_module.precomputed_ranges(table):
        for i, sample in enumerate(layouts):
            st, th, bo = scalar_layout_states(base, sample, peaks)
            states[i] = st
            thickness[i] = [np.nan if v is None else v for v in th]
            bottom[i] = [np.nan if v is None else v for v in bo]
    return states, thickness, bottom
