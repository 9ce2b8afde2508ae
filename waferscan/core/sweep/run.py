"""Monte Carlo sweeps (SPEC §12): does a recipe hold under real tolerances?

N layouts are drawn from an INPUT layout by a tolerance file (core/sweep/distributions.py); each is
scanned and mapped with the recipe, and the reported state of every slot is compared with the
state that was placed. The draws, the scan and the mapping run in numpy over blocks of layouts
at once (layouts x wafers), not as N scans in a Python loop:

- exact edges per wafer, in closed form (``geometry.ranges.translation_ranges``: the scalar
  ``translation_range`` over arrays, the same floats: a level wafer's faces, a tilted disc's
  extent along the lift through the corners of its region, a level bowed wafer's lowest bottom
  and highest top over the beam's chord);
- onto the step grid, where a grid position lies clearly inside or outside the edges; the rare
  wafer with an edge within ``GRID_MARGIN`` of a grid position, and the geometry the array
  formulas do not cover (a tilted bowed wafer), go through the scalar engine, so that the
  result is the scalar path's exactly (a test holds them equal on hundreds of layouts);
- runs per layout (overlapping intervals merged), latched as the scan latches them;
- the mapping, by either rule set, scattered per slot with the worst finding kept.

A beam spot, latching in motion or exact edges (z_step = 0) take the scalar path layout by
layout (``scalar_block``): slower, the same answers by construction. A beam spot read on the
step grid goes through core/sweep/spot_scan.py instead: the spot's column ranges of the whole block
over arrays, bit for bit the floats the scalar spot engine computes, then its strips and its
blocked fraction at every step for the whole block at once, the same floats again, and the
runs, latching and mapping layout by layout as the scalar path does them (tests hold every
state, reading and peak equal to the scalar path's).

Reproducibility: layouts are drawn in blocks of ``BLOCK_SIZE``; block b's generator is
SeedSequence(seed, spawn_key=(b,)). The samples depend only on the seed and N, whatever the
partitions the blocks are grouped into and the workers that run them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .. import mapping
from ..mapping import (
    CROSS,
    DOUBLE,
    EMPTY,
    LIMIT_SLACK,
    POSITION_ERROR,
    PRESENT,
    PROTRUDING,
    THIN,
    SlotPlan,
    map_slots,
)
from ..geometry.beam import TOUCH_TOLERANCE
from ..geometry.ranges import translation_ranges
from ..model import DOWN, SLOW, UP, UPDOWN, Beam, Wafer

# Layouts per block: the unit the seeds are derived for. Fixed, never taken from the workers.
BLOCK_SIZE = 500
# The wafers of a block whose beam ranges are computed at once (scan_block): 4,096 keep the
# temporaries in a core's cache. 100,000 layouts on this 2-core machine: 3.5-3.65 s on one
# process, 1.90-1.94 s on two, against 3.35-3.4 s and 1.71-1.73 s in chunks (the same results:
# every operation there is element by element).
SWEEP_CHUNK = 4096
# A grid position nearer than this (mm) to a wafer's edge is settled by the scalar engine's own
# test, not by the array formulas (which agree with it to ~1e-12 mm).
GRID_MARGIN = 1e-7
# Reported state code of an unscanned slot in the sweep's arrays (mapping.UNSCANNED is "?").
UNSCANNED = 7
# Summary names, indexed by state code (SPEC §12).
STATE_KEYS = ("empty", "present", "cross", "double", "thin", "position_error", "protruding",
              "unscanned")
# The scenario's wafer states (core/files/scenario.py) by the truth code they place.
PLACED = {"absent": EMPTY, "present": PRESENT, "cross": CROSS, "double": DOUBLE, "thin": THIN,
          "misplaced": POSITION_ERROR, "protruding": PROTRUDING}
# The order [states] probabilities are laid out in for drawing: fixed (not the file's order).
STATE_DRAW_ORDER = ("absent", "present", "cross", "double", "thin", "misplaced", "protruding")
# Rank of each state code in mapping's severity order (EMPTY < PRESENT < THIN < POSITION_ERROR
# < DOUBLE < CROSS < PROTRUDING).
_RANK = (0, 1, 5, 4, 2, 3, 6)
_BY_RANK = (EMPTY, PRESENT, THIN, POSITION_ERROR, DOUBLE, CROSS, PROTRUDING)


# --- the base: what every sample shares ------------------------------------------------------

@dataclass(frozen=True)
class SweepBase:
    """The INPUT layout reduced to what a sweep varies: the scanned carrier, the recipe (a
    ``SlotPlan``) and the state placed in each slot (truth codes, slot 1 first; the slot above a
    cross-slotted wafer is CROSS too, ``cross_start`` marks the lower one)."""

    layout: object
    carrier: object
    plan: SlotPlan
    load: tuple
    cross_start: tuple


def sweep_base(layout, plan=None, rules=None):
    """The ``SweepBase`` of a layout: its scanned carrier, the recipe (``plan``, default the
    layout's own; ``rules`` replaces its rule set) and the states its wafers were placed in,
    read from their geometry (``placed_states``)."""
    from ..scan.scan_result import slot_plan

    carrier = layout.scanned_carrier
    plan = plan or slot_plan(carrier, layout.mapping)
    if rules is not None:
        plan = replace(plan, rules=rules)
    load, starts = placed_states(layout, carrier, plan)
    return SweepBase(layout, carrier, plan, tuple(load), tuple(starts))


def placed_states(layout, carrier, plan):
    """Per slot of the carrier, the state its wafers were placed in (truth codes), read from the
    wafers as the scenario builder seats them: a tilted wafer is cross-slotted (it and the slot
    above), one raised off its seat beyond the position window misplaced, one out of the
    opening beyond the protrusion limit protruding, a thin one thin, two in a slot double.
    Returns (states, cross_start)."""
    from ..geometry.beam import wafer_bounds
    from ..scan.scan_result import _carrier_wafers, protrusion

    count = carrier.slot_count
    found = {s: [] for s in range(1, count + 1)}
    for wafer in _carrier_wafers(carrier, layout.wafers):
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
    """The number of layouts in each block of an N-layout sweep."""
    return [min(BLOCK_SIZE, n - b * BLOCK_SIZE) for b in range(block_count(n))]


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
    t_nominal = carrier.wafer_thickness
    t = draws.get("thickness", np.full((m, S, 2), t_nominal))
    seat = np.array([carrier.seat_z(s) for s in range(1, S + 1)])
    cx, cy = carrier.center
    fx, fy = carrier.front
    kind = np.where(truth == CROSS, np.where(start, CROSS, -1), truth)  # -1: the cross's upper
    exists = np.zeros((m, S, 2), dtype=bool)
    exists[..., 0] = (kind != EMPTY) & (kind != -1)
    exists[..., 1] = kind == DOUBLE
    z = np.broadcast_to(seat[None, :, None], (m, S, 2)).copy()
    z = np.where((kind == POSITION_ERROR)[..., None], z + MISPLACED_RISE, z)
    z = np.where((kind == CROSS)[..., None], z + 0.5 * carrier.pitch, z)
    thickness = np.where((kind == THIN)[..., None], THIN_FACTOR * t, t)
    shift = np.where((kind == PROTRUDING)[..., None], PROTRUDING_SHIFT, 0.0) + \
        draws.get("protrusion", zeros)
    x = cx + shift * fx
    y = cy + shift * fy
    z = z + draws.get("seat_offset", zeros)
    if "beam_z" in draws:  # the beam higher than taught: every wafer lower on the scan's scale
        z = z - draws["beam_z"][:, None, None]
    normal = np.zeros((m, S, 2, 3))
    normal[..., 2] = 1.0
    slope = carrier.pitch / carrier.support_span
    sn = slope / math.sqrt(1.0 + slope * slope)
    cn = 1.0 / math.sqrt(1.0 + slope * slope)
    lx, ly = carrier.lateral
    cross_normal = np.array([-sn * lx, -sn * ly, cn])
    normal = np.where((kind == CROSS)[..., None, None], cross_normal, normal)
    if "tilt" in draws:
        normal = _tilted(normal, draws["tilt"], draws["tilt_axis"])
    center = np.stack([x, y, z], axis=-1)
    # A double's second wafer lies on the first, whatever its seat, tilt and protrusion: its
    # bottom face on the first's top face (the scenario's seat + t for a level pair).
    center[..., 1, :] = center[..., 0, :] + thickness[..., 0, None] * normal[..., 0, :]
    normal[..., 1, :] = normal[..., 0, :]
    bow = draws.get("bow", zeros + _base_bow(base))
    e0 = base.layout.beam.direction
    direction = np.tile(np.array(e0, dtype=float), (m, 1))
    if "beam_tilt" in draws:
        direction = _beam_tilted(e0, draws["beam_tilt"])
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
    from ..scan.scan_result import _carrier_wafers

    for wafer in _carrier_wafers(base.carrier, base.layout.wafers):
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


# --- the scalar path (the oracle, and the spot's path) ---------------------------------------

def scalar_layout_states(base, layout, peaks=None, ray_ranges=None):
    """Reported state codes, measured thickness and bottom per slot (lists; None where a slot
    has no run) of one layout by the scalar path: ``scan_layout`` and the recipe's mapping.
    ``peaks``: a list to which the largest blocked fraction of each group of wafers a beam spot
    saw is appended (SPEC §10; none for the ideal beam). ``ray_ranges``: the block's centre-ray
    ranges (``spot_scan.range_table``), for a beam spot."""
    from ..mapping import unscanned_slots
    from ..scan.layout_scan import scan_layout
    from ..scan.scan_result import protruding_slots

    plan = base.plan
    result = scan_layout(layout, ray_ranges=ray_ranges)
    if peaks is not None and result.signal is not None:
        peaks.extend(group.peak for group in result.signal.groups)
    runs = [(r.bottom, r.top) for r in result.runs]
    flagged, _ = protruding_slots(base.carrier, plan, layout.wafers)
    unscanned = unscanned_slots(plan, (layout.scan.start_z, layout.scan.final_z))
    slot_map = map_slots(plan, runs, flagged, unscanned)
    states, thickness, bottom = [], [], []
    for slot in slot_map.slots:
        states.append(UNSCANNED if slot.state == mapping.UNSCANNED else slot.state)
        if slot.runs:
            run = result.runs[slot.runs[0]]
            thickness.append(run.diff)
            bottom.append(run.bottom)
        else:
            thickness.append(None)
            bottom.append(None)
    return states, thickness, bottom


def scalar_block(base, draws, peaks=None):
    """``scan_block``'s answer layout by layout through the scalar path (``peaks`` as in
    ``scalar_layout_states``)."""
    import numpy as np

    m, S = draws.truth.shape
    states = np.zeros((m, S), dtype=np.int8)
    thickness = np.full((m, S), np.nan)
    bottom = np.full((m, S), np.nan)
    for i in range(m):
        st, th, bo = scalar_layout_states(base, sample_layout(base, draws, i), peaks)
        states[i] = st
        thickness[i] = [np.nan if v is None else v for v in th]
        bottom[i] = [np.nan if v is None else v for v in bo]
    return states, thickness, bottom


def spot_block(base, draws, peaks=None):
    """``scalar_block``'s answer (states, thickness, bottom; ``peaks`` as there) for a layout
    with a beam spot (core/sweep/spot_scan.py): the block's column ranges over arrays first
    (``range_table``); the layouts read per step in a fast scan through ``lean_block``, the
    others through the scalar path, which finds the ranges there. The same answers as
    ``scalar_block``, bit for bit (tests/core/test_sweep_spot.py)."""
    import numpy as np

    from .spot_scan import lean_block, lean_spot_path, range_table

    layout = base.layout
    spot = layout.spot
    m, S = draws.truth.shape
    layouts = [sample_layout(base, draws, i) for i in range(m)]
    table = range_table(layouts, spot) if spot is not None and not spot.ideal else {}
    states = np.zeros((m, S), dtype=np.int8)
    thickness = np.full((m, S), np.nan)
    bottom = np.full((m, S), np.nan)
    lean = [i for i, sample in enumerate(layouts) if lean_spot_path(sample)]
    answers = dict(zip(lean, lean_block([layouts[i] for i in lean], table)))
    for i, sample in enumerate(layouts):
        if i in answers:
            runs, group_peaks = answers[i]
            if peaks is not None:
                peaks.extend(group_peaks)
            st, th, bo = states_of_runs(base, sample, runs)
        else:
            st, th, bo = scalar_layout_states(base, sample, peaks, table)
        states[i] = st
        thickness[i] = [np.nan if v is None else v for v in th]
        bottom[i] = [np.nan if v is None else v for v in bo]
    return states, thickness, bottom


def states_of_runs(base, layout, runs):
    """``scalar_layout_states``'s answer from the scan's runs (``SensorRun``s): the
    recipe's mapping, the first run's thickness and bottom per slot."""
    from ..mapping import unscanned_slots
    from ..scan.scan_result import protruding_slots

    plan = base.plan
    flagged, _ = protruding_slots(base.carrier, plan, layout.wafers)
    unscanned = unscanned_slots(plan, (layout.scan.start_z, layout.scan.final_z))
    slot_map = map_slots(plan, [(r.bottom, r.top) for r in runs], flagged, unscanned)
    states, thickness, bottom = [], [], []
    for slot in slot_map.slots:
        states.append(UNSCANNED if slot.state == mapping.UNSCANNED else slot.state)
        if slot.runs:
            run = runs[slot.runs[0]]
            thickness.append(run.diff)
            bottom.append(run.bottom)
        else:
            thickness.append(None)
            bottom.append(None)
    return states, thickness, bottom


def needs_scalar_path(layout):
    """A beam spot, latching in motion, a slow scan's jab or sweep, or exact edges: the layout
    is scanned by the scalar path, one layout at a time."""
    from ..scan import slow_scan
    from ..scan.sensing import ideal_sensor

    return (not ideal_sensor(layout) or layout.scan.exact or slow_scan.probes_pockets(layout.scan))


# --- the vectorised scan ---------------------------------------------------------------------

def _scalar_steps(base, draws, i, s, k):
    """One wafer's stepped interval by the scalar engine (engines._snap_to_grid et al.)."""
    from ..scan.engines import _is_level, _settled_steps, _snap_to_grid, wafer_edges

    carrier = base.carrier
    wafer = Wafer(name=f"{carrier.name}_S{s + 1:02d}_{k}",
                  center=tuple(float(v) for v in draws.center[i, s, k]),
                  normal=tuple(float(v) for v in draws.normal[i, s, k]),
                  diameter=carrier.wafer_diameter, thickness=float(draws.thickness[i, s, k]),
                  carrier=carrier.name, slot=s + 1, bow=float(draws.bow[i, s, k]))
    beam = base.layout.beam
    layout = replace(base.layout, wafers=(wafer,), beam=Beam(
        beam.emitter, tuple(float(v) for v in draws.direction[i]), beam.length))
    edges = wafer_edges(layout, wafer)
    if edges is None:
        return None
    return (_is_level(layout, wafer) and _settled_steps(layout, edges)) or \
        _snap_to_grid(layout, wafer, edges)


