"""A sweep with a beam spot (SPEC §12 with §10; ``sweep.spot_block`` runs a block): the
spot's column ranges of a whole block of sampled layouts in numpy, then the blocked fraction
of the whole block at once (``lean_block``), or each layout through the scalar spot engine
(core/scan/sensing.py), which finds the ranges precomputed instead of computing them one
``translation_range`` at a time.

With a tilted beam every column of the spot (and every strip's middle column, where the spot
engine checks its limits are linear) is a general ``translation_range``: the corners of a
(lam, tau) region bounded by the beam's ends, the faces and the rim (core/geometry/ranges.py),
~40 µs each in Python, ~1,200 a layout of 25 slots. ``range_table`` works them out for a whole
block with ``translation_ranges``, that function over arrays, the same floats bit for bit;
what it cannot promise (a bowed wafer, the degenerate rims, a pair of lines on the edge of the
parallel test) is left to the scalar function.

The precomputed ranges are handed to core/sensor/spot.py as a table keyed by the wafer and the
column's offset (the ``ray_ranges`` argument): a range the table lacks (a strip halved beyond
its middle column, an uncovered wafer) the spot engine computes itself.

A scan read on the step grid (``lean_spot_path``) then goes through ``lean_block`` for the
whole block: the groups of wafers as ``spot.wafer_groups`` forms them; a group of one wafer's
strips straight from the table over arrays where no strip needs halving and no piece continues
the one before it (else ``BlockedFraction``'s own search); the blocked fraction of every group
of every layout at its steps in one chunked evaluation (a round spot's area without the sort,
the same floats); then per layout the amplifier's output, the latching and the up/down runs as
``sensing.sensed_scan`` makes them, and the recipe's mapping. Nothing else of ``scan_layout``
(the line beam's intervals, the warnings) is computed. Same answers as the scalar path:
tests/core/test_sweep_spot.py compares states, readings and every group's peak exactly.
"""

from __future__ import annotations

import math

from ..geometry.ranges import translation_ranges
from ..model import SLOW as SLOW_MODE
from ..sensor import spot as spot_module

# Translations evaluated at once by _BlockFraction (x the strips: ~25,000 floats an array).
_CHUNK = 1000
# Column ranges computed at once by range_table.
_RANGE_CHUNK = 8192
# A range the table leaves to the scalar function.
MISSING = spot_module.MISSING


def column_offsets(spot, columns=spot_module.COLUMNS):
    """The offsets s (mm) across the spot at which the spot engine asks for a column's range
    first: its columns and the middle of each strip between two (the same floats it computes)."""
    positions = spot_module.column_positions(spot, columns)
    middles = [0.5 * (positions[i] + positions[i + 1]) for i in range(columns)]
    return positions + middles


def range_table(layouts, spot, columns=spot_module.COLUMNS):
    """The centre-ray ranges (tol 0) of every flat wafer of ``layouts`` (each with its own
    beam, the same lift axis and emitter) at ``column_offsets``: {(id(wafer), id(beam)):
    ({s: its place in the list}, [(lo, hi) or None, in the offsets' order])}; the ranges the
    array formulas do not cover bit for bit are ``MISSING`` in the list."""
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
    length = lengths.pop()
    parts = []
    # In chunks that stay in the cache (~30 arrays deep); each element is its own.
    for a in range(0, n * k, _RANGE_CHUNK):
        b = a + _RANGE_CHUNK
        parts.append(translation_ranges(emitter[a:b], direction[a:b], axis, center[a:b],
                                        normal[a:b], radius[a:b], thickness[a:b], length, 0.0))
    lo, hi, hit, covered = (np.concatenate(x) for x in zip(*parts))
    values = list(zip(lo.tolist(), hi.tolist()))
    for j in np.flatnonzero(~hit).tolist():
        values[j] = None
    for j in np.flatnonzero(~covered).tolist():
        values[j] = MISSING
    index = {offset: j for j, offset in enumerate(offsets)}
    for j, (wafer, beam, _) in enumerate(rows):
        table[(id(wafer), id(beam))] = (index, values[j * k:(j + 1) * k])
    return table


