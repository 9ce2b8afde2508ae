"""Drawing a sweep's layouts (SPEC §12): what every sample shares (``SweepBase``: the input
layout, its carrier, the recipe's plan and the state placed in each slot), and blocks of layouts
drawn from the tolerance file over arrays, block b's generator seeded by (seed, b) alone."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..mapping import CROSS, DOUBLE, EMPTY, POSITION_ERROR, PRESENT, PROTRUDING, THIN, SlotPlan
from ..model import Beam, Wafer

# Layouts per block: the unit the seeds are derived for. Fixed, never taken from the workers.
BLOCK_SIZE = 500
# The scenario's wafer states (core/files/scenario.py) by the truth code they place.
PLACED = {"absent": EMPTY, "present": PRESENT, "cross": CROSS, "double": DOUBLE, "thin": THIN,
          "misplaced": POSITION_ERROR, "protruding": PROTRUDING}
# The order [states] probabilities are laid out in for drawing: fixed (not the file's order).
STATE_DRAW_ORDER = ("absent", "present", "cross", "double", "thin", "misplaced", "protruding")


# --- the base: what every sample shares ------------------------------------------------------

@dataclass(frozen=True)
class SweepBase:
    """The INPUT layout reduced to what a sweep varies: the scanned carrier, the recipe (a
    ``SlotPlan``) and the state placed in each slot (truth codes, slot 1 first; the slot above a
    cross-slotted wafer is CROSS too, ``cross_start`` marks the lower one). ``clearance``: the
    ``[clearance]`` report's ClearanceCheck (core/sweep/clearance.py), None when not asked."""

    layout: object
    carrier: object
    plan: SlotPlan
    load: tuple
    cross_start: tuple
    clearance: object = None


def sweep_base(layout, plan=None, rules=None, clearance=None):
    """The ``SweepBase`` of a layout: its scanned carrier, the recipe (``plan``, default the
    layout's own; ``rules`` replaces its rule set) and the states its wafers were placed in,
    read from their geometry (``placed_states``); ``clearance``: a ClearanceCheck, or None."""
    from ..scan.scan_result import slot_plan

    carrier = layout.scanned_carrier
    plan = plan or slot_plan(carrier, layout.mapping)
    if rules is not None:
        plan = replace(plan, rules=rules)
    load, starts = placed_states(layout, carrier, plan)
    return SweepBase(layout, carrier, plan, tuple(load), tuple(starts), clearance)


def placed_states(layout, carrier, plan):
    """Per slot of the carrier, the state its wafers were placed in (truth codes), read from the
    wafers as the scenario builder seats them: a tilted wafer is cross-slotted (it and the slot
    above), one raised off its seat beyond the position window misplaced, one out of the
    opening beyond the protrusion limit protruding, a thin one thin, two in a slot double.
    Returns (states, cross_start)."""
    from ..geometry.beam import wafer_bounds
    from ..scan.scan_result import carrier_wafers, protrusion

    count = carrier.slot_count
    found = {s: [] for s in range(1, count + 1)}
    for wafer in carrier_wafers(carrier, layout.wafers):
        z0 = wafer_bounds(wafer)[0][2]
        slot = wafer.slot if wafer.slot is not None else plan.nearest_slot(z0)
        if 1 <= slot <= count:
            found[slot].append(wafer)
    states = [EMPTY] * count
    starts = [False] * count
    below, above = plan.position_window()
    for slot, wafers in found.items():
        if not wafers:
            continue
        w = wafers[0]
        offset = w.center[2] - carrier.seat_z(slot)
        if abs(w.normal[2]) < 1.0 - 1e-12 and slot < count:
            states[slot - 1] = states[slot] = CROSS
            starts[slot - 1] = True
        elif len(wafers) > 1:
            states[slot - 1] = DOUBLE
        elif protrusion(carrier, w) > plan.protrusion_limit:
            states[slot - 1] = PROTRUDING
        elif offset > above or -offset > below:
            states[slot - 1] = POSITION_ERROR
        elif w.thickness < plan.thickness_window()[0]:
            states[slot - 1] = THIN
        elif states[slot - 1] != CROSS:
            states[slot - 1] = PRESENT
    return states, starts


# --- drawing the samples ---------------------------------------------------------------------

def block_count(n):
    """How many blocks N layouts make."""
    return (n + BLOCK_SIZE - 1) // BLOCK_SIZE


def block_sizes(n):
    """The number of layouts in each block of an N-layout sweep (a list: for small N; a
    partition asks ``block_size`` block by block)."""
    return [block_size(n, b) for b in range(block_count(n))]


def block_size(n, block):
    """The number of layouts in block ``block`` of an N-layout sweep."""
    return min(BLOCK_SIZE, n - block * BLOCK_SIZE)


def layouts_in(n, blocks):
    """The number of layouts in ``blocks`` (contiguous, ascending) of an N-layout sweep."""
    if not len(blocks):
        return 0
    return min(n, (blocks[-1] + 1) * BLOCK_SIZE) - blocks[0] * BLOCK_SIZE