def scan_block(base, draws):
    """Reported state codes (m, S), measured thickness and bottom (m, S; nan without a run) of
    a block of sampled layouts, in numpy over layouts x wafers. Equal to ``scalar_block``."""
    import numpy as np

    layout = base.layout
    scan = layout.scan
    plan = base.plan
    if needs_scalar_path(layout):
        return scalar_block(base, draws)
    m, S = draws.truth.shape
    W = 2 * S
    exists = draws.exists.reshape(m, W)
    li, wi = np.nonzero(exists)
    center = draws.center.reshape(m, W, 3)[li, wi]
    normal = draws.normal.reshape(m, W, 3)[li, wi]
    radius = np.full(len(li), 0.5 * base.carrier.wafer_diameter)
    thickness = draws.thickness.reshape(m, W)[li, wi]
    bow = draws.bow.reshape(m, W)[li, wi]
    # In chunks of wafers: translation_ranges makes dozens of temporaries the length of its
    # arrays, and a block's (~12,000 wafers) spill from the core's cache; a chunk's stay in it
    # (SWEEP_CHUNK).
    direction = draws.direction[li]
    chunks = [slice(a, a + SWEEP_CHUNK) for a in range(0, len(li), SWEEP_CHUNK)] or [slice(0)]
    parts = [translation_ranges(layout.beam.emitter, direction[c], layout.lift_axis, center[c],
                                normal[c], radius[c], thickness[c], layout.beam.length,
                                TOUCH_TOLERANCE, bow[c])
             for c in chunks]
    lo, hi, hit, covered = (np.concatenate([p[k] for p in parts]) for k in range(4))
    scalar = ~covered
    z0 = layout.beam.emitter[2]
    az = layout.lift_axis[2]
    e0 = z0 + lo * az
    e1 = z0 + hi * az
    step = scan.z_step
    last = scan.last_step
    with np.errstate(invalid="ignore"):
        x0 = (e0 - scan.start_z) / step
        x1 = (e1 - scan.start_z) / step
        margin = GRID_MARGIN / step
        near = ((np.abs(x0 - np.rint(x0)) <= margin) | (np.abs(x1 - np.rint(x1)) <= margin))
        k_lo = np.maximum(0, np.ceil(x0))
        k_hi = np.minimum(last, np.floor(x1))
    near &= hit
    hit = hit & ~near
    scalar |= near
    k_lo = np.where(hit, k_lo, 0).astype(np.int64)
    k_hi = np.where(hit, k_hi, -1).astype(np.int64)
    for j in np.flatnonzero(scalar):
        steps = _scalar_steps(base, draws, int(li[j]), int(wi[j]) // 2, int(wi[j]) % 2)
        if steps is not None:
            k_lo[j], k_hi[j] = steps
    valid = k_lo <= k_hi
    first = np.full((m, W), np.iinfo(np.int64).max)
    lastk = np.full((m, W), -1, dtype=np.int64)
    first[li[valid], wi[valid]] = k_lo[valid]
    lastk[li[valid], wi[valid]] = k_hi[valid]
    run_lo, run_hi, run_ok = _merge_runs(first, lastk)
    if scan.mode == SLOW:  # only the carrier's pockets are read (scan_result._window)
        w_lo = max(0, math.ceil((plan.seat_z(1) - 0.5 * plan.pitch - scan.start_z) / step))
        w_hi = min(last, math.floor((plan.seat_z(plan.slot_count) + 0.5 * plan.pitch
                                     - scan.start_z) / step))
        run_ok &= ~((run_hi < w_lo) | (run_lo > w_hi))
        run_lo = np.maximum(run_lo, w_lo)
        run_hi = np.minimum(run_hi, w_hi)
    bottom = scan.start_z + run_lo * step  # ScanParameters.position
    top = scan.start_z + run_hi * step
    if draws.sensor_response is None:
        bottom, top = _latched(bottom, top, scan)
    else:
        lag = (scan.scan_speed * draws.sensor_response)[:, None] if scan.mode != SLOW else 0.0
        bottom, top = _latched_arrays(bottom, top, scan, lag)
    # Compact each layout's valid runs to the left, in ascending order (they already are).
    order = np.argsort(~run_ok, axis=1, kind="stable")
    bottom = np.take_along_axis(bottom, order, axis=1)
    top = np.take_along_axis(top, order, axis=1)
    run_ok = np.take_along_axis(run_ok, order, axis=1)
    states, first_run = map_runs(plan, bottom, top, run_ok)
    flagged = protruding_mask(base, draws)
    states = np.where(flagged, PROTRUDING, states)
    unscanned = _unscanned(plan, scan)
    if unscanned:
        cols = np.array(unscanned) - 1
        states[:, cols] = np.where(flagged[:, cols], PROTRUDING, UNSCANNED)
    has = first_run < bottom.shape[1]
    pick = np.minimum(first_run, bottom.shape[1] - 1)
    b = np.take_along_axis(bottom, pick, axis=1)
    tp = np.take_along_axis(top, pick, axis=1)
    thick = np.where(has, tp - b, np.nan)
    return states.astype(np.int8), thick, np.where(has, b, np.nan)


def _unscanned(plan, scan):
    from ..mapping import unscanned_slots

    return unscanned_slots(plan, (scan.start_z, scan.final_z))


def _merge_runs(first, last):
    """Per layout (rows), the union of the step intervals (first, last) (first = int max where
    none) as runs: intervals that overlap or are adjacent merge (engines.runs_from_intervals).
    Returns (lo, hi, ok) arrays (m, W): run j of each layout, ok where it exists."""
    import numpy as np

    m, W = first.shape
    order = np.argsort(first, axis=1, kind="stable")
    f = np.take_along_axis(first, order, axis=1)
    la = np.take_along_axis(last, order, axis=1)
    present = la >= 0
    reach = np.maximum.accumulate(np.where(present, la, -2), axis=1)
    before = np.concatenate([np.full((m, 1), -2, dtype=np.int64), reach[:, :-1]], axis=1)
    new = present & (f > before + 1)
    run_id = np.cumsum(new, axis=1) - 1
    lo = np.zeros((m, W), dtype=np.int64)
    hi = np.full((m, W), -1, dtype=np.int64)
    ok = np.zeros((m, W), dtype=bool)
    rows = np.broadcast_to(np.arange(m)[:, None], (m, W))
    lo[rows[new], run_id[new]] = f[new]
    ok[rows[new], run_id[new]] = True
    flat = (rows * W + np.maximum(run_id, 0))[present]
    hi_flat = hi.reshape(-1)
    np.maximum.at(hi_flat, flat, la[present])
    return lo, hi, ok


def _latched(bottom, top, scan):
    """(bottom, top) of runs as latched (scan_result.latch, then min/max as SensorRun does)."""
    lag = scan.latch_lag
    if scan.mode == SLOW or scan.direction == UP:
        return bottom + lag, top + lag
    if scan.direction == DOWN:
        return bottom - lag, top - lag
    assert scan.direction == UPDOWN
    return 0.5 * ((bottom + lag) + (bottom - lag)), 0.5 * ((top + lag) + (top - lag))


def _latched_arrays(bottom, top, scan, lag):
    """``_latched`` with a per-layout lag (m, 1)."""
    if scan.mode == SLOW:
        return bottom, top
    if scan.direction == UP:
        return bottom + lag, top + lag
    if scan.direction == DOWN:
        return bottom - lag, top - lag
    return 0.5 * ((bottom + lag) + (bottom - lag)), 0.5 * ((top + lag) + (top - lag))


def protruding_mask(base, draws):
    """(m, S) True where the load port's protrusion check flags the slot
    (scan_result.protruding_slots over arrays)."""
    import numpy as np

    carrier, plan = base.carrier, base.plan
    m, S = draws.truth.shape
    W = 2 * S
    out = np.zeros((m, S), dtype=bool)
    c = draws.center.reshape(m, W, 3)
    n = draws.normal.reshape(m, W, 3)
    t = draws.thickness.reshape(m, W)
    h = t / 2.0
    mx, my, mz = c[..., 0] + h * n[..., 0], c[..., 1] + h * n[..., 1], c[..., 2] + h * n[..., 2]
    r = 0.5 * carrier.wafer_diameter
    z_lo = carrier.seat_z(1) - carrier.pitch
    z_hi = carrier.seat_z(carrier.slot_count) + carrier.pitch
    inside = draws.exists.reshape(m, W) & (np.hypot(mx - carrier.center[0],
                                                    my - carrier.center[1]) < r) \
        & (z_lo <= mz) & (mz <= z_hi)
    fx, fy = carrier.front
    along = n[..., 0] * fx + n[..., 1] * fy
    # the solid's frontmost point (scan_result.front_reach over arrays): from the bottom centre
    reach = (c[..., 0] - carrier.center[0]) * fx + (c[..., 1] - carrier.center[1]) * fy
    across = np.sqrt(np.maximum(0.0, 1.0 - along * along))
    rim = r * across
    curve = draws.bow.reshape(m, W) * along
    if (curve > 0.0).any():
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = across * r * r / (2.0 * curve)
            inner = vertex * across + curve * (1.0 - vertex * vertex / (r * r))
        rim = np.where((curve > 0.0) & (vertex < r), inner, rim)
    reach = reach + (rim + np.maximum(0.0, t * along))  # front_reach's sum, then added
    amount = reach - 0.5 * carrier.wafer_diameter
    flagged = inside & (amount > plan.protrusion_limit)
    if not flagged.any():
        return out
    radius = 0.5 * carrier.wafer_diameter
    bows = np.abs(draws.bow.reshape(m, W))
    for i, w in zip(*np.nonzero(flagged)):
        nz = float(n[i, w, 2])
        half = radius * math.sqrt(max(0.0, 1.0 - nz * nz)) + (0.5 * float(t[i, w])
                                                               + float(bows[i, w])) * abs(nz)
        z0, z1 = float(mz[i, w]) - half, float(mz[i, w]) + half
        out[i, plan.nearest_slot(z0) - 1] = True
        for slot in range(1, S + 1):
            if z0 <= plan.seat_z(slot) <= z1:
                out[i, slot - 1] = True
    return out


def map_runs(plan, bottom, top, ok):
    """``mapping.map_slots`` over arrays: runs (m, R) by bottom and top (latched, ascending per
    layout, ``ok`` where a run exists). Returns (states (m, S) codes, first_run (m, S): the
    index of the first run in each slot, R where none)."""
    import numpy as np

    m, R = bottom.shape
    S = plan.slot_count
    eps = LIMIT_SLACK
    length = top - bottom
    if plan.thickness_correction != 1.0:
        length = length / plan.thickness_correction
    low, high = plan.thickness_window()
    below, above = plan.position_window()
    limit = plan.double_limit()
    first = plan.first_slot_z
    pitch = plan.pitch

    def nearest(z):
        return np.floor((z - first) / pitch + 0.5).astype(np.int64) + 1

    def seat(slot):
        return first + (slot - 1) * pitch

    landings = []  # (slot, state, valid) arrays (m, R)
    if plan.rules == mapping.BOUNDARY:
        # mapping._judge_by_boundaries over arrays, the same floats: references at seat + t/2,
        # boundaries halfway between them, none beyond the outer slots.
        first_reference = first + 0.5 * plan.wafer_thickness

        def nearest_reference(z):
            slot = np.floor((z - first_reference) / pitch + 0.5).astype(np.int64) + 1
            return np.minimum(S, np.maximum(1, slot))

        def reference(slot):
            return seat(slot) + 0.5 * plan.wafer_thickness

        def boundary(slot):
            return reference(slot) + 0.5 * pitch

        centre = 0.5 * (bottom + top)
        slot = nearest_reference(centre)
        lowest = nearest_reference(bottom)
        highest = nearest_reference(top)
        span = int(np.max(np.where(ok, highest - lowest, 0), initial=0))

        def crossed(b):
            bz = boundary(b)
            return (b >= lowest) & (b < highest) & (bottom < bz - eps) & (top > bz + eps)

        any_crossed = np.zeros((m, R), dtype=bool)
        for j in range(span):
            any_crossed |= crossed(lowest + j)
        for j in range(span + 1):
            s = lowest + j
            spanned = crossed(s - 1) | crossed(s)
            landings.append((s, np.full((m, R), CROSS), ok & any_crossed & spanned))
        long_run = ~any_crossed & (length > limit + eps)
        third = pitch / 3.0 + eps
        up = long_run & (slot < S) & (boundary(slot) - centre <= third)
        down = long_run & ~up & (slot > 1) & (centre - boundary(slot - 1) <= third)
        landings.append((slot, np.full((m, R), CROSS), ok & (up | down)))
        landings.append((np.where(up, slot + 1, slot - 1), np.full((m, R), CROSS),
                         ok & (up | down)))
        single = ok & ~any_crossed & ~up & ~down
        offset = centre - reference(slot)
        state = np.where(length > high + eps, DOUBLE,
                         np.where(length < low - eps, THIN,
                                  np.where((offset > above + eps) | (-offset > below + eps),
                                           POSITION_ERROR, PRESENT)))
        landings.append((slot, state, single))
    else:
        cross = length > limit + eps
        middle = 0.5 * (bottom + top)
        lower = np.floor((middle - first) / pitch).astype(np.int64) + 1
        slot = nearest(bottom)
        offset = bottom - seat(slot)
        state = np.where((offset > above + eps) | (-offset > below + eps), POSITION_ERROR,
                         np.where(length < low - eps, THIN,
                                  np.where(length <= high + eps, PRESENT, DOUBLE)))
        landings.append((np.where(cross, lower, slot), np.where(cross, CROSS, state), ok))
        landings.append((lower + 1, np.full((m, R), CROSS), ok & cross))
    rank = np.zeros(m * (S + 2), dtype=np.int64)
    first_run = np.full(m * (S + 2), R, dtype=np.int64)
    rows = np.broadcast_to(np.arange(m)[:, None], (m, R))
    index = np.broadcast_to(np.arange(R)[None, :], (m, R))
    ranks = np.array(_RANK)
    flat_landings = []
    for slot, state, valid in landings:
        v = valid & (slot >= 1) & (slot <= S)
        cell = (rows * (S + 2) + np.where(v, slot, 0))[v]
        np.maximum.at(rank, cell, ranks[np.asarray(state)[v]])
        np.minimum.at(first_run, cell, index[v])
        flat_landings.append((cell, np.asarray(state)[v], index[v]))
    # A second run in a slot (not a cross-slotted one) is not a normally inserted wafer.
    for cell, state, idx in flat_landings:
        late = (state != CROSS) & (idx > first_run[cell])
        np.maximum.at(rank, cell[late], _RANK[POSITION_ERROR])
    rank = rank.reshape(m, S + 2)[:, 1:S + 1]
    first_run = first_run.reshape(m, S + 2)[:, 1:S + 1]
    return np.array(_BY_RANK)[rank], first_run


# --- a block, start to finish ----------------------------------------------------------------

def sweep_block(base, tolerances, seed, block, count, scalar=False):
    """Draw, scan and map block ``block`` (``count`` layouts). Returns a dict of arrays:
    ``truth``, ``reported`` (m, S codes), ``thickness``, ``bottom`` (m, S, nan without a run).
    ``scalar``: through the scalar path (the oracle)."""
    draws = draw_block(base, tolerances, seed, block, count)
    peaks = []
    spot = base.layout.spot
    if scalar:
        states, thickness, bottom = scalar_block(base, draws, peaks)
    elif spot is not None and not spot.ideal:
        # The block at once (core/sweep/spot_scan.py): the scalar path's answers, bit for bit.
        states, thickness, bottom = spot_block(base, draws, peaks)
    elif needs_scalar_path(base.layout):
        states, thickness, bottom = scalar_block(base, draws, peaks)
    else:
        states, thickness, bottom = scan_block(base, draws)
    # The weakest signal a wafer gave: a beam spot's smallest peak blocked fraction over the
    # groups of wafers it saw; the ideal beam blocks all or nothing (1).
    weakest = min(peaks) if peaks else 1.0
    return {"truth": draws.truth, "reported": states, "thickness": thickness, "bottom": bottom,
            "weakest_peak": weakest}


# The columns of ``layout_moments``' per-layout vector of each state.
_TRUE, _REPORTED, _CORRECT, _HOLDS, _LACKS, _ONE = range(6)


def layout_moments(truth, reported):
    """What the rates' intervals need of the layouts (rows of ``truth`` and ``reported``, state
    codes (m, S)): for each state s (0..7) the sums over layouts of v vᵀ, v the layout's vector
    (slots truly s, slots reported s, slots truly and reported s, 1 if it holds a slot truly s,
    1 if it holds a slot not truly s, 1), an (8, 6, 6) integer array. A rate's count and its
    trials in one layout are differences of these counts, so the sums of their squares and
    products over layouts are sums of these entries (``rate_intervals``). Integers: partitions
    add them up in any order to the same numbers."""
    import numpy as np

    m, S = truth.shape
    rows = np.arange(m, dtype=np.int64)[:, None] * 8
    cells = 8 * m
    at = rows + truth
    slots_true = np.bincount(at.ravel(), minlength=cells).reshape(m, 8).T
    v = np.empty((8, m, 6))
    v[..., _TRUE] = slots_true
    v[..., _REPORTED] = np.bincount((rows + reported).ravel(), minlength=cells).reshape(m, 8).T
    v[..., _CORRECT] = np.bincount(at[truth == reported], minlength=cells).reshape(m, 8).T
    v[..., _HOLDS] = slots_true > 0
    v[..., _LACKS] = slots_true < S
    v[..., _ONE] = 1.0
    # In floats for the speed of a matrix product; every entry is a whole number below
    # 2**53 (a block's layouts x S²), so every sum of products is exact, in any order.
    return np.matmul(v.transpose(0, 2, 1), v).astype(np.int64)


def block_tally(base, result):
    """What a block adds to a sweep's summary: the confusion counts (8 x 8: truth x reported),
    and the measured thickness and offset from the seat of the slots by their true state (under
    "boundary" rules the offset of the run's centre from the slot's reference, seat + t/2, as
    those rules judge position)."""
    import numpy as np

    truth = result["truth"].astype(np.int64)
    reported = result["reported"].astype(np.int64)
    confusion = np.zeros((8, 8), dtype=np.int64)
    np.add.at(confusion, (truth.ravel(), reported.ravel()), 1)
    moments = layout_moments(truth, reported)
    plan = base.plan
    seats = np.array([plan.seat_z(s) for s in range(1, plan.slot_count + 1)])
    thickness = result["thickness"]
    if plan.rules == mapping.BOUNDARY:
        # The position those rules judge: the run's centre against the slot's reference.
        offset = (result["bottom"] + 0.5 * thickness) - (seats[None, :]
                                                         + 0.5 * plan.wafer_thickness)
    else:
        offset = result["bottom"] - seats[None, :]
    if plan.thickness_correction != 1.0:
        thickness = thickness / plan.thickness_correction
    measured = {}
    # A slot's own run: not a cross-slotted run from a neighbour, not half a pitch off its seat.
    own = ~np.isnan(thickness) & (reported != CROSS) & (reported != UNSCANNED) & \
        (np.abs(offset) < 0.5 * plan.pitch)
    for code in (PRESENT, THIN, DOUBLE, POSITION_ERROR):
        sel = (truth == code) & own
        measured[STATE_KEYS[code]] = (thickness[sel], offset[sel])
    return {"confusion": confusion, "moments": moments, "measured": measured,
            "weakest_peak": result.get("weakest_peak", 1.0)}


def combine_tallies(tallies):
    """The tallies of blocks (in block order) as one: counts added, measures concatenated in
    block order, so the result does not depend on how the blocks were grouped."""
    import numpy as np

    confusion = sum(t["confusion"] for t in tallies)
    moments = sum(t["moments"] for t in tallies)
    weakest = min(t.get("weakest_peak", 1.0) for t in tallies)
    measured = {}
    for key in tallies[0]["measured"]:
        measured[key] = (np.concatenate([t["measured"][key][0] for t in tallies]),
                         np.concatenate([t["measured"][key][1] for t in tallies]))
    return {"confusion": confusion, "moments": moments, "measured": measured,
            "weakest_peak": weakest}


def partition_tally(base, tolerances, seed, n, blocks):
    """The given blocks (a partition) of an N-layout sweep, reduced to what the summary reads:
    the confusion counts, the weakest peak, the extremes of the readings the suggested recipe
    is built from, and the margins of the truly present wafers, sorted. The margins are the
    bulk (~22 values a layout); a sweep leaves them where the partition ran and asks them for
    a few order statistics and a histogram (``reduce_partitions``)."""
    import numpy as np

    sizes = block_sizes(n)
    tally = combine_tallies([block_tally(base, sweep_block(base, tolerances, seed, b, sizes[b]))
                             for b in blocks])
    measured = tally["measured"]
    th, off = measured["present"]

    def ends(values):
        return (float(values.min()), float(values.max())) if len(values) else None

    extremes = {"thickness": ends(th), "offset": ends(off),
                "thin_thickness": ends(measured["thin"][0]),
                "double_thickness": ends(measured["double"][0]),
                "misplaced_offset": ends(np.abs(measured["position_error"][1]))}
    return {"confusion": tally["confusion"], "moments": tally["moments"],
            "weakest_peak": tally["weakest_peak"],
            "extremes": extremes,
            "margins": {key: np.sort(values) for key, values in
                        margin_values(base.plan, tally).items()}}


# --- reducing the partitions ------------------------------------------------------------------
#
# The summary needs the margins' order statistics (min, percentiles, max) over every partition,
# exactly. Rather than bring every partition's margins to one place (40 MB for 100,000
# layouts, and a sort there that no worker shares), each partition sends every
# DIGEST_STRIDE-th of its sorted margins; those bound each wanted order statistic between two
# values, and each partition then sends the few of its margins between them and how many lie
# below. Two small round trips, the same numbers as sorting everything in one place.

DIGEST_STRIDE = 256
MARGIN_BINS = 60


def partition_digest(part, stride=None):
    """A partition without its margins: its counts and extremes, and of each kind of margin the
    count, the largest and every ``stride``-th value from the smallest (a sorted sample;
    default DIGEST_STRIDE)."""
    stride = stride or DIGEST_STRIDE
    out = {k: part[k] for k in ("confusion", "moments", "weakest_peak", "extremes")}
    out["margins"] = {key: {"count": len(values), "stride": stride,
                            "samples": values[::stride].copy(),
                            "max": float(values[-1]) if len(values) else None}
                      for key, values in part["margins"].items()}
    return out


def _brackets(digests, key, ranks):
    """For each 0-based rank r of the margins ``key`` of every partition together, values
    (low, high) with low <= the r-th smallest <= high, from the partitions' samples. A
    partition's k samples below a value v (every stride-th margin from the smallest) say that
    between (k - 1) * stride + 1 and k * stride of its margins lie below v (all of them when
    every sample does)."""
    import numpy as np

    kinds = [d["margins"][key] for d in digests]
    candidates = np.unique(np.concatenate([kind["samples"] for kind in kinds]))
    below_at_most = np.zeros(len(candidates), dtype=np.int64)   # margins < v, at most
    up_to_at_least = np.zeros(len(candidates), dtype=np.int64)  # margins <= v, at least
    for kind in kinds:
        sample, count, stride = kind["samples"], kind["count"], kind["stride"]
        a = np.searchsorted(sample, candidates, side="left")
        below_at_most += np.where(a < len(sample), a * stride, count)
        b = np.searchsorted(sample, candidates, side="right")
        up_to_at_least += np.where(b > 0, (b - 1) * stride + 1, 0)
    out = []
    for r in ranks:
        i = int(np.searchsorted(below_at_most, r, side="right")) - 1
        j = int(np.searchsorted(up_to_at_least, r + 1, side="left"))
        out.append((float(candidates[i]) if i >= 0 else -math.inf,
                    float(candidates[j]) if j < len(candidates) else math.inf))
    return out


def partition_details(part, brackets, edges):
    """What a partition adds to the order statistics and histograms: for each kind of margin
    and each (low, high) of ``brackets[key]``, how many of its margins lie below low and those
    from low to high as distinct values with their counts (readings on the step grid repeat:
    a block's ~11,000 thickness margins hold ~26 values); and its histogram over
    ``edges[key]`` (numpy.histogram's bins), where ``edges`` has the key."""
    import numpy as np

    out = {}
    for key, values in part["margins"].items():
        pieces = []
        for low, high in brackets.get(key, ()):
            a = int(np.searchsorted(values, low, side="left"))
            b = int(np.searchsorted(values, high, side="right"))
            pieces.append((a, *np.unique(values[a:b], return_counts=True)))
        hist = None
        if edges.get(key) is not None:
            hist = np.histogram(values, bins=edges[key])[0]
        out[key] = {"selected": pieces, "histogram": hist}
    return out


def _nth_between(pieces, r):
    """The r-th smallest margin (0-based, of every partition) from the partitions' pieces of
    one bracket: (how many lie below it, its distinct values, their counts)."""
    import numpy as np

    below = sum(p[0] for p in pieces)
    values = np.concatenate([p[1] for p in pieces])
    counts = np.concatenate([p[2] for p in pieces])
    distinct, where = np.unique(values, return_inverse=True)
    totals = np.zeros(len(distinct), dtype=np.int64)
    np.add.at(totals, where.ravel(), counts)
    return float(distinct[np.searchsorted(np.cumsum(totals), r - below, side="right")])


def linear_percentile(count, p, nth):
    """The p-th percentile of ``count`` values whose k-th smallest (0-based) is ``nth(k)``, by
    linear interpolation between the order statistics at (count - 1) p / 100 (numpy's default
    method, with its rounding: the same floats as numpy.percentile of the values)."""
    g = (count - 1) * (p / 100)
    if g >= count - 1:
        return nth(count - 1)
    k = math.floor(g)
    t = g - k
    low, high = nth(k), nth(k + 1)
    step = high - low
    return high - step * (1 - t) if t >= 0.5 else low + step * t


def _wanted_ranks(count):
    """The 0-based ranks linear_percentile reads for PERCENTILES of ``count`` values."""
    ranks = set()
    for p in PERCENTILES:
        linear_percentile(count, p, lambda k: ranks.add(k) or 0.0)
    return sorted(ranks)


class LocalPartitions:
    """Runs a sweep's partitions in this process, one after the other (a sweep's ``runner``;
    tolerance_study has the Dask one). ``run`` returns handles to the partitions' results, kept
    where they were computed; ``apply`` calls a function on each and brings back its answers."""

    def run(self, function, args, progress=None):
        results = []
        for i, a in enumerate(args):
            results.append(function(*a))
            if progress:
                progress(i + 1, len(args))
        return results

    def apply(self, function, handles, *extra):
        return [function(h, *extra) for h in handles]


def reduce_partitions(runner, handles, histograms=False):
    """The partitions' results (``runner``'s handles) as one tally: counts added, extremes
    taken, and of each kind of margin its distribution (count, min, PERCENTILES, max) and,
    with ``histograms``, its histogram in MARGIN_BINS equal bins from min to max (counts,
    edges). Exact whatever the partitions: the order statistics are the margins' own."""
    import numpy as np

    digests = runner.apply(partition_digest, handles)
    confusion = sum(d["confusion"] for d in digests)
    moments = sum(d["moments"] for d in digests)
    weakest = min(d["weakest_peak"] for d in digests)
    extremes = {}
    for name in digests[0]["extremes"]:
        found = [d["extremes"][name] for d in digests if d["extremes"][name] is not None]
        extremes[name] = ((min(f[0] for f in found), max(f[1] for f in found)) if found
                          else None)
    counts, ends, ranks, around, brackets, edges = {}, {}, {}, {}, {}, {}
    for key in digests[0]["margins"]:
        held = [d["margins"][key] for d in digests if d["margins"][key]["count"]]
        counts[key] = sum(h["count"] for h in held)
        if not held:
            continue
        ends[key] = (min(float(h["samples"][0]) for h in held), max(h["max"] for h in held))
        ranks[key] = _wanted_ranks(counts[key])
        around[key] = _brackets(digests, key, ranks[key])  # one for each rank
        # Neighbouring ranks (a percentile's two) mostly share a bracket: each asked once.
        brackets[key] = sorted(set(around[key]))
        if histograms:
            edges[key] = np.histogram_bin_edges(ends[key], bins=MARGIN_BINS)
    details = runner.apply(partition_details, handles, brackets, edges) if brackets else []
    margins, hists = {}, {}
    for key, count in counts.items():
        if count == 0:
            margins[key] = None
            continue
        asked = {bracket: i for i, bracket in enumerate(brackets[key])}
        nth = {r: _nth_between([d[key]["selected"][asked[b]] for d in details], r)
               for r, b in zip(ranks[key], around[key])}
        dist = {"count": int(count), "min": ends[key][0]}
        for p in PERCENTILES:
            dist[f"p{p}"] = float(linear_percentile(count, p, nth.__getitem__))
        dist["max"] = ends[key][1]
        margins[key] = dist
        if histograms:
            hists[key] = (sum(d[key]["histogram"] for d in details), edges[key])
    return {"confusion": confusion, "moments": moments, "weakest_peak": weakest,
            "extremes": extremes,
            "margins": margins, "histograms": hists}


def partitions(n, count):
    """The blocks of an N-layout sweep split into ``count`` contiguous partitions (fewer when
    there are fewer blocks)."""
    blocks = list(range(block_count(n)))
    count = max(1, min(count, len(blocks)))
    size, extra = divmod(len(blocks), count)
    out, start = [], 0
    for i in range(count):
        end = start + size + (1 if i < extra else 0)
        out.append(blocks[start:end])
        start = end
    return out


# --- statistics ------------------------------------------------------------------------------

Z95 = 1.959963984540054


def wilson(k, n, z=Z95):
    """The Wilson score interval (low, high) of a proportion k/n at ~95 %; (None, None) when
    n = 0."""
    if n == 0:
        return (None, None)
    return _wilson(k / n, n, z, k == 0, k == n)


def _wilson(p, n, z, none, every):
    """The Wilson score interval of a proportion p over n trials (n may be a float, an
    effective number of trials); ``none`` (``every``): no trial (every trial) counted, so the
    low (high) end is 0 (1) exactly, not a rounding residue of it."""
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1.0 - p) / n + z * z / (4 * n * n)) / denom
    return (0.0 if none else max(0.0, centre - half), 1.0 if every else min(1.0, centre + half))


