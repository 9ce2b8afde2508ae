"""Slow scanning's arm motions (SPEC §13): the jab and the sweep of each pocket, exactly.

At each pocket of the scanned carrier, at the height of a seated wafer's mid-thickness
(seat + t/2, a scan position), the robot may

- **jab**: advance the fork along its heading (horizontal, across the beam, towards the carrier)
  by ``jab`` mm and back. A through-beam fork straddles the wafer's edge, so the jab goes its
  whole reach; the beam translates, and the advance at which it is first blocked (the pocket's
  **front**) is the lower end of a closed-form translation range (``geometry.translation_range``,
  the lift's closed form along another axis). Measured from the start pose; None when nothing is
  met within ``jab``. With a jab the pocket's Z steps are made with the fork in, advanced by
  ``jab`` (``stepping_layout``): the start pose may then stand clear in front of the carrier,
  where the jab can measure a protrusion.
- **sweep**: at the jab's deepest point (or the start pose without a jab) turn the wrist by
  -``sweep`` .. +``sweep`` degrees. The wrist axis is
  vertical, ``sweep_radius`` mm behind the beam's midpoint along the heading (260 mm on the
  bundled robot). The pocket's **sweep** is the pair (first, last): the lowest and the highest
  wrist angle (degrees, counter-clockwise seen from above) at which the beam is blocked.

Sweep accuracy. For a level wafer (its axis vertical, the wrist's axis) the beam's part inside
the wafer's thickness band turns in a plane: the blocked angles change only where an end of that
part crosses the rim or its line is tangent to the rim, both closed forms (a cos φ + b sin φ = k);
the blocked state is tested between consecutive candidates. Exact up to rounding (≤ 1e-9 deg,
tested). Any other wafer (tilted, cross-slotted) is bracketed on a grid of at most
``SWEEP_GRID_DEG`` and each change bisected with the exact test to ``SWEEP_TOLERANCE_DEG``; a
blocked interval narrower than the grid step can be missed there (documented:
docs/tutorials/slow-scanning.md).

What the MCS judges from them: a front nearer than a seated wafer's by more than the protrusion
limit is a protruding wafer (6, beside the load port's check: the jab adds evidence, it never
clears a wafer the load port sees sticking out, which a jab at seat + t/2 passes over when the
wafer sits low or high in its seat window); a sweep whose centre is turned from a seated
wafer's by more than the position tolerance, as a sideways shift at the wafer's centre, is a
position error (5), with the reason as a warning.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .. import schema
from ..geometry.beam import TOUCH_TOLERANCE, beam_hits_wafer, wafer_bounds
from ..geometry.ranges import merged_ranges, translation_range
from ..mapping import (
    _SEVERITY,
    LIMIT_SLACK,
    POSITION_ERROR,
    PROTRUDING,
    UNSCANNED,
    SlotMap,
    SlotState,
)
from ..model import Beam, Wafer

# Keys of [scan] and parameters.txt for slow scanning (SPEC §13), with their checks. The
# defaults live on ScanParameters (model.py).
SETTING_KEYS = {
    "jab": schema.non_negative,            # mm, 0: no jab
    "sweep": schema.non_negative,          # degrees, 0: no sweep
    "sweep_radius": schema.positive,       # mm from the wrist axis to the beam's midpoint
    "arm_speed": schema.positive,          # mm/s, the jab's straight advance
    "arm_acceleration": schema.positive,   # mm/s²
    "wrist_speed": schema.positive,        # deg/s, the sweep
    "wrist_acceleration": schema.positive,  # deg/s²
}
SETTING_DEFAULTS = {"jab": 0.0, "sweep": 0.0, "sweep_radius": 260.0, "arm_speed": 250.0,
                    "arm_acceleration": 1000.0, "wrist_speed": 90.0, "wrist_acceleration": 360.0}
MAX_SWEEP_DEG = 90.0  # a wrist turned further would swing the fork into the carrier's walls

SWEEP_TOLERANCE_DEG = 1e-9
SWEEP_GRID_DEG = 0.005


def setting_problem(key, value):
    """A message when a slow-scan setting's value makes no sense together (beyond its check)."""
    if key == "sweep" and value > MAX_SWEEP_DEG:
        return f"must be at most {MAX_SWEEP_DEG:g} degrees, got {value:g}"
    return None


def given_values(scan):
    """The slow-scan settings that differ from their defaults, in SETTING_KEYS' order: written
    to parameters.txt and results.txt only then, so a scan without them lists what it did."""
    return {k: getattr(scan, k) for k in SETTING_KEYS
            if getattr(scan, k, SETTING_DEFAULTS[k]) != SETTING_DEFAULTS[k]}


def probes_pockets(scan):
    """True when a slow scan makes a jab or a sweep at each pocket."""
    return scan.mode == "slow" and (scan.jab > 0.0 or scan.sweep > 0.0)