def block_rng(seed, block):
    """The generator of block ``block`` of a sweep with ``seed``: depends on nothing else."""
    import numpy as np

    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(int(block),)))


@dataclass
class Draws:
    """A block's sampled layouts as arrays: ``truth`` (m, S) placed state codes; per wafer
    (m, S, 2: a slot's wafer and a double's second) ``exists``, centre, normal, thickness,
    bow; per layout the beam's direction (m, 3), sensor_response (m,) and threshold_on (m,),
    None where the INPUT's value stands."""

    truth: object
    exists: object
    center: object   # (m, S, 2, 3)
    normal: object   # (m, S, 2, 3)
    thickness: object
    bow: object
    direction: object
    sensor_response: object
    threshold_on: object

    @property
    def count(self):
        return self.truth.shape[0]


def _tilted(n0, theta_deg, phi):
    """Rodrigues: the unit vectors ``n0`` (..., 3) turned by theta (deg) about the horizontal
    axes (cos phi, sin phi, 0). A zero angle leaves n0 exactly as it was."""
    import numpy as np

    th = np.radians(theta_deg)
    c, s = np.cos(th), np.sin(th)
    hx, hy = np.cos(phi), np.sin(phi)
    nx, ny, nz = n0[..., 0], n0[..., 1], n0[..., 2]
    # h x n0 with h = (hx, hy, 0)
    kx, ky, kz = hy * nz, -hx * nz, hx * ny - hy * nx
    hn = hx * nx + hy * ny
    out = np.stack([nx * c + kx * s + hx * hn * (1.0 - c),
                    ny * c + ky * s + hy * hn * (1.0 - c),
                    nz * c + kz * s], axis=-1)
    return out


def draw_block(base, tolerances, seed, block, count):
    """Draw ``count`` layouts of block ``block`` (``Draws``). The order of the draws is fixed
    (states, then each quantity in tolerances.DRAW_ORDER), so the seed alone decides them."""
    import numpy as np

    from ..files.scenario import MISPLACED_RISE, PROTRUDING_SHIFT, THIN_FACTOR
    from .distributions import DRAW_ORDER

    rng = block_rng(seed, block)
    carrier = base.carrier
    S = carrier.slot_count
    m = count
    # States: each slot drawn independently; a cross-slotted wafer takes the slot above too,
    # whose own draw is then void; one drawn in the top slot (no slot above) is seated present.
    if tolerances.states is not None:
        probs = dict(tolerances.states)
        p = np.array([probs.get(s, 0.0) for s in STATE_DRAW_ORDER])
        edges = np.cumsum(p)
        edges[-1] = 1.0
        u = rng.random((m, S))
        drawn = np.array([PLACED[s] for s in STATE_DRAW_ORDER])[
            np.minimum(np.searchsorted(edges, u, side="right"), len(p) - 1)]
        truth = np.empty((m, S), dtype=np.int8)
        start = np.zeros((m, S), dtype=bool)
        covered = np.zeros(m, dtype=bool)
        for s in range(S):
            own = drawn[:, s]
            crossing = (own == CROSS) & ~covered
            if s == S - 1:
                own = np.where(crossing, PRESENT, own)
                crossing = np.zeros(m, dtype=bool)
            truth[:, s] = np.where(covered, CROSS, own)
            start[:, s] = crossing
            covered = crossing
    else:
        truth = np.tile(np.array(base.load, dtype=np.int8), (m, 1))
        start = np.tile(np.array(base.cross_start, dtype=bool), (m, 1))
    draws = {}
    for name in DRAW_ORDER:
        dist = tolerances.get(name)
        if dist is None:
            continue
        per_wafer = name in ("seat_offset", "thickness", "bow", "tilt", "protrusion")
        draws[name] = _clipped(name, dist.draw(rng, (m, S, 2) if per_wafer else (m,)))
        if name == "tilt":
            draws["tilt_axis"] = rng.uniform(0.0, 2.0 * math.pi, (m, S, 2))
    zeros = np.zeros((m, S, 2))
    # The block's own array (the clipped draw, or a new one): its thin wafers changed in place.
    thickness = draws.get("thickness", np.full((m, S, 2), carrier.wafer_thickness))
    seat = np.array([carrier.seat_z(s) for s in range(1, S + 1)])
    cx, cy = carrier.center
    fx, fy = carrier.front
    kind = np.where(truth == CROSS, np.where(start, CROSS, -1), truth)  # -1: the cross's upper
    exists = np.zeros((m, S, 2), dtype=bool)
    exists[..., 0] = (kind != EMPTY) & (kind != -1)
    exists[..., 1] = kind == DOUBLE
    # The few wafers of a state are changed in place (the same floats as np.where's over the
    # whole block, without its arrays of every wafer).
    cross = kind == CROSS
    thickness[kind == THIN] *= THIN_FACTOR
    # The centre of each slot's first wafer (m, S); a double's second is placed on it below,
    # whatever its own seat and protrusion drew (drawn all the same: the seed decides them).
    z = np.broadcast_to(seat[None, :], (m, S)).copy()
    z[kind == POSITION_ERROR] += MISPLACED_RISE
    z[cross] += 0.5 * carrier.pitch
    shift = np.where(kind == PROTRUDING, PROTRUDING_SHIFT, 0.0) + \
        draws.get("protrusion", zeros)[..., 0]
    x = cx + shift * fx
    y = cy + shift * fy
    z = z + draws.get("seat_offset", zeros)[..., 0]
    if "beam_z" in draws:  # the beam higher than taught: every wafer lower on the scan's scale
        z = z - draws["beam_z"][:, None]
    normal = np.zeros((m, S, 2, 3))
    normal[..., 2] = 1.0
    slope = carrier.pitch / carrier.support_span
    sn = slope / math.sqrt(1.0 + slope * slope)
    cn = 1.0 / math.sqrt(1.0 + slope * slope)
    lx, ly = carrier.lateral
    cross_normal = np.array([-sn * lx, -sn * ly, cn])
    normal[cross] = cross_normal
    if "tilt" in draws:
        normal = _tilted(normal, draws["tilt"], draws["tilt_axis"])
    # A double's second wafer lies on the first, whatever its seat, tilt and protrusion: its
    # bottom face on the first's top face (the scenario's seat + t for a level pair). Written
    # coordinate by coordinate: (m, S) arrays, not (m, S, 3) ones whose innermost run is 3.
    center = np.empty((m, S, 2, 3))
    for axis, first in enumerate((x, y, z)):
        center[..., 0, axis] = first
        center[..., 1, axis] = first + thickness[..., 0] * normal[..., 0, axis]
        normal[..., 1, axis] = normal[..., 0, axis]
    bow = draws.get("bow", zeros + _base_bow(base))
    e0 = base.layout.beam.direction
    if "beam_tilt" in draws:
        direction = _beam_tilted(e0, draws["beam_tilt"])
    else:
        direction = np.tile(np.array(e0, dtype=float), (m, 1))
    return Draws(truth, exists, center, normal, thickness, bow, direction,
                 draws.get("sensor_response"), draws.get("threshold_on"))