INTERVALS = ("95 % Wilson score intervals over the layouts: the number of trials is the "
             "slots counted divided by the design effect, the spread of the layouts' own "
             "rates (cluster-robust, by layout) over the spread independent slots would give, "
             "at least 1; a rate of 0 or 1 gives no spread to measure and counts one trial "
             "per layout")


def layout_interval(k, n, kk, kn, nn, layouts, z=Z95):
    """The ~95 % interval (low, high) of a rate k / n counted over layouts, layout i adding
    k_i of its n_i trials (slots): ``kk``, ``kn``, ``nn`` are the sums over layouts of k_i²,
    k_i n_i and n_i², ``layouts`` the number of layouts with n_i > 0 (integers). The slots of
    one layout share its draws (a beam's teach error moves them all), so they are not
    independent trials: the variance of the rate is estimated from the layouts' spread, the
    ratio estimator's cluster-robust variance L / (L − 1) Σ (k_i − p n_i)² / n², and the
    Wilson interval is taken with the effective number of trials n / deff, deff that variance
    over the binomial p (1 − p) / n, at least 1 (never narrower than independent slots). With
    k = 0 or k = n there is no spread to measure: one trial per layout, the widest the
    layouts allow. (None, None) when n = 0."""
    if n == 0:
        return (None, None)
    if 0 < k < n and layouts > 1:
        # n² Σ (k_i − p n_i)², p = k / n, in integers: exact, whatever the order of the sums
        spread = kk * n * n - 2 * k * n * kn + k * k * nn
        deff = (layouts * spread) / ((layouts - 1) * n * k * (n - k))
        trials = n / max(1.0, deff)
    else:
        trials = layouts
    return _wilson(k / n, trials, z, k == 0, k == n)