# --- geometry ----------------------------------------------------------------------------------

def heading(layout):
    """The fork's heading: the horizontal unit vector across the beam that points into the
    scanned carrier (against its ``front``). ValueError for a vertical beam."""
    ex, ey, _ = layout.beam.direction
    norm = math.hypot(ex, ey)
    if norm < 1e-12:
        raise ValueError("the beam is vertical: the fork has no heading to jab along")
    hx, hy = -ey / norm, ex / norm
    fx, fy = layout.scanned_carrier.front
    if hx * fx + hy * fy > 0.0:
        hx, hy = -hx, -hy
    return (hx, hy, 0.0)


def emitter_at(layout, z, advance=0.0):
    """The emitter at scan position z after the fork advanced ``advance`` mm along its heading."""
    hx, hy, _ = heading(layout)
    x, y, zz = layout.emitter_at(z)
    return (x + advance * hx, y + advance * hy, zz)


def wrist_axis(layout, z, advance=0.0):
    """(x, y) of the vertical wrist axis: ``sweep_radius`` behind the beam's midpoint."""
    hx, hy, _ = heading(layout)
    ox, oy, _ = emitter_at(layout, z, advance)
    ex, ey, _ = layout.beam.direction
    half = 0.5 * layout.beam.length
    radius = layout.scan.sweep_radius
    return (ox + half * ex - radius * hx, oy + half * ey - radius * hy)


def _turn_xy(x, y, cx, cy, degrees):
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    dx, dy = x - cx, y - cy
    return (cx + c * dx - s * dy, cy + s * dx + c * dy)


def beam_at(layout, z, advance=0.0, turn=0.0):
    """The beam at scan position z, the fork advanced ``advance`` mm and the wrist turned by
    ``turn`` degrees (counter-clockwise seen from above): (emitter, Beam)."""
    emitter = emitter_at(layout, z, advance)
    beam = layout.beam
    if turn == 0.0:
        return emitter, Beam(emitter, beam.direction, beam.length)
    wx, wy = wrist_axis(layout, z, advance)
    x, y = _turn_xy(emitter[0], emitter[1], wx, wy, turn)
    ex, ey, ez = beam.direction
    dx, dy = _turn_xy(ex, ey, 0.0, 0.0, turn)
    moved = (x, y, emitter[2])
    return moved, Beam(moved, (dx, dy, ez), beam.length)


def _turned_wafer(wafer, wx, wy, degrees):
    """The wafer turned about the vertical axis through (wx, wy): turning the beam by +a is
    turning the wafers by -a."""
    cx, cy = _turn_xy(wafer.center[0], wafer.center[1], wx, wy, degrees)
    nx, ny = _turn_xy(wafer.normal[0], wafer.normal[1], 0.0, 0.0, degrees)
    return Wafer(wafer.name, (cx, cy, wafer.center[2]), (nx, ny, wafer.normal[2]),
                 wafer.diameter, wafer.thickness)


def wafers_near(layout, z):
    """The wafers whose Z extent the beam at scan position z can reach (the arm's motions are
    horizontal, so they never change which heights the beam spans)."""
    beam = layout.beam
    rise = beam.length * beam.direction[2]
    low, high = z + min(0.0, rise), z + max(0.0, rise)
    found = []
    for wafer in layout.wafers:
        (_, _, z0), (_, _, z1) = wafer_bounds(wafer)
        if z0 - 1e-6 <= high and low <= z1 + 1e-6:
            found.append(wafer)
    return found


def jab_front(layout, z, reach, wafers=None, tol=TOUCH_TOLERANCE):
    """The advance (mm, 0..reach) along the heading at which the beam at scan position z is
    first blocked, or None: the least lower end of the wafers' translation ranges."""
    emitter = layout.emitter_at(z)
    axis = heading(layout)
    beam = Beam(emitter, layout.beam.direction, layout.beam.length)
    front = None
    for wafer in (wafers_near(layout, z) if wafers is None else wafers):
        span = translation_range(emitter, beam, axis, wafer, tol)
        if span is None or span[1] < 0.0 or span[0] > reach:
            continue
        met = max(span[0], 0.0)
        front = met if front is None else min(front, met)
    return front


def _solve_cos_sin(a, b, k):
    """Angles (degrees) with a cos φ + b sin φ = k."""
    m = math.hypot(a, b)
    if m == 0.0 or abs(k) > m:
        return []
    base = math.atan2(b, a)
    spread = math.acos(max(-1.0, min(1.0, k / m)))
    return [math.degrees(base - spread), math.degrees(base + spread)]


def _wrap(degrees):
    return (degrees + 180.0) % 360.0 - 180.0