def _round_area_below(spot, sa, sb, ya, yb, primitive_a, primitive_b):
    """``spot.area_below`` of a round spot, the same floats with less work: the line meets the
    circle at s1 <= s2, clipped into [sa, sb], so the four break points are already in order
    (sa, s1, s2, sb) and need no sort (no -0.0 among them: a strip's ends are +0.0 or not zero,
    and the roots' zeros are +0.0); the circle's primitive at sa and sb is the strip's own
    (``primitive_a``, ``primitive_b``, computed once per strip, not once per translation).
    Where the line misses the circle (disc <= 0, s1 = s2 = sa) the first two segments are
    empty, each term a zero, and the sum is 0.0 plus the whole strip's term: only that is
    computed there."""
    import numpy as np

    width = sb - sa
    m = (yb - ya) / width
    k = ya - m * sa
    r = spot.half_width
    qa = 1.0 + m * m
    qb = m * k
    disc = qb * qb - qa * (k * k - r * r)
    shape = k.shape
    sa, sb = np.broadcast_to(sa, shape), np.broadcast_to(sb, shape)
    pa, pb = np.broadcast_to(primitive_a, shape), np.broadcast_to(primitive_b, shape)
    # The whole strip, segment (sa, sb): the answer where the line misses the circle.
    mid_s = 0.5 * (sa + sb)
    mid = m * mid_s + k
    c_mid = np.sqrt(np.maximum(r * r - mid_s * mid_s, 0.0))
    arc = pb - pa
    linear = 0.5 * m * (sb * sb - sa * sa) + k * (sb - sa)
    total = np.zeros(shape)
    total += np.where(mid >= c_mid, arc, np.where(mid <= -c_mid, -arc, linear))
    at = np.flatnonzero(disc > 0.0)
    if not len(at):
        return total
    m, k, qa, qb, disc = (x.reshape(-1)[at] for x in (m, k, qa, qb, disc))
    sa, sb, pa, pb = (x.reshape(-1)[at] for x in (sa, sb, pa, pb))
    root = np.sqrt(np.maximum(disc, 0.0))
    c1, c2 = np.clip((-qb - root) / qa, sa, sb), np.clip((-qb + root) / qa, sa, sb)
    pts = (sa, c1, c2, sb)
    prim = (pa, spot_module.circle_primitive(c1, r), spot_module.circle_primitive(c2, r), pb)
    crossing = np.zeros(len(at))
    for j in range(3):
        a, bnd = pts[j], pts[j + 1]
        mid_s = 0.5 * (a + bnd)
        mid = m * mid_s + k
        c_mid = np.sqrt(np.maximum(r * r - mid_s * mid_s, 0.0))
        arc = prim[j + 1] - prim[j]
        linear = 0.5 * m * (bnd * bnd - a * a) + k * (bnd - a)
        crossing += np.where(mid >= c_mid, arc, np.where(mid <= -c_mid, -arc, linear))
    total.reshape(-1)[at] = crossing
    return total


class RoundSpotFraction(spot_module.GroupedFraction):
    """``spot.GroupedFraction`` of a round spot, evaluated by ``_round_area_below``: the same
    values bit for bit (tests/core/test_sweep_spot.py)."""

    def __init__(self, fractions):
        super().__init__(fractions)
        r = self.spot.half_width
        self.primitives = {width: (spot_module.circle_primitive(table["_sa"], r),
                                   spot_module.circle_primitive(table["_sb"], r))
                           for width, table in self.tables.items()}

    def groups_area_below(self, width, rows, d, ya, yb):
        pa, pb = (p[rows] for p in self.primitives[width])
        return _round_area_below(self.spot, d["_sa"], d["_sb"], ya, yb, pa, pb)