# Limits no draw may pass (a normal's far tail): a thickness above 0, a response time not
# negative, a threshold in (0, 1].
_LIMITS = {"thickness": (1e-6, math.inf), "sensor_response": (0.0, math.inf),
           "threshold_on": (1e-6, 1.0)}


def _clipped(name, values):
    import numpy as np

    if name not in _LIMITS:
        return values
    return np.clip(values, *_LIMITS[name])


def _base_bow(base):
    """The INPUT's bow of its carrier's wafers (the first one's; 0 without wafers)."""
    from ..scan.scan_result import carrier_wafers

    for wafer in carrier_wafers(base.carrier, base.layout.wafers):
        return wafer.bow
    return 0.0


def _beam_tilted(e0, beta_deg):
    """The beam's direction ``e0`` turned by beta (deg, array) in its vertical plane."""
    import numpy as np

    ex, ey, ez = e0
    h = math.hypot(ex, ey)
    if h == 0.0:
        raise ValueError("beam_tilt: the beam runs vertically, it has no vertical plane")
    # k: the unit vector of the vertical plane normal to e0 (up for a level beam).
    kx, ky, kz = -ez * ex / h, -ez * ey / h, h
    b = np.radians(beta_deg)
    c, s = np.cos(b), np.sin(b)
    return np.stack([ex * c + kx * s, ey * c + ky * s, ez * c + kz * s], axis=-1)


def sample_layout(base, draws, i):
    """Layout ``i`` of a block as a normal ``Layout`` (for the scalar path and for scripts)."""
    from ..sensor.spot import Amplifier

    carrier = base.carrier
    wafers = []
    S = carrier.slot_count
    for s in range(S):
        for k in range(2):
            if not draws.exists[i, s, k]:
                continue
            wafers.append(Wafer(
                name=f"{carrier.name}_S{s + 1:02d}_{k}",
                center=tuple(float(v) for v in draws.center[i, s, k]),
                normal=tuple(float(v) for v in draws.normal[i, s, k]),
                diameter=carrier.wafer_diameter,
                thickness=float(draws.thickness[i, s, k]),
                carrier=carrier.name, slot=s + 1, bow=float(draws.bow[i, s, k])))
    layout = base.layout
    beam = Beam(layout.beam.emitter, tuple(float(v) for v in draws.direction[i]),
                layout.beam.length)
    scan = layout.scan
    if draws.sensor_response is not None:
        scan = replace(scan, sensor_response=float(draws.sensor_response[i]))
    amplifier = layout.amplifier
    if draws.threshold_on is not None:
        old = amplifier or Amplifier()
        on = float(draws.threshold_on[i])
        off = old.threshold_off if old.threshold_off is None else min(old.threshold_off, on)
        amplifier = Amplifier(on, off)
    others = tuple(c for c in layout.carriers if c.name == carrier.name)
    return replace(layout, carriers=others, carrier=carrier.name, wafers=tuple(wafers),
                   beam=beam, scan=scan, amplifier=amplifier)
