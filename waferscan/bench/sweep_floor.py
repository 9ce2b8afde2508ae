"""SPEC §9's floor for sweeps: the same layouts drawn, scanned and mapped as plainly as numpy
allows, for the bench to measure beside ``run_sweep`` (issue 30).

What it does, for N layouts of the input's scanned carrier under a tolerance file's
``seat_offset``, ``thickness``, ``protrusion``, ``beam_z``, ``beam_tilt``, ``sensor_response``
and ``[states]``: draw every quantity for all layouts at once; each wafer's blocked interval in
closed form (its faces along the beam over the chord the beam cuts from its rim: a tilted beam
and a cross-slotted wafer's slope both taken along the chord); the step grid; the runs (each
layout's intervals sorted and merged); the latch's lag; each run to its slot by its bottom, its
state by thickness and position; the confusion counts against what was placed. What it leaves
out is the product's generality, not its work: no scalar oracle at the grid's edges, no beam
spot, bow, wafer tilt or second rule set, no margins' order statistics. Its random draws are
its own, so it agrees with a sweep in distribution, not layout by layout (tested so).
"""

from __future__ import annotations

import math

__all__ = ["floor_sweep"]

# Layouts drawn and scanned at once: ~20 arrays of (layouts x 2 x slots) floats, ~16 MB (16 %
# faster than 20,000 layouts at once here).
FLOOR_CHUNK = 4096


def _states(rng, probabilities, m, S):
    """Placed state codes (m, S): each slot drawn; a cross-slotted wafer takes the slot above
    (whose own draw is void), or is seated present in the top slot."""
    import numpy as np

    from ..core.mapping import CROSS, DOUBLE, EMPTY, POSITION_ERROR, PRESENT, PROTRUDING, THIN

    names = ("absent", "present", "cross", "double", "thin", "misplaced", "protruding")
    codes = np.array([EMPTY, PRESENT, CROSS, DOUBLE, THIN, POSITION_ERROR, PROTRUDING])
    edges = np.cumsum([probabilities.get(k, 0.0) for k in names])
    edges[-1] = 1.0
    drawn = codes[np.minimum(np.searchsorted(edges, rng.random((m, S)), side="right"), 6)]
    drawn[:, -1] = np.where(drawn[:, -1] == CROSS, PRESENT, drawn[:, -1])
    lower = np.zeros((m, S), dtype=bool)  # the lower slot of a cross-slotted wafer
    covered = np.zeros(m, dtype=bool)
    for s in range(S):
        lower[:, s] = (drawn[:, s] == CROSS) & ~covered
        drawn[:, s] = np.where(covered, CROSS, drawn[:, s])
        covered = lower[:, s]
    return drawn, lower