def rate_intervals(moments, state, slots):
    """(miss, false call) intervals of ``state`` from ``layout_moments``' sums (``slots`` a
    layout): a miss is a slot truly the state reported otherwise (k_i = true − correct of n_i =
    true), a false call a slot not truly the state reported as it (k_i = reported − correct of
    n_i = slots − true)."""
    M = [[int(v) for v in row] for row in moments[state]]
    T, R, C, H, L, O = _TRUE, _REPORTED, _CORRECT, _HOLDS, _LACKS, _ONE
    miss = layout_interval(M[T][O] - M[C][O], M[T][O],
                           M[T][T] - 2 * M[T][C] + M[C][C], M[T][T] - M[T][C], M[T][T],
                           M[H][O])
    false_call = layout_interval(
        M[R][O] - M[C][O], slots * M[O][O] - M[T][O],
        M[R][R] - 2 * M[R][C] + M[C][C],
        slots * (M[R][O] - M[C][O]) - M[T][R] + M[T][C],
        slots * slots * M[O][O] - 2 * slots * M[T][O] + M[T][T],
        M[L][O])
    return miss, false_call


PERCENTILES = (1, 5, 50, 95, 99)


def summarise(base, tolerances, n, seed, tally):
    """The sweep's summary (the dict written as summary.json) from ``reduce_partitions``'s
    tally."""
    from ..files.scenario import MISPLACED_RISE, THIN_FACTOR

    plan = base.plan
    conf = tally["confusion"]
    names = STATE_KEYS
    confusion = {names[i]: {names[j]: int(conf[i, j]) for j in range(8)} for i in range(8)
                 if conf[i].sum() > 0}
    total = int(conf.sum())
    rates = {}
    for i, name in enumerate(names):
        true_n = int(conf[i].sum())
        reported_n = int(conf[:, i].sum())
        hits = int(conf[i, i])
        if true_n == 0 and reported_n == 0:
            continue
        missed = true_n - hits
        false_calls = reported_n - hits
        others = total - true_n
        miss_95, false_call_95 = rate_intervals(tally["moments"], i, plan.slot_count)
        rates[name] = {
            "true": true_n, "reported": reported_n, "correct": hits,
            "miss_rate": missed / true_n if true_n else None,
            "miss_rate_95": list(miss_95),
            "false_call_rate": false_calls / others if others else None,
            "false_call_rate_95": list(false_call_95),
        }
    low, high = plan.thickness_window()
    below, above = plan.position_window()
    ends = tally["extremes"]
    # Safer thresholds: each limit halfway between the present wafers' extreme and the nearest
    # reading of the state on the other side (or, with none drawn, that state's nominal reading:
    # a thin wafer THIN_FACTOR t, a double 2 t, a misplaced wafer MISPLACED_RISE off its seat).
    t = plan.wafer_thickness
    suggested = None
    if ends["thickness"] is not None:
        th_min, th_max = ends["thickness"]
        off_min, off_max = ends["offset"]
        thin, double, mis = (ends["thin_thickness"], ends["double_thickness"],
                             ends["misplaced_offset"])
        lo_ref = thin[1] if thin else THIN_FACTOR * t
        hi_ref = double[0] if double else 2.0 * t
        pos_ref = mis[0] if mis else MISPLACED_RISE
        t_min = 0.5 * (th_min + lo_ref)
        t_max = 0.5 * (th_max + hi_ref)
        worst_below = float(max(0.0, -off_min))
        worst_above = float(max(0.0, off_max))
        suggested = {
            "thickness_min": t_min, "thickness_max": t_max,
            "position_below": 0.5 * (worst_below + pos_ref),
            "position_above": 0.5 * (worst_above + pos_ref),
            # Halfway between an empty slot's blocked fraction (0) and the weakest peak a wafer
            # gave: the largest margin to both. The ideal beam blocks all or nothing: 0.5.
            "threshold_on": 0.5 * tally.get("weakest_peak", 1.0),
            "weakest_peak": tally.get("weakest_peak", 1.0),
            "worst_thickness_margin": min(th_min - t_min, t_max - th_max),
        }
    layout = base.layout
    return {
        "n": int(n), "seed": int(seed), "slots": int(plan.slot_count),
        "slot_count_total": total,
        "rules": plan.rules,
        "recipe": {"thickness_min": low, "thickness_max": high, "position_below": below,
                   "position_above": above, "double_threshold": plan.double_limit(),
                   "protrusion_limit": plan.protrusion_limit,
                   "threshold_on": (layout.amplifier.threshold_on if layout.amplifier
                                    else 0.5)},
        "tolerances": {name: {"dist": d.kind, "a": d.a, "b": d.b}
                       for name, d in tolerances.quantities.items()},
        "states": ({STATE_KEYS[PLACED[state]]: p for state, p in tolerances.states}
                   if tolerances.states else "INPUT's load"),
        "confusion": confusion,
        "rates": rates,
        "intervals": INTERVALS,
        "margins": tally["margins"],
        "suggested": suggested,
    }