class _Strips:
    """A group's strips with linear limits, as ``spot.BlockedFraction`` holds them (the fields
    ``spot.GroupedFraction`` reads), built from the table by ``_single_wafer_strips``."""

    def __init__(self, spot, beta, pieces):
        import numpy as np

        self.spot = spot
        self.beta = beta
        data = np.array(pieces, dtype=float).reshape(-1, 6)
        self._sa, self._sb = data[:, 0], data[:, 1]
        self._lo_a, self._lo_b, self._hi_a, self._hi_b = (data[:, 2], data[:, 3], data[:, 4],
                                                          data[:, 5])


def _single_wafer_strips(spot, positions, middles, ranges, middle_ranges):
    """``BlockedFraction``'s strips of a group of one wafer, in its order, when no strip needs
    halving: the column ranges ``ranges`` at ``positions`` and ``middle_ranges`` at the strips'
    middles (a range or None each). None where a strip would be halved (the caller then builds
    the group with ``BlockedFraction`` itself)."""
    pieces = []
    tolerance = spot_module.LINEAR_TOLERANCE
    for i in range(len(positions) - 1):
        sa, sb = positions[i], positions[i + 1]
        a, b = ranges[i], ranges[i + 1]
        left = [] if a is None else [a]
        right = [] if b is None else [b]
        if left != right:
            m = middle_ranges[i]
            middle = [] if m is None else [m]
            if not (len(left) == len(right) == len(middle) and all(
                    abs(0.5 * (lo[0] + r[0]) - mi[0]) <= tolerance
                    and abs(0.5 * (lo[1] + r[1]) - mi[1]) <= tolerance
                    for lo, r, mi in zip(left, right, middle))):
                return None
        # BlockedFraction's ``add``.
        if len(left) == 1 and pieces and pieces[-1][1] == sa and spot_module.extends_linearly(
                pieces[-1], sb, right[0]):
            last = pieces[-1]
            pieces[-1] = (last[0], sb, last[2], right[0][0], last[4], right[0][1])
            continue
        for (la, ha), (lb, hb) in zip(left, right):
            pieces.append((sa, sb, la, lb, ha, hb))
    return pieces


def lean_spot_path(layout):
    """Whether ``spot_runs`` covers the layout's scan: a beam spot read on the step grid
    (latched per step, not exact) in a fast scan. Others take the scalar ``scan_layout``."""
    from ..sensor.motion import STEP

    scan = layout.scan
    spot = layout.spot
    return (spot is not None and not spot.ideal and scan.latch == STEP and not scan.exact
            and scan.mode != SLOW_MODE and scan.final_z >= scan.start_z)


def spot_runs(layout, table):
    """The runs (``SensorRun``) and the groups' peak blocked fractions of ``sensing.sensed_scan``
    for a layout ``lean_spot_path`` covers (``lean_block`` of that one layout)."""
    return lean_block([layout], table)[0]