def _level_candidates(emitter, beam, wafer, wx, wy, tol):
    """Wrist angles at which the blocked state of a level wafer can change (see the module's
    docstring); None when the beam never enters the wafer's thickness band."""
    t = wafer.thickness
    ox, oy, oz = emitter
    ex, ey, ez = beam.direction
    h0 = oz - wafer.center[2]
    lo, hi = 0.0, beam.length
    if ez == 0.0:
        if not -tol <= h0 <= t + tol:
            return None
    else:
        a, b = (-tol - h0) / ez, (t + tol - h0) / ez
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
        if lo > hi:
            return None
    cx, cy = wafer.center[0] - wx, wafer.center[1] - wy
    r = wafer.radius + tol
    ends = [(ox + lam * ex - wx, oy + lam * ey - wy) for lam in (lo, hi)]
    angles = []
    for px, py in ends:  # an end of the band's part on the rim
        k = 0.5 * (px * px + py * py + cx * cx + cy * cy - r * r)
        angles += _solve_cos_sin(px * cx + py * cy, px * cy - py * cx, k)
    ux, uy = ends[1][0] - ends[0][0], ends[1][1] - ends[0][1]
    norm = math.hypot(ux, uy)
    if norm > 0.0:  # the part's line tangent to the rim
        nx, ny = -uy / norm, ux / norm
        d0 = ends[0][0] * nx + ends[0][1] * ny
        for k in (d0 + r, d0 - r):
            angles += _solve_cos_sin(nx * cx + ny * cy, nx * cy - ny * cx, k)
    # The beam turned by +φ meets the wafer as the wafer turned by -φ does: the candidates are
    # angles of the beam's turn, so they are solved with the beam's points turned (above).
    return angles


def turn_bounds(amplitude):
    """(low, high) wrist angles, degrees: a sweep's amplitude A is (-A, +A); a pair is kept (the
    angles a sweep reached, SPEC §13 amended)."""
    if isinstance(amplitude, (tuple, list)):
        return float(amplitude[0]), float(amplitude[1])
    return -float(amplitude), float(amplitude)


def sweep_pair(layout, z, advance, amplitude, wafers=None, tol=TOUCH_TOLERANCE, exact=True):
    """(first, last): the lowest and highest wrist turn in [-amplitude, +amplitude] degrees (or
    in [low, high] when ``amplitude`` is that pair) at which the beam (scan position z, fork
    advanced ``advance``) is blocked; None if never. ``exact=False`` forces the
    bracket-and-bisect path for every wafer (for tests)."""
    wafers = wafers_near(layout, z) if wafers is None else wafers
    if not wafers:
        return None
    emitter, beam = beam_at(layout, z, advance)
    wx, wy = wrist_axis(layout, z, advance)
    first = last = None
    for wafer in wafers:
        level = exact and wafer.normal[0] == 0.0 and wafer.normal[1] == 0.0
        span = (_level_span(emitter, beam, wafer, wx, wy, amplitude, tol) if level
                else _bisected_span(emitter, beam, wafer, wx, wy, amplitude, tol))
        if span is None:
            continue
        first = span[0] if first is None else min(first, span[0])
        last = span[1] if last is None else max(last, span[1])
    return None if first is None else (first, last)


def _blocked(emitter, beam, wafer, wx, wy, turn, tol):
    return beam_hits_wafer(emitter, beam, _turned_wafer(wafer, wx, wy, -turn), tol)


def _level_span(emitter, beam, wafer, wx, wy, amplitude, tol):
    angles = _level_candidates(emitter, beam, wafer, wx, wy, tol)
    if angles is None:
        return None
    low, high = turn_bounds(amplitude)
    points = sorted({low, high} | {a for a in map(_wrap, angles) if low < a < high})
    blocked = []
    for i, a in enumerate(points):
        if _blocked(emitter, beam, wafer, wx, wy, a, tol):
            blocked.append(a)
        if i + 1 < len(points):
            mid = 0.5 * (a + points[i + 1])
            if _blocked(emitter, beam, wafer, wx, wy, mid, tol):
                blocked += [a, points[i + 1]]
    return (min(blocked), max(blocked)) if blocked else None


def _bisect(emitter, beam, wafer, wx, wy, clear, blocked, tol):
    """The boundary between a clear and a blocked wrist angle, to SWEEP_TOLERANCE_DEG."""
    while abs(blocked - clear) > SWEEP_TOLERANCE_DEG:
        mid = 0.5 * (clear + blocked)
        if mid in (clear, blocked):
            break
        if _blocked(emitter, beam, wafer, wx, wy, mid, tol):
            blocked = mid
        else:
            clear = mid
    return blocked