def margin_values(plan, tally):
    """The thickness and position margins (mm, > 0 inside the recipe's windows) of every truly
    present wafer the scan saw: {"thickness": array, "position": array}."""
    import numpy as np

    low, high = plan.thickness_window()
    below, above = plan.position_window()
    th, off = tally["measured"]["present"]
    return {"thickness": np.minimum(th - low, high - th),
            "position": np.minimum(off + below, above - off)}


def sweep_tally(layout, tolerances, n, seed=0, plan=None, rules=None, partition_count=1,
                runner=None, progress=None, histograms=False):
    """Run the sweep and return (base, tally): ``run_sweep`` before its summary (the tally of
    ``reduce_partitions``, with the margins' histograms when asked)."""
    if n < 1:
        raise ValueError(f"a sweep needs at least one layout, got n = {n}")
    base = sweep_base(layout, plan, rules)
    parts = partitions(n, partition_count)
    runner = runner or LocalPartitions()
    handles = runner.run(partition_tally, [(base, tolerances, seed, n, blocks)
                                           for blocks in parts], progress)
    return base, reduce_partitions(runner, handles, histograms)


def run_sweep(layout, tolerances, n, seed=0, plan=None, rules=None, partition_count=1,
              runner=None, progress=None):
    """Sweep N layouts drawn from ``layout`` by ``tolerances`` (core.sweep.distributions.Tolerances) and
    return the summary dict (summary.json's content). ``plan`` / ``rules``: the recipe
    (default: the layout's own). The blocks are grouped into ``partition_count`` partitions,
    which ``runner`` runs (default: ``LocalPartitions``, here one after another; the Dask
    runner is tolerance_study's); ``progress(done, total)`` after each. The result depends
    only on the layout, the tolerances, N and the seed. From a script:

        layout = read_scenario("resources/examples/paper.toml")
        summary = run_sweep(layout, read_tolerances("fab_tolerances.toml"), 10_000, seed=1)
    """
    base, tally = sweep_tally(layout, tolerances, n, seed, plan, rules, partition_count,
                              runner, progress)
    return summarise(base, tolerances, n, seed, tally)