def _table_strips(spot, rows):
    """``BlockedFraction``'s strips of groups of one wafer over arrays: ``rows`` holds each
    wafer's ranges at ``column_offsets`` (tuples or None). Returns (strips, fallback): per row
    a boolean mask over the spot's strips of those that make a piece (its limits are the
    strip's ends'), or None for the rows whose strips are not that simple (a strip to halve, a
    piece continuing the one before it in a straight line): ``_single_wafer_strips`` or
    ``BlockedFraction`` builds those, in order."""
    import numpy as np

    columns = spot_module.COLUMNS
    n = len(rows)
    flat = [x if x is not None else (math.nan, math.nan) for row in rows for x in row]
    data = np.array(flat, dtype=float).reshape(n, 2 * columns + 1, 2)
    ok = ~np.isnan(data[:, :, 0])
    col_lo, col_hi, col_ok = data[:, :columns + 1, 0], data[:, :columns + 1, 1], ok[:, :columns + 1]
    mid_lo, mid_hi, mid_ok = data[:, columns + 1:, 0], data[:, columns + 1:, 1], ok[:, columns + 1:]
    l0, l1, left = col_lo[:, :-1], col_hi[:, :-1], col_ok[:, :-1]
    r0, r1, right = col_lo[:, 1:], col_hi[:, 1:], col_ok[:, 1:]
    tolerance = spot_module.LINEAR_TOLERANCE
    both = left & right
    with np.errstate(invalid="ignore"):
        equal = both & (l0 == r0) & (l1 == r1)
        linear = both & mid_ok & (np.abs(0.5 * (l0 + r0) - mid_lo) <= tolerance) & \
            (np.abs(0.5 * (l1 + r1) - mid_hi) <= tolerance)
        piece = equal | linear
        simple = np.all(piece | (~left & ~right), axis=1)
        # ``add`` would merge strip i into strip i-1's piece (spot.extends_linearly, tol 1e-12): such
        # rows are built one strip after another.
        positions = np.array(spot_module.column_positions(spot, columns))
        sa, sb = positions[:-1], positions[1:]
        f = (sb[1:] - sa[:-1]) / (sb[:-1] - sa[:-1])
        lo_line = l0[:, :-1] + f * (r0[:, :-1] - l0[:, :-1]) - r0[:, 1:]
        hi_line = l1[:, :-1] + f * (r1[:, :-1] - l1[:, :-1]) - r1[:, 1:]
        merges = piece[:, :-1] & piece[:, 1:] & (np.abs(lo_line) <= 1e-12) & \
            (np.abs(hi_line) <= 1e-12)
    simple &= ~merges.any(axis=1)
    return [piece[i] if simple[i] else None for i in range(n)], (sa, sb, l0, r0, l1, r1)


class _BlockFraction:
    """The blocked fraction of every group of a block of layouts, in one evaluation per number
    of strips: ``spot.GroupedFraction``'s tables with each group's beta (its layout's) beside
    its strips, read by ``_round_area_below`` (a round spot) or ``spot.area_below``."""

    FIELDS = spot_module.GroupedFraction.FIELDS

    def __init__(self, spot):
        self.spot = spot
        self.rows = {}  # strip count -> {field: [arrays]}, betas
        self.where = []  # group -> (strip count, row)

    def add(self, beta, fields):
        """A group with strips ``fields`` (six equal-length 1-D arrays); returns its index."""
        width = len(fields[0])
        table = self.rows.setdefault(width, ([[] for _ in self.FIELDS], []))
        for column, values in zip(table[0], fields):
            column.append(values)
        table[1].append(beta)
        self.where.append((width, len(table[1]) - 1))
        return len(self.where) - 1

    def add_many(self, betas, fields):
        """Groups of one strip count: ``fields`` six (groups, strips) arrays."""
        import numpy as np

        width = fields[0].shape[1]
        table = self.rows.setdefault(width, ([[] for _ in self.FIELDS], []))
        start = len(table[1])
        for column, values in zip(table[0], fields):
            column.extend(np.asarray(values))
        table[1].extend(betas)
        first = len(self.where)
        self.where.extend((width, start + i) for i in range(len(betas)))
        return list(range(first, len(self.where)))

    def evaluate(self, tau, group):
        """b at translations ``tau`` of groups ``group`` (arrays)."""
        import numpy as np

        spot = self.spot
        r = spot.half_width
        where = np.array(self.where, dtype=np.int64).reshape(-1, 2)
        width, slot = where[:, 0], where[:, 1]
        out = np.zeros(tau.shape)
        for w, (columns, betas) in self.rows.items():
            if w == 0:
                continue
            mask = width[group] == w
            if not mask.any():
                continue
            fields = {name: np.array(values).reshape(len(betas), w)
                      for name, values in zip(self.FIELDS, columns)}
            if spot.round:
                fields["pa"] = spot_module.circle_primitive(fields["_sa"], r)
                fields["pb"] = spot_module.circle_primitive(fields["_sb"], r)
            beta_of = np.array(betas)
            where_all = np.flatnonzero(mask)
            # In chunks that stay in the cache (the arrays of one evaluation are ~40 deep).
            for start in range(0, len(where_all), _CHUNK):
                at = where_all[start:start + _CHUNK]
                rows = slot[group[at]]
                d = {name: values[rows] for name, values in fields.items()}
                b = beta_of[rows][:, None]
                t = tau[at][:, None]
                if spot.round:
                    upper = _round_area_below(spot, d["_sa"], d["_sb"], b * (d["_hi_a"] - t),
                                              b * (d["_hi_b"] - t), d["pa"], d["pb"])
                    lower = _round_area_below(spot, d["_sa"], d["_sb"], b * (d["_lo_a"] - t),
                                              b * (d["_lo_b"] - t), d["pa"], d["pb"])
                else:
                    upper = spot_module.area_below(spot, d["_sa"], d["_sb"],
                                                    b * (d["_hi_a"] - t), b * (d["_hi_b"] - t))
                    lower = spot_module.area_below(spot, d["_sa"], d["_sb"],
                                                    b * (d["_lo_a"] - t), b * (d["_lo_b"] - t))
                out[at] = (upper - lower).sum(axis=1) / spot.area
        return np.clip(out, 0.0, 1.0)