def _bisected_span(emitter, beam, wafer, wx, wy, amplitude, tol):
    import numpy as np

    from ..geometry.beam import beam_hits_wafers

    low, high = turn_bounds(amplitude)
    count = max(3, int(math.ceil((high - low) / SWEEP_GRID_DEG)) + 1)
    grid = np.linspace(low, high, count)
    a = np.radians(-grid)
    c, s = np.cos(a), np.sin(a)
    dx, dy = wafer.center[0] - wx, wafer.center[1] - wy
    nx, ny, nz = wafer.normal
    hits = beam_hits_wafers(emitter[0], emitter[1], emitter[2], beam,
                            wx + c * dx - s * dy, wy + s * dx + c * dy, wafer.center[2],
                            c * nx - s * ny, s * nx + c * ny, nz, wafer.radius, wafer.thickness,
                            tol)
    where = np.flatnonzero(hits)
    if where.size == 0:
        return None
    i, j = int(where[0]), int(where[-1])
    first = float(grid[i]) if i == 0 else _bisect(emitter, beam, wafer, wx, wy, float(grid[i - 1]),
                                                  float(grid[i]), tol)
    last = float(grid[j]) if j == count - 1 else _bisect(emitter, beam, wafer, wx, wy,
                                                         float(grid[j + 1]), float(grid[j]), tol)
    return (first, last)


# --- the tines during the sweep ----------------------------------------------------------------
#
# The fork's tines are the beam's two ends. Turning about a wrist behind the beam, a tine swings
# on a circle about the wrist axis; where it lies inside a wafer's rim while at that wafer's
# height, a real fork would strike the wafer. The sweep is still made and reported as SPEC §13
# builds it; these ranges say where it could not be (SPEC §3, honest results). For the bundled
# robot's 160 mm beam 260 mm in front of the wrist, the sweep's edges are exactly where a tine
# leaves the rim, so every sweep that finds both edges has a strike range beside each.

def tine_points(layout, z, advance, turn):
    """The two tines (the beam's ends, (x, y, z) in mm) at scan position z, the fork advanced
    ``advance`` mm and the wrist turned by ``turn`` degrees."""
    emitter, beam = beam_at(layout, z, advance, turn)
    return (emitter, tuple(o + beam.length * d for o, d in zip(emitter, beam.direction)))


def tine_inside(point, direction, wafer, tol):
    """True when the point lies in the wafer's solid (grown by ``tol``): the engines' exact
    per-ray test on a beam of length 0 at the point."""
    return beam_hits_wafer(point, Beam(point, direction, 0.0), wafer, tol)


def _tine_spans(emitter, beam, end, wafer, wx, wy, amplitude, tol, exact=True):
    """The wrist-angle intervals in [-amplitude, +amplitude] degrees over which the beam's end
    ``end`` (0: the emitter's, 1: the receiver's) is inside ``wafer``; a list of (low, high).

    A level flat wafer is turned in its own plane, so the tine's height against the wafer does
    not change and it crosses the rim where a cos φ + b sin φ = k (closed form, the sweep's own
    end crossing); the state between consecutive crossings is tested exactly. Any other wafer
    (tilted, bowed) is bracketed on a grid of at most SWEEP_GRID_DEG and each change bisected
    with the exact test to SWEEP_TOLERANCE_DEG."""
    lam = end * beam.length
    px = emitter[0] + lam * beam.direction[0]
    py = emitter[1] + lam * beam.direction[1]
    pz = emitter[2] + lam * beam.direction[2]

    def inside(turn):
        x, y = _turn_xy(px, py, wx, wy, turn)
        dx, dy = _turn_xy(beam.direction[0], beam.direction[1], 0.0, 0.0, turn)
        return tine_inside((x, y, pz), (dx, dy, beam.direction[2]), wafer, tol)

    low, high = turn_bounds(amplitude)
    level = exact and wafer.normal[0] == 0.0 and wafer.normal[1] == 0.0 and not wafer.bow
    if level:
        ux, uy = px - wx, py - wy
        cx, cy = wafer.center[0] - wx, wafer.center[1] - wy
        r = wafer.radius + tol
        k = 0.5 * (ux * ux + uy * uy + cx * cx + cy * cy - r * r)
        crossings = _solve_cos_sin(ux * cx + uy * cy, ux * cy - uy * cx, k)
        points = sorted({low, high} | {a for a in map(_wrap, crossings) if low < a < high})
        spans = []
        for a, b in zip(points, points[1:]):
            if inside(0.5 * (a + b)):
                spans.append((a, b))
        return merged_ranges(spans)
    import numpy as np

    count = max(3, int(math.ceil((high - low) / SWEEP_GRID_DEG)) + 1)
    grid = np.linspace(low, high, count)
    states = (_tine_grid(px, py, pz, beam.direction, wafer, wx, wy, grid, tol)
              if not wafer.bow else np.array([inside(float(a)) for a in grid], dtype=bool))
    # Grid indices where the state changes, each bisected with the exact test.
    edges = [-1] + [int(i) for i in np.flatnonzero(states[1:] != states[:-1])] + [count - 1]
    spans = []
    for i, j in zip(edges, edges[1:]):
        if not states[j]:
            continue  # a clear stretch
        first = low if i < 0 else bisect_boundary(inside, float(grid[i]), float(grid[i + 1]))
        last = (high if j == count - 1
                else bisect_boundary(inside, float(grid[j + 1]), float(grid[j])))
        spans.append((first, last))
    return spans


