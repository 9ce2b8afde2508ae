"""A beam of finite size (SPEC §10): the blocked fraction b(z) of a round or slit spot.

The beam is the bundle of rays parallel to the beam's direction e through every point of the
spot, which lies in the plane normal to e; the spot's height runs along v, the part of the lift
axis a normal to e (unit), its width along u = e x v. Uniform intensity, so b(z) is the share of
the spot's area whose ray meets a wafer solid.

How it is computed, without stepping. A ray at width s and height h is the beam's central ray
moved by s u + h v = s u + (h/beta) a - (h alpha/beta) e, alpha = a.e, beta = |a - alpha e|:
the column s of rays is the column's centre ray translated along the lift axis (and slid along
its own line, which changes nothing unless a wafer reaches past the beam's ends). So if the
centre ray of column s meets a wafer for lift translations tau in [tau0(s), tau1(s)] (the closed
form ``translation_range``, exact), the rays of that column blocked at translation tau are those
with h in [beta (tau0 - tau), beta (tau1 - tau)]. The blocked area is then the integral over s
of that interval clipped to the spot's column [-c(s), c(s)]. Across the spot tau0(s) and tau1(s)
are taken linear between columns (``COLUMNS`` of them); with linear limits the integral is
closed form (a circle's area below a straight line within a vertical strip; a rectangle's for a
slit). A level wafer crossed well inside its rim has constant limits, so its b(z) is exact: the
band of circular segments of the tests' oracle. Tilted wafers have linear face limits (exact as
well); only a rim crossing the spot (a grazing chord) is approximated, piecewise linearly.

Several wafers within a spot's height of each other block the union of their intervals; where
the union's pieces do not pair up from one column to the next, that strip takes the union at its
middle column, constant across it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..geometry.ranges import merged_ranges, translation_range

# Columns across the spot at which the per-column translation range is computed exactly; the
# limits are linear between them. The oracle (a level wafer) is exact for any number; this many
# keeps a grazing chord's rim, curved across a 5 mm spot, within a fraction of a micrometre.
COLUMNS = 24
# A strip's limits are taken linear when its middle column's lie within this (mm of lift
# travel) of the straight line; otherwise it is halved, at most MAX_SPLITS times.
LINEAR_TOLERANCE = 1e-6
MAX_SPLITS = 12
# Bisection of a threshold crossing stops below this (mm of lift travel).
EDGE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class BeamSpot:
    """The beam's cross-section: round (``diameter``) or a slit (``width`` x ``height``), mm.
    All zero: the ideal line of the paper."""

    diameter: float = 0.0
    width: float = 0.0
    height: float = 0.0

    @property
    def ideal(self):
        return self.diameter == 0.0 and self.width == 0.0 and self.height == 0.0

    @property
    def round(self):
        return self.diameter > 0.0

    @property
    def half_width(self):
        return 0.5 * (self.diameter if self.round else self.width)

    @property
    def half_height(self):
        return 0.5 * (self.diameter if self.round else self.height)

    @property
    def area(self):
        """mm²."""
        if self.round:
            return math.pi * 0.25 * self.diameter * self.diameter
        return self.width * self.height


@dataclass(frozen=True)
class Amplifier:
    """The sensor amplifier's switching levels, as blocked fractions: the output turns ON when
    b >= ``threshold_on`` and back OFF when b < ``threshold_off`` (default: equal, no
    hysteresis)."""

    threshold_on: float = 0.5
    threshold_off: float | None = None

    @property
    def off_level(self):
        return self.threshold_on if self.threshold_off is None else self.threshold_off


IDEAL_SPOT = BeamSpot()
DEFAULT_AMPLIFIER = Amplifier()


def spot_frame(direction, lift_axis):
    """(u, v, alpha, beta) of the spot: v the unit part of the lift axis normal to the beam
    (the spot's height), u = e x v (its width), alpha = a.e, beta = |a - alpha e|."""
    ex, ey, ez = direction
    ax, ay, az = lift_axis
    alpha = ax * ex + ay * ey + az * ez
    vx, vy, vz = ax - alpha * ex, ay - alpha * ey, az - alpha * ez
    beta = math.sqrt(vx * vx + vy * vy + vz * vz)
    if beta < 1e-9:
        raise ValueError("the beam runs along the lift axis: a spot has no height to sweep")
    v = (vx / beta, vy / beta, vz / beta)
    u = (ey * v[2] - ez * v[1], ez * v[0] - ex * v[2], ex * v[1] - ey * v[0])
    return u, v, alpha, beta


def column_positions(spot, columns):
    """Column offsets s across the spot (mm), from one side to the other."""
    w = spot.half_width
    return [-w + 2.0 * w * i / columns for i in range(columns + 1)]


def _chord_half(spot, s):
    """Half the spot's extent along v at width s."""
    if spot.round:
        r = spot.half_width
        return math.sqrt(max(0.0, r * r - s * s))
    return spot.half_height


def extends_linearly(piece, s, limits, tol=1e-12):
    """Whether the strip ``piece`` (sa, sb, lo_a, lo_b, hi_a, hi_b) continued straight to width
    ``s`` meets ``limits`` (lo, hi) there, to ``tol`` mm."""
    sa, sb, lo_a, lo_b, hi_a, hi_b = piece
    f = (s - sa) / (sb - sa)
    return (abs(lo_a + f * (lo_b - lo_a) - limits[0]) <= tol
            and abs(hi_a + f * (hi_b - hi_a) - limits[1]) <= tol)


# In a table of centre-ray ranges worked out beforehand (``ray_ranges``, made by
# core/sweep/spot_scan.py's ``range_table`` over arrays: {(id(wafer), id(beam)): ({s: j},
# [range j, or MISSING])}, the same floats ``translation_range`` gives), a range not worked out.
MISSING = object()


def _centre_ray_range(s, u, beam, axis, wafer, table=None):
    """``translation_range`` (tol 0) of the centre ray of the spot's column at offset s, read
    from ``table`` (``ray_ranges``) where it holds it."""
    if table is not None:
        entry = table.get((id(wafer), id(beam)))
        if entry is not None:
            j = entry[0].get(s)
            if j is not None and entry[1][j] is not MISSING:
                return entry[1][j]
    ox, oy, oz = beam.emitter
    return translation_range((ox + s * u[0], oy + s * u[1], oz + s * u[2]), beam, axis, wafer,
                             tol=0.0)


def column_ranges(layout, wafer, spot, columns=COLUMNS, ray_ranges=None):
    """For each column of the spot (``column_positions``), the exact range (tau_lo, tau_hi) of
    lift translations over which the column's centre ray meets the wafer, or None; read from
    ``ray_ranges`` (a sweep's table worked out beforehand, see MISSING) where it holds them."""
    beam, axis = layout.beam, layout.lift_axis
    u = spot_frame(beam.direction, axis)[0]
    return [_centre_ray_range(s, u, beam, axis, wafer, ray_ranges)
            for s in column_positions(spot, columns)]


class BlockedFraction:
    """b(tau) for a group of wafers (a callable over numpy arrays of lift translations tau,
    mm along the lift axis from the beam's start). Built once per group from the exact
    translation ranges of the spot's columns (``column_ranges`` of each wafer), reduced to
    strips with linear limits. ``ranges``: the wafers' ``column_ranges`` when the caller has
    them; ``ray_ranges``: a sweep's table of centre-ray ranges (``column_ranges``)."""

    def __init__(self, layout, wafers, spot, ranges=None, columns=COLUMNS, ray_ranges=None):
        import numpy as np

        self.spot = spot
        beam, axis = layout.beam, layout.lift_axis
        u, _, _, beta = spot_frame(beam.direction, axis)
        self.beta = beta
        if ranges is None:
            ranges = [column_ranges(layout, w, spot, columns, ray_ranges) for w in wafers]
        positions = column_positions(spot, columns)
        at_nodes = [merged_ranges([r[i] for r in ranges if r[i] is not None])
                    for i in range(columns + 1)]

        def at(s):
            spans = (_centre_ray_range(s, u, beam, axis, w, ray_ranges) for w in wafers)
            return merged_ranges([x for x in spans if x is not None])

        pieces = []  # (sa, sb, lo_a, lo_b, hi_a, hi_b)

        def add(sa, sb, left, right):
            if len(left) == 1 and pieces and pieces[-1][1] == sa and extends_linearly(pieces[-1], sb,
                                                                              right[0]):
                # One limit pair running on in a straight line (a level wafer's constant
                # limits): one wider strip, as exact, and the area is evaluated once.
                last = pieces[-1]
                pieces[-1] = (last[0], sb, last[2], right[0][0], last[4], right[0][1])
                return
            for (la, ha), (lb, hb) in zip(left, right):
                pieces.append((sa, sb, la, lb, ha, hb))

        def strip(sa, sb, left, right, depth):
            """Limits linear across [sa, sb] where the middle column agrees with that to
            LINEAR_TOLERANCE; else the strip is halved (a tilted wafer's rim, curved; a
            wafer that only part of the spot's columns meet, at the edge of its chord)."""
            if left == right:
                # Equal ends: a level wafer's limits are the faces', the same in every column.
                add(sa, sb, left, right)
                return
            middle = at(0.5 * (sa + sb))
            if len(left) == len(right) == len(middle) and all(
                    abs(0.5 * (l[0] + r[0]) - m[0]) <= LINEAR_TOLERANCE
                    and abs(0.5 * (l[1] + r[1]) - m[1]) <= LINEAR_TOLERANCE
                    for l, r, m in zip(left, right, middle)):
                add(sa, sb, left, right)
            elif depth >= MAX_SPLITS:
                # A strip narrower than the spot / (COLUMNS 2**MAX_SPLITS): the middle's
                # limits across it.
                add(sa, sb, middle, middle)
            else:
                strip(sa, 0.5 * (sa + sb), left, middle, depth + 1)
                strip(0.5 * (sa + sb), sb, middle, right, depth + 1)

        for i in range(columns):
            strip(positions[i], positions[i + 1], at_nodes[i], at_nodes[i + 1], 0)
        self.empty = not pieces
        data = np.array(pieces, dtype=float).reshape(-1, 6)
        self._sa, self._sb = data[:, 0], data[:, 1]
        self._lo_a, self._lo_b, self._hi_a, self._hi_b = data[:, 2], data[:, 3], data[:, 4], data[:, 5]
        if pieces:
            reach = spot.half_height / beta
            self.support = (float(min(data[:, 2].min(), data[:, 3].min())) - reach,
                            float(max(data[:, 4].max(), data[:, 5].max())) + reach)
        else:
            self.support = None

    def __call__(self, tau):
        """Blocked fraction (0..1) at lift translations ``tau`` (array or float)."""
        import numpy as np

        tau = np.asarray(tau, dtype=float)
        if self.empty:
            return np.zeros(tau.shape)
        t = tau.reshape(-1, 1)
        b = self.beta
        upper = area_below(self.spot, self._sa, self._sb, b * (self._hi_a - t), b * (self._hi_b - t))
        lower = area_below(self.spot, self._sa, self._sb, b * (self._lo_a - t), b * (self._lo_b - t))
        fraction = (upper - lower).sum(axis=1) / self.spot.area
        return np.clip(fraction, 0.0, 1.0).reshape(tau.shape)


class GroupedFraction:
    """Several ``BlockedFraction``s (of one spot and layout) evaluated in one call:
    ``fraction(tau, group)`` with arrays of translations and group indices. Groups with the same
    number of strips share one table (a level wafer's single strip is not padded to a tilted
    wafer's many)."""

    FIELDS = ("_sa", "_sb", "_lo_a", "_lo_b", "_hi_a", "_hi_b")

    def __init__(self, fractions):
        import numpy as np

        self.spot = fractions[0].spot if fractions else None
        self.beta = fractions[0].beta if fractions else 1.0
        self.tables = {}  # strip count -> (group indices, {field: (groups, strips) array})
        for g, f in enumerate(fractions):
            self.tables.setdefault(len(f._sa), []).append(g)
        self.slot = np.zeros(len(fractions), dtype=int)  # a group's row in its table
        self.width = np.zeros(len(fractions), dtype=int)
        for width, members in self.tables.items():
            self.slot[members] = np.arange(len(members))
            self.width[members] = width
            self.tables[width] = {name: np.array([getattr(fractions[g], name) for g in members])
                                  .reshape(len(members), width) for name in self.FIELDS}

    def __call__(self, tau, group):
        import numpy as np

        tau = np.asarray(tau, dtype=float)
        group = np.asarray(group, dtype=int)
        out = np.zeros(tau.shape)
        b = self.beta
        for width, table in self.tables.items():
            if width == 0:
                continue
            mask = self.width[group] == width
            if not mask.any():
                continue
            rows = self.slot[group[mask]]
            d = {k: v[rows] for k, v in table.items()}
            t = tau[mask][:, None]
            upper = self.groups_area_below(width, rows, d, b * (d["_hi_a"] - t), b * (d["_hi_b"] - t))
            lower = self.groups_area_below(width, rows, d, b * (d["_lo_a"] - t), b * (d["_lo_b"] - t))
            out[mask] = (upper - lower).sum(axis=1) / self.spot.area
        return np.clip(out, 0.0, 1.0)

    def groups_area_below(self, width, rows, d, ya, yb):
        """The spot's area under the lines from ``ya`` to ``yb`` over the strips ``d`` (rows
        ``rows`` of the groups of ``width`` strips); a subclass may evaluate it faster."""
        return area_below(self.spot, d["_sa"], d["_sb"], ya, yb)


def circle_primitive(s, r):
    """Integral of sqrt(r² - s²) ds from 0 to s."""
    import numpy as np

    s = np.clip(s, -r, r)
    return 0.5 * (s * np.sqrt(np.maximum(r * r - s * s, 0.0)) + r * r * np.arcsin(s / r))


def area_below(spot, sa, sb, ya, yb):
    """Integral over s in [sa, sb] of clip(y(s), -c(s), c(s)), y linear from ya to yb: the
    spot's area below the line in that strip, less the strip's lower half. Arrays broadcast."""
    import numpy as np

    width = sb - sa
    m = (yb - ya) / width
    k = ya - m * sa
    if not spot.round:
        # Clip of a linear function to a constant band: break where it meets +-c.
        c = spot.half_height
        points = [np.broadcast_to(sa, k.shape), np.broadcast_to(sb, k.shape)]
        with np.errstate(divide="ignore", invalid="ignore"):
            for level in (-c, c):
                x = np.where(m != 0.0, (level - k) / np.where(m != 0.0, m, 1.0), sa)
                points.append(np.clip(x, sa, sb))
        pts = np.sort(np.stack(points), axis=0)
        total = np.zeros(k.shape)
        for j in range(3):
            a, bnd = pts[j], pts[j + 1]
            mid = m * (0.5 * (a + bnd)) + k
            linear = 0.5 * m * (bnd * bnd - a * a) + k * (bnd - a)
            total += np.where(mid >= c, c * (bnd - a), np.where(mid <= -c, -c * (bnd - a), linear))
        return total
    r = spot.half_width
    # Where the line meets the circle: (1 + m²) s² + 2 m k s + k² - r² = 0.
    qa = 1.0 + m * m
    qb = m * k
    disc = qb * qb - qa * (k * k - r * r)
    root = np.sqrt(np.maximum(disc, 0.0))
    s1 = np.where(disc > 0.0, (-qb - root) / qa, sa)
    s2 = np.where(disc > 0.0, (-qb + root) / qa, sa)
    sa_b = np.broadcast_to(sa, k.shape)
    sb_b = np.broadcast_to(sb, k.shape)
    pts = np.sort(np.stack([sa_b, sb_b, np.clip(s1, sa, sb), np.clip(s2, sa, sb)]), axis=0)
    total = np.zeros(k.shape)
    for j in range(3):
        a, bnd = pts[j], pts[j + 1]
        mid_s = 0.5 * (a + bnd)
        mid = m * mid_s + k
        c_mid = np.sqrt(np.maximum(r * r - mid_s * mid_s, 0.0))
        arc = circle_primitive(bnd, r) - circle_primitive(a, r)
        linear = 0.5 * m * (bnd * bnd - a * a) + k * (bnd - a)
        total += np.where(mid >= c_mid, arc, np.where(mid <= -c_mid, -arc, linear))
    return total


def wafer_groups(layout, wafers, spot, columns=COLUMNS, ray_ranges=None):
    """The wafers whose blocked regions on the spot can overlap, grouped: a group's lift
    translations, grown by the spot's reach, overlap no other group's. Returns a sorted list of
    (indices, ranges, (tau_lo, tau_hi)): the wafers, their ``column_ranges`` and the range of
    translations over which the group can block any of the spot. Wafers no column meets are
    left out. ``ray_ranges`` as for ``column_ranges``."""
    beta = spot_frame(layout.beam.direction, layout.lift_axis)[3]
    reach = spot.half_height / beta
    spans = []
    for index, wafer in enumerate(wafers):
        ranges = column_ranges(layout, wafer, spot, columns, ray_ranges)
        found = [r for r in ranges if r is not None]
        if found:
            spans.append((min(r[0] for r in found) - reach, max(r[1] for r in found) + reach,
                          index, ranges))
    spans.sort(key=lambda x: (x[0], x[1]))
    groups = []
    for lo, hi, index, ranges in spans:
        if groups and lo <= groups[-1][2][1]:
            members, member_ranges, (glo, ghi) = groups[-1]
            groups[-1] = (members + [index], member_ranges + [ranges], (glo, max(ghi, hi)))
        else:
            groups.append(([index], [ranges], (lo, hi)))
    return groups