def lean_block(layouts, table):
    """Per layout (each one ``lean_spot_path`` covers, all with one spot), the runs
    (``SensorRun``) and the groups' peak blocked fractions of ``sensing.sensed_scan``, and
    nothing else it computes (the line beam's wafer intervals, warnings, the slot map): the
    same steps in the same order, the groups of one wafer built from ``table`` over arrays
    (``_table_strips``) and every group's b at its steps in one evaluation for the block."""
    import numpy as np

    from ..scan.scan_result import SensorRun
    from ..scan.sensing import stroke_latcher, strokes
    from ..sensor.amplifier import stepped_output
    from ..sensor.spot import DEFAULT_AMPLIFIER, BlockedFraction

    if not layouts:
        return []
    spot = layouts[0].spot
    columns = spot_module.COLUMNS
    positions = spot_module.column_positions(spot, columns)
    middles = column_offsets(spot)[columns + 1:]
    fraction = _BlockFraction(spot)
    plans = []  # per layout: (groups as (names, z span), group indices in ``fraction``)
    singles = []  # (layout, group, beta, the wafer's ranges at column_offsets)
    for li, layout in enumerate(layouts):
        beam, axis = layout.beam, layout.lift_axis
        if layout.spot != spot:
            raise ValueError("lean_block: the layouts must share one beam spot")
        z0, az = beam.emitter[2], axis[2]
        beta = spot_module.spot_frame(beam.direction, axis)[3]
        b_id = id(beam)
        low, high = layout.scan.start_z, layout.scan.final_z
        groups = []
        for members, ranges, (tau_lo, tau_hi) in spot_module.wafer_groups(layout, layout.wafers, spot, ray_ranges=table):
            wafers = [layout.wafers[i] for i in members]
            entry = table.get((id(wafers[0]), b_id)) if len(wafers) == 1 else None
            index = None
            if entry is not None and MISSING not in entry[1]:
                singles.append((li, len(groups), beta, entry[1]))
            else:
                f = BlockedFraction(layout, wafers, spot, ranges, ray_ranges=table)
                index = fraction.add(beta, [getattr(f, name) for name in _BlockFraction.FIELDS])
            z_lo, z_hi = z0 + tau_lo * az, z0 + tau_hi * az
            groups.append([tuple(w.name for w in wafers), (max(z_lo, low), min(z_hi, high)),
                           index])
        plans.append(groups)
    if singles:
        pieces, (sa, sb, l0, r0, l1, r1) = _table_strips(spot, [row for *_, row in singles])
        simple = [i for i, p in enumerate(pieces) if p is not None]
        by_width = {}
        for i in simple:
            by_width.setdefault(int(pieces[i].sum()), []).append(i)
        for width, members in by_width.items():
            mask = np.array([pieces[i] for i in members])
            idx = np.array(members)
            fields = [np.broadcast_to(sa, mask.shape)[mask], np.broadcast_to(sb, mask.shape)[mask],
                      l0[idx][mask], r0[idx][mask], l1[idx][mask], r1[idx][mask]]
            fields = [x.reshape(len(members), width) for x in fields]
            indices = fraction.add_many([singles[i][2] for i in members], fields)
            for i, g in zip(members, indices):
                li, gi = singles[i][0], singles[i][1]
                plans[li][gi][2] = g
        for i, p in enumerate(pieces):
            if p is not None:
                continue
            li, gi, beta, row = singles[i]
            strips = _single_wafer_strips(spot, positions, middles, row[:columns + 1],
                                          row[columns + 1:])
            if strips is None:
                layout = layouts[li]
                name = plans[li][gi][0][0]
                wafer = next(w for w in layout.wafers if w.name == name)
                f = BlockedFraction(layout, [wafer], spot, [list(row[:columns + 1])],
                                    ray_ranges=table)
                fields = [getattr(f, name) for name in _BlockFraction.FIELDS]
            else:
                data = np.array(strips, dtype=float).reshape(-1, 6)
                fields = [data[:, j] for j in range(6)]
            plans[li][gi][2] = fraction.add(beta, fields)
    # Every group's steps, b at them in one evaluation.
    taus, owners, steps = [], [], []
    for layout, groups in zip(layouts, plans):
        scan = layout.scan
        z0, az = layout.beam.emitter[2], layout.lift_axis[2]
        mine = []
        for names, (lo, hi), g in groups:
            k_lo = max(0, math.ceil((lo - scan.start_z) / scan.z_step))
            k_hi = min(scan.last_step, math.floor((hi - scan.start_z) / scan.z_step))
            z = scan.position(np.arange(k_lo, k_hi + 1, dtype=float))
            mine.append(z)
            taus.append((z - z0) / az)
            owners.append(np.full(len(z), g))
        steps.append(mine)
    values_all = fraction.evaluate(np.concatenate(taus), np.concatenate(owners)) if taus \
        else np.zeros(0)
    answers = []
    offset = 0
    for layout, groups, mine in zip(layouts, plans, steps):
        scan = layout.scan
        amplifier = layout.amplifier or DEFAULT_AMPLIFIER
        on_level, off_level = amplifier.threshold_on, amplifier.off_level
        moving = strokes(scan)
        out = {up: [] for up in moving}
        peaks = [0.0] * len(groups)
        for g, ((names, _, _), z) in enumerate(zip(groups, mine)):
            values = values_all[offset:offset + len(z)]
            offset += len(z)
            if not len(z):
                continue
            peaks[g] = float(values.max())
            for up in moving:
                for first, last in stepped_output(values, on_level, off_level, up):
                    out[up].append((float(z[first]), float(z[last]), names))
        for up in moving:
            out[up].sort()
        # sensed_scan's runs.
        latched = {}
        for up in moving:
            at = stroke_latcher(scan, up)
            latched[up] = [(at(a), at(b)) if up else (at(b), at(a)) for a, b, _ in out[up]]
        runs = []
        if len(moving) == 2 and len(out[True]) == len(out[False]) and all(
                u[0] <= d[1] and d[0] <= u[1] for u, d in zip(out[True], out[False])):
            for (a, b, names), (in_u, out_u), (in_d, out_d) in zip(out[True], latched[True],
                                                                   latched[False]):
                runs.append(SensorRun(0.5 * (in_u + out_d), 0.5 * (out_u + in_d), names,
                                      (a, b)))
        else:
            first = moving[0]
            for (a, b, names), (z_in, z_out) in zip(out[first], latched[first]):
                runs.append(SensorRun(z_in, z_out, names, (a, b)))
        answers.append((runs, peaks))
    return answers