def _tine_grid(px, py, pz, direction, wafer, wx, wy, grid, tol):
    """The tine at (px, py, pz) inside the flat wafer at each wrist angle of ``grid``: the
    engines' array test, the wafer turned the other way about the wrist (as _bisected_span)."""
    import numpy as np

    from ..geometry.beam import beam_hits_wafers

    a = np.radians(-grid)
    c, s = np.cos(a), np.sin(a)
    dx, dy = wafer.center[0] - wx, wafer.center[1] - wy
    nx, ny, nz = wafer.normal
    hits = beam_hits_wafers(px, py, pz, Beam((px, py, pz), direction, 0.0),
                            wx + c * dx - s * dy, wy + s * dx + c * dy, wafer.center[2],
                            c * nx - s * ny, s * nx + c * ny, nz, wafer.radius, wafer.thickness,
                            tol)
    return np.asarray(hits, dtype=bool)


def bisect_boundary(inside, clear, within, tolerance=None):
    """The boundary between a value where ``inside`` is False (``clear``) and one where it is
    True (``within``), to ``tolerance`` (default SWEEP_TOLERANCE_DEG, for wrist angles): the last
    value found inside."""
    tolerance = SWEEP_TOLERANCE_DEG if tolerance is None else tolerance
    while abs(within - clear) > tolerance:
        mid = 0.5 * (clear + within)
        if mid in (clear, within):
            break
        if inside(mid):
            within = mid
        else:
            clear = mid
    return within


def sweep_strikes(layout, z, advance, amplitude, wafers=None, tol=TOUCH_TOLERANCE, exact=True):
    """The wrist-angle ranges (degrees, a tuple of (low, high), in order) in [-amplitude,
    +amplitude] over which a tine of the fork (an end of the beam at scan position z, the fork
    advanced ``advance``) lies inside a wafer: within its rim while at a height within its
    thickness, where a real fork would strike it. Empty when never. Level wafers are exact up
    to rounding (≤ 1e-9 deg, tested), others bisected to SWEEP_TOLERANCE_DEG on a grid of
    SWEEP_GRID_DEG (a strike narrower than that can be missed). ``exact=False`` forces the
    bracket-and-bisect path for every wafer (for tests)."""
    by_tine = tine_strikes(layout, z, advance, amplitude, wafers, tol, exact)
    return tuple(merged_ranges(list(by_tine[0] + by_tine[1])))


def tine_strikes(layout, z, advance, amplitude, wafers=None, tol=TOUCH_TOLERANCE, exact=True):
    """``sweep_strikes`` tine by tine: (the emitter's ranges, the receiver's ranges), each a
    tuple of (low, high) degrees, for drawing each tine's path inside the wafer."""
    wafers = wafers_near(layout, z) if wafers is None else wafers
    emitter, beam = beam_at(layout, z, advance)
    wx, wy = wrist_axis(layout, z, advance)
    return tuple(tuple(merged_ranges([span for wafer in wafers
                                for span in _tine_spans(emitter, beam, end, wafer, wx, wy,
                                                        amplitude, tol, exact)]))
                 for end in (0, 1))


def strike_words(strike):
    """The strike ranges as words: 'from -32.588 to -1.618 deg and from +1.618 to +32.588 deg'."""
    return " and ".join(f"from {a:+.3f} to {b:+.3f} deg" for a, b in strike)


def strike_warnings(probes):
    """One warning line per set of pockets whose sweep turns a tine into a wafer over the same
    ranges (to the printed 0.001°), naming the slots; none for pockets without a strike."""
    grouped = {}
    for p in probes:
        if p.strike:
            grouped.setdefault(strike_words(p.strike), []).append(p.slot)
    return [f"slot{'s' if len(slots) > 1 else ''} {', '.join(map(str, slots))}: the sweep turns "
            f"a tine (an end of the beam) into the wafer {words} (a real fork would strike "
            f"it)" for words, slots in grouped.items()]


# --- per pocket --------------------------------------------------------------------------------