def floor_sweep(layout, tolerances, n, seed=0):
    """The confusion counts (8 x 8: placed state x reported) of ``n`` layouts drawn from
    ``layout`` by ``tolerances`` (core.sweep.distributions.Tolerances), drawn, scanned and
    mapped plainly (module docstring)."""
    import numpy as np

    from ..core.files.scenario import MISPLACED_RISE, PROTRUDING_SHIFT, THIN_FACTOR
    from ..core.mapping import (CROSS, DOUBLE, EMPTY, LIMIT_SLACK, POSITION_ERROR, PRESENT,
                                PROTRUDING, THIN)
    from ..core.scan.scan_result import slot_plan

    carrier = layout.scanned_carrier
    plan = slot_plan(carrier, layout.mapping)
    scan, beam = layout.scan, layout.beam
    S, r = carrier.slot_count, 0.5 * carrier.wafer_diameter
    seats = np.array([carrier.seat_z(s) for s in range(1, S + 1)])
    t_low, t_high = plan.thickness_window()
    below, above = plan.position_window()
    # The limits inclusive by LIMIT_SLACK, as mapping's judge has them.
    t_low, t_high, below, above = (t_low - LIMIT_SLACK, t_high + LIMIT_SLACK,
                                   below + LIMIT_SLACK, above + LIMIT_SLACK)
    double = plan.double_limit() + LIMIT_SLACK
    seat_one, pitch = carrier.first_slot_z, carrier.pitch
    severity = np.array([EMPTY, PRESENT, THIN, POSITION_ERROR, DOUBLE, CROSS, PROTRUDING])
    rank = np.zeros(8, dtype=np.int64)
    rank[severity] = np.arange(len(severity))
    (ex, ey, _), (dx, dy, dz) = beam.emitter, beam.direction
    horizontal = math.hypot(dx, dy)
    ux, uy = dx / horizontal, dy / horizontal  # the beam's heading
    cx, cy = carrier.center
    fx, fy = carrier.front
    slope = carrier.pitch / carrier.support_span  # a cross-slotted wafer's rise a mm
    lx, ly = carrier.lateral
    rng = np.random.default_rng(seed)
    probabilities = dict(tolerances.states or {"present": 1.0})
    confusion = np.zeros((8, 8), dtype=np.int64)

    def draw(name, shape, nominal=0.0):
        dist = tolerances.get(name)
        return np.full(shape, nominal) if dist is None else dist.draw(rng, shape)

    for start in range(0, n, FLOOR_CHUNK):
        m = min(FLOOR_CHUNK, n - start)
        truth, lower = _states(rng, probabilities, m, S)
        # Per wafer (m, S, 2: a slot's wafer and a double's second) and per layout.
        seat = draw("seat_offset", (m, S, 2))
        thickness = np.clip(draw("thickness", (m, S, 2), carrier.wafer_thickness), 1e-6, None)
        protrusion = draw("protrusion", (m, S, 2))
        beam_z = draw("beam_z", m)
        tilt = np.radians(draw("beam_tilt", m))
        lag = scan.scan_speed * np.clip(draw("sensor_response", m, scan.sensor_response), 0, None)
        kind = truth[..., None]
        exists = np.stack([(truth != EMPTY) & ((truth != CROSS) | lower), truth == DOUBLE], -1)
        thickness = np.where(kind == THIN, THIN_FACTOR * thickness, thickness)
        z = (seats[None, :, None] + seat - beam_z[:, None, None]
             + np.where(kind == POSITION_ERROR, MISPLACED_RISE, 0.0)
             + np.where(kind == CROSS, 0.5 * carrier.pitch, 0.0))
        z[..., 1] = z[..., 0] + thickness[..., 0]
        shift = protrusion + np.where(kind == PROTRUDING, PROTRUDING_SHIFT, 0.0)
        # The chord the beam's line cuts from the rim, in mm along the beam's heading.
        px, py = ex - (cx + shift * fx), ey - (cy + shift * fy)
        along = px * ux + py * uy
        across2 = px * px + py * py - along * along
        half = np.sqrt(np.maximum(r * r - across2, 0.0))
        length = beam.length * math.sqrt(1.0 - dz * dz)
        a = np.clip(-along - half, 0.0, length)
        b = np.clip(-along + half, 0.0, length)
        met = exists & (r * r >= across2) & (a < b)
        # A face's height over the chord against the beam's: the beam's rise a mm (its tilt)
        # less the face's (a cross-slotted wafer's slope across the carrier).
        cross = kind == CROSS
        z = z + np.where(cross, slope * (lx * px + ly * py), 0.0)
        rise = np.tan(math.asin(dz) + tilt)[:, None, None] - np.where(
            cross, slope * (ux * lx + uy * ly), 0.0)
        za, zb = z - rise * a, z - rise * b  # the bottom face where each end of the chord is
        low, high = np.minimum(za, zb), np.maximum(za, zb) + thickness
        with np.errstate(invalid="ignore"):
            k_lo = np.where(met, np.maximum(0, np.ceil((low - scan.start_z) / scan.z_step)),
                            np.inf)
            k_hi = np.where(met, np.minimum(scan.last_step,
                                            np.floor((high - scan.start_z) / scan.z_step)), -1)
        k_lo = np.where(k_lo <= k_hi, k_lo, np.inf).reshape(m, 2 * S)
        k_hi = k_hi.reshape(m, 2 * S)
        # Runs: each layout's intervals by their first step, merged where they touch.
        order = np.argsort(k_lo, axis=1)
        first = np.take_along_axis(k_lo, order, axis=1)
        reach = np.maximum.accumulate(np.take_along_axis(k_hi, order, axis=1), axis=1)
        new = np.isfinite(first)
        new[:, 1:] &= first[:, 1:] > reach[:, :-1] + 1
        closes = np.ones_like(new)
        closes[:, :-1] = new[:, 1:]
        closes &= np.cumsum(new, axis=1) > 0
        rows, cols = np.nonzero(new)
        bottom = scan.start_z + first[rows, cols] * scan.z_step + lag[rows]
        top = scan.start_z + reach[np.nonzero(closes)] * scan.z_step + lag[rows]
        # SPEC §4 run by run: longer than the double limit, cross-slotted in the two slots
        # around its middle; else in the slot whose seat its bottom is nearest, judged by
        # position, then thickness; the worst finding a slot kept, a second run in a slot a
        # position error.
        size = top - bottom
        cross = size > double
        slot = np.where(cross, np.floor((0.5 * (bottom + top) - seat_one) / pitch),
                        np.floor((bottom - seat_one) / pitch + 0.5)).astype(np.int64)
        offset = bottom - (seat_one + slot * pitch)
        state = np.where(cross, CROSS,
                         np.where((offset > above) | (-offset > below), POSITION_ERROR,
                                  np.where(size < t_low, THIN,
                                           np.where(size <= t_high, PRESENT, DOUBLE))))
        rows = np.concatenate([rows, rows[cross]])
        slot = np.concatenate([slot, slot[cross] + 1])
        state = np.concatenate([state, state[cross]])
        inside = (slot >= 0) & (slot < S)
        rows, slot, state = rows[inside], slot[inside], state[inside]
        worst = np.zeros((m, S), dtype=np.int64)
        np.maximum.at(worst, (rows, slot), rank[state])
        runs = np.zeros((m, S), dtype=np.int64)
        np.add.at(runs, (rows, slot), 1)
        worst = np.where((runs > 1) & (worst < rank[CROSS]),
                         np.maximum(worst, rank[POSITION_ERROR]), worst)
        reported = severity[worst]
        out = (shift[..., 0] > plan.protrusion_limit) & exists[..., 0]
        reported = np.where(out, PROTRUDING, reported)
        confusion += np.bincount((truth * 8 + reported).ravel(),
                                 minlength=64).reshape(8, 8)
    return confusion