@dataclass(frozen=True)
class PocketProbe:
    """What the jab and the sweep found at one pocket (SPEC §13). ``z``: the scan position they
    were made at; ``front``: advance at first block (mm) or None; ``depth``: the advance the sweep
    was made at; ``sweep``: (first, last) degrees or None; ``expected_front`` and
    ``expected_sweep``: the same for a wafer seated in this pocket; ``shift``: the sideways shift
    (mm, along the carrier's left-to-right) the sweep's centre shows, or None; ``strike``: the
    wrist-angle ranges ((low, high) degrees) over which a tine was inside a wafer
    (``sweep_strikes``), empty when none or no sweep; ``reached``: (low, high), the wrist angles
    the sweep turned to (SPEC §13 amended: each side stops where the fork would come closer
    than clearance_min; the whole ±sweep when nothing stopped it or no robot was checked),
    None without a sweep."""

    slot: int
    z: float
    front: float | None
    depth: float
    sweep: tuple | None
    expected_front: float | None = None
    expected_sweep: tuple | None = None
    shift: float | None = None
    strike: tuple = ()
    reached: tuple | None = None


def seated_wafer(carrier, slot):
    """The nominal wafer seated in a slot of the carrier: what the MCS compares against."""
    cx, cy = carrier.center
    return Wafer(f"seated_{slot}", (cx, cy, carrier.seat_z(slot)), (0.0, 0.0, 1.0),
                 carrier.wafer_diameter, carrier.wafer_thickness)


def pocket_height(plan, slot):
    """The scan position of a pocket's jab and sweep: a seated wafer's mid-thickness."""
    return plan.seat_z(slot) + 0.5 * plan.wafer_thickness


def probe_pocket(layout, slot, z, measure=None, turn_limits=None):
    """The jab and the sweep at one pocket. ``measure(z, reach, (low, high))`` -> (front, sweep)
    measures them another way (the CAD layer's ``document`` engine, through the robot);
    by default the closed forms above. ``turn_limits(slot, z, depth, amplitude)`` -> (low,
    high): how far the sweep may turn each way (the robot layer's clearance, SPEC §13
    amended); by default the whole ±sweep."""
    scan = layout.scan
    depth = scan.jab
    reached = None
    if scan.sweep > 0.0:
        reached = ((-scan.sweep, scan.sweep) if turn_limits is None
                   else tuple(turn_limits(slot, z, depth, scan.sweep)))
    if measure is None:
        front = jab_front(layout, z, scan.jab) if scan.jab > 0.0 else None
        sweep = sweep_pair(layout, z, depth, reached) if scan.sweep > 0.0 else None
    else:
        front, sweep = measure(z, scan.jab, reached if reached is not None else 0.0)
    carrier = layout.scanned_carrier
    nominal = [seated_wafer(carrier, slot)]
    # The seated wafer's front edge as the jab would meet it: negative when the start pose's
    # beam already crosses it (the jab then cannot measure a protrusion). None: out of reach.
    emitter = layout.emitter_at(z)
    span = translation_range(emitter, Beam(emitter, layout.beam.direction, layout.beam.length),
                             heading(layout), nominal[0], 0.0)
    expected_front = None if span is None else span[0]
    expected_sweep = (sweep_pair(layout, z, depth, reached, nominal)
                      if scan.sweep > 0.0 else None)
    shift = None
    # A sweep blocked at an end of its turn has no edge there: no shift is read from it.
    at_end = any(found is not None and any(abs(a - b) <= SWEEP_TOLERANCE_DEG
                                           for a, b in zip(found, turn_bounds(reached)))
                 for found in (sweep, expected_sweep))
    if sweep is not None and expected_sweep is not None and not at_end:
        shift = _sideways_shift(layout, z, depth, carrier, slot,
                                0.5 * (sweep[0] + sweep[1])
                                - 0.5 * (expected_sweep[0] + expected_sweep[1]))
    # Where the sweep turns a tine into a wafer (honest results, SPEC §3): the layout's own
    # geometry, whichever way the sweep was measured (the document engine agrees with it).
    strike = sweep_strikes(layout, z, depth, reached) if scan.sweep > 0.0 else ()
    return PocketProbe(slot, z, front, depth, sweep, expected_front, expected_sweep, shift,
                       strike, reached)


def _sideways_shift(layout, z, depth, carrier, slot, turned):
    """A sweep centred ``turned`` degrees from a seated wafer's shows the wafer turned by that
    much about the wrist axis (the blocked angles of a turned wafer are the seated one's,
    turned): its centre's displacement across the carrier, in mm."""
    wx, wy = wrist_axis(layout, z, depth)
    cx, cy = carrier.center
    x, y = _turn_xy(cx, cy, wx, wy, turned)
    lx, ly = carrier.lateral
    return (x - cx) * lx + (y - cy) * ly


def stepping_layout(layout):
    """The layout a slow scan's Z steps are made in: with a jab, the fork is in the pocket,
    advanced by ``jab`` along its heading; otherwise the layout itself."""
    scan = layout.scan
    if scan.mode != "slow" or scan.jab <= 0.0:
        return layout
    emitter = emitter_at(layout, layout.beam.emitter[2], scan.jab)
    return replace(layout, beam=Beam(emitter, layout.beam.direction, layout.beam.length))


def probe_pockets(layout, plan, slots, measure=None, turn_limits=None):
    """The jab and sweep of each listed slot, in order (a tuple of PocketProbe)."""
    return tuple(probe_pocket(layout, slot, pocket_height(plan, slot), measure, turn_limits)
                 for slot in slots)


def judge(layout, plan, probes):
    """From the pockets' probes: (slots protruding by the jab, {slot off position by the sweep:
    why}, warnings), each reason and warning a sentence (SPEC §3 "Honest results", §13)."""
    scan = layout.scan
    protruding, off, warnings = [], {}, []
    blind, stopped = [], {}
    for p in probes:
        if scan.jab > 0.0 and p.expected_front is not None:
            if p.front is not None and p.expected_front - p.front > plan.protrusion_limit \
                    + LIMIT_SLACK:
                protruding.append(p.slot)
            elif p.front is not None and p.front <= 0.0 \
                    and p.expected_front <= plan.protrusion_limit + LIMIT_SLACK:
                blind.append(p.slot)
        if scan.sweep > 0.0 and p.reached == (0.0, 0.0):
            warnings.append(f"slot {p.slot}: the sweep could not turn: before it turns the "
                            f"fork is already within clearance_min "
                            f"({layout.mapping.clearance_min:g} mm) of what is in the pocket "
                            f"(a seated wafer would leave it room), so no position is judged "
                            f"from it")
        elif p.sweep is not None and scan.sweep > 0.0:
            low, high = p.reached or (-scan.sweep, scan.sweep)
            ends = [a for a, end in zip(p.sweep, (low, high))
                    if abs(a - end) <= SWEEP_TOLERANCE_DEG]
            short = [a for a in ends if abs(a) < scan.sweep - SWEEP_TOLERANCE_DEG]
            if short:
                # SPEC §13 amended: a side stopped by clearance_min with the beam still blocked.
                stopped.setdefault(f"{low:+.3f} .. {high:+.3f} deg", []).append(p.slot)
            elif ends:
                warnings.append(f"slot {p.slot}: the sweep is still blocked at its end "
                                f"({', '.join(f'{a:+g}' for a in ends)} deg): its edges are not "
                                f"known, so no position is judged from it; widen the sweep")
            elif p.shift is not None and abs(p.shift) > plan.position_tolerance + LIMIT_SLACK:
                side = "right" if p.shift > 0 else "left"
                off[p.slot] = (
                    f"slot {p.slot}: the sweep ({p.sweep[0]:+.3f} to {p.sweep[1]:+.3f} deg) is "
                    f"centred {0.5 * (p.sweep[0] + p.sweep[1]):+.3f} deg where a seated wafer's "
                    f"is {0.5 * (p.expected_sweep[0] + p.expected_sweep[1]):+.3f} deg: the wafer "
                    f"sits {abs(p.shift):.3f} mm to the {side}, beyond the position tolerance "
                    f"{plan.position_tolerance:g} mm: position error (5)")
    for words, slots in stopped.items():
        warnings.append(
            f"slot{'s' if len(slots) > 1 else ''} {', '.join(map(str, slots))}: the sweep "
            f"stopped where the fork comes within clearance_min "
            f"({layout.mapping.clearance_min:g} mm) of a wafer ({words}), the beam still "
            f"blocked there: the wafer's edges lie beyond where the fork may turn, so no "
            f"position is judged from the sweep")
    warnings += strike_warnings(probes)
    if blind:
        warnings.append(f"the jab starts within the protrusion limit of a seated wafer's front "
                        f"edge (slot{'s' if len(blind) > 1 else ''} "
                        f"{', '.join(map(str, blind))} blocked at the start pose): it cannot "
                        f"tell a protruding wafer there; start the scan further out")
    return protruding, off, warnings


def missed_protrusion_warnings(plan, probes, by_slot):
    """One warning per probed pocket whose jab did not find the protrusion the load port's check
    sees (``by_slot``: scan_result.protrusions_by_slot's slots): the slot still reads 6 (SPEC §4),
    and the words say what each sensor saw."""
    warnings = []
    for p in probes:
        seen = ", ".join(f"{name} {mm:.3f} mm" for name, mm in by_slot.get(p.slot, ()))
        if p.front is None:
            jab = "met nothing"
        else:
            jab = f"met the pocket's front at {p.front:.3f} mm"
            if p.expected_front is not None:
                jab += f" (a seated wafer's at {p.expected_front:.3f} mm)"
        warnings.append(f"slot {p.slot}: the jab at Z = {p.z:.3f} mm {jab}, but the load port's "
                        f"protrusion check sees {seen} out of the opening (limit "
                        f"{plan.protrusion_limit:g} mm): protruding (6)")
    return warnings


def with_position_errors(slot_map, slots):
    """The slot map with the listed slots raised to a position error (5) where that is worse
    than what they read; an unscanned or protruding slot stays as it is."""
    if not slots:
        return slot_map
    slots = set(slots)
    states = []
    for s in slot_map.slots:
        state = s.state
        if s.slot in slots and state != UNSCANNED and \
                _SEVERITY.index(POSITION_ERROR) > _SEVERITY.index(state) and state != PROTRUDING:
            state = POSITION_ERROR
        states.append(SlotState(s.slot, s.seat_z, state, s.runs))
    return SlotMap(tuple(states))


# --- duration ----------------------------------------------------------------------------------

def move_time(distance, speed, acceleration=math.inf):
    """Seconds for a point-to-point move of ``distance`` from rest to rest: a trapezoidal
    profile (a triangle when too short to reach ``speed``); infinite acceleration: distance/speed."""
    distance = abs(distance)
    if distance == 0.0:
        return 0.0
    if math.isinf(acceleration):
        return distance / speed
    if distance >= speed * speed / acceleration:
        return distance / speed + speed / acceleration
    return 2.0 * math.sqrt(distance / acceleration)


def lift_acceleration(scan):
    """The lift's acceleration (mm/s²): SPEC §10's [scan] acceleration where the scan has one,
    else infinite (full speed at once), its default there."""
    return getattr(scan, "acceleration", math.inf)


def fast_duration(scan):
    """Seconds of a fast scan: one stroke start_z..final_z at scan_speed (two for updown)."""
    stroke = move_time(scan.final_z - scan.start_z, scan.scan_speed, lift_acceleration(scan))
    return 2.0 * stroke if scan.direction == "updown" else stroke


def nominal_probes(scan, plan, slots):
    """The pockets a slow scan with these settings would probe (the listed slots), for its
    duration only: the height and depth of each jab and sweep, nothing found. Empty without a
    jab or a sweep. Lets a fast scan's result say what the slow one would take (SPEC §13)."""
    if not (scan.jab > 0.0 or scan.sweep > 0.0):
        return ()
    return tuple(PocketProbe(slot, pocket_height(plan, slot), None, scan.jab, None)
                 for slot in slots)


def slow_fast_notice(scan):
    """A warning when the scan is fast but asks for a jab or a sweep (only a slow scan makes
    them), else None."""
    if scan.mode == "slow" or not (scan.jab > 0.0 or scan.sweep > 0.0):
        return None
    asked = " and ".join(w for w, v in (("a jab", scan.jab), ("a sweep", scan.sweep)) if v > 0)
    return (f"{asked} {'are' if ' and ' in asked else 'is'} set but only a slow scan "
            f"(mode = slow) makes them: this fast scan's beam stayed at the start pose, and the "
            f"slow duration is what a slow scan with them would take"
            + (" at most (its sweeps turned all the way: a sweep stops short where the fork "
               "would come within clearance_min)" if scan.sweep > 0.0 else ""))


def slow_duration(scan, plan, probes=()):
    """Seconds of a slow scan: pocket by pocket (bottom up), the lift to the pocket's window,
    each step of it a move from rest to rest and a read at rest (sensor_response), then at
    seat + t/2 the jab out to its deepest point and back, and the sweep 0 -> -A -> +A -> 0 (or
    to the angles it reached)."""
    a_lift = lift_acceleration(scan)
    v = scan.scan_speed
    by_slot = {p.slot: p for p in probes}
    z = scan.start_z
    total = 0.0
    for slot in range(1, plan.slot_count + 1):
        low, high = plan.window(slot)
        k_lo = max(0, math.ceil((low - scan.start_z) / scan.z_step - 1e-9)) if scan.z_step else 0
        k_hi = min(scan.last_step, math.floor((high - scan.start_z) / scan.z_step + 1e-9)) \
            if scan.z_step else 0
        if scan.z_step and k_lo <= k_hi:
            first = scan.position(k_lo)
            total += move_time(first - z, v, a_lift)
            steps = k_hi - k_lo
            total += steps * move_time(scan.z_step, v, a_lift)
            total += (steps + 1) * scan.sensor_response
            z = scan.position(k_hi)
        elif not scan.z_step:
            total += move_time(low - z, v, a_lift) + move_time(high - low, v, a_lift)
            z = high
        probe = by_slot.get(slot)
        if probe is None:
            continue
        total += move_time(probe.z - z, v, a_lift)
        z = probe.z
        total += 2.0 * move_time(probe.depth, scan.arm_speed, scan.arm_acceleration)
        if scan.sweep > 0.0:
            # 0 -> low -> high -> 0: the angles it reached (SPEC §13 amended), else ±sweep.
            low, high = probe.reached or (-scan.sweep, scan.sweep)
            w, aw = scan.wrist_speed, scan.wrist_acceleration
            total += (move_time(low, w, aw) + move_time(high - low, w, aw)
                      + move_time(high, w, aw))
    return total
