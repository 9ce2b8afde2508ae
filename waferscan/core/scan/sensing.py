"""A scan with a real sensor (SPEC §10): a beam spot, the amplifier's thresholds, latching while
the axis moves. ``scan_layout`` hands a layout here when it asks for any of them; the ideal
sensor (spot 0, latch ``step``) keeps the paper's path in core/scan/layout_scan.py untouched, so its results
stay bit for bit what they were.

The signal is worked out per group of wafers that can share the spot (core/sensor/spot.py): for a
continuous stroke (``latch`` encoder or sampled, or z_step = 0) the output's edges are found by
bisection on the closed-form b(z); on the step grid b is read at each step inside the group's
reach and the output is switched step by step. Either way only the few positions near wafers
are evaluated: the cost does not grow with the length of the travel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..mapping import map_slots, two_run_warnings, unscanned_slots
from ..model import DOWN, SLOW, UP
from ..sensor.amplifier import (
    SAMPLES_PER_SPOT,
    grouped_level_intervals,
    output_intervals,
    stepped_output,
)
from ..sensor.motion import STEP, Stroke
from ..sensor.spot import (
    DEFAULT_AMPLIFIER,
    IDEAL_SPOT,
    BlockedFraction,
    GroupedFraction,
    wafer_groups,
)
from .engines import ExactHits, analytic_engine


def ideal_sensor(layout):
    """True when the layout asks for none of SPEC §10's sensor models: the paper's scan."""
    spot = layout.spot
    return (spot is None or spot.ideal) and layout.scan.latch == STEP


@dataclass
class SignalGroup:
    """b(z) of one group of wafers: ``fraction`` of the lift translation tau, with z = z0 +
    tau * az; ``z_range`` where it can be non-zero; ``peak`` the largest b seen."""

    fraction: object
    z0: float
    az: float
    z_range: tuple
    names: tuple
    peak: float = 0.0


@dataclass
class SignalTrace:
    """The blocked fraction along the scan, for plots: groups with a spot, or the ideal beam's
    runs (b is 1 inside, 0 outside). Thresholds as blocked fractions."""

    groups: list
    ideal_runs: tuple
    threshold_on: float
    threshold_off: float

    def blocked(self, z):
        """b at scan positions z (numpy array)."""
        import numpy as np

        z = np.asarray(z, dtype=float)
        b = np.zeros(z.shape)
        for group in self.groups:
            inside = (z >= group.z_range[0]) & (z <= group.z_range[1])
            if inside.any():
                b[inside] += group.fraction((z[inside] - group.z0) / group.az)
        for lo, hi in self.ideal_runs:
            b[(z >= lo) & (z <= hi)] = 1.0
        return np.clip(b, 0.0, 1.0)


def strokes(scan):
    """The directions the beam moves in, True for up."""
    if scan.mode == SLOW or scan.direction == UP:
        return (True,)
    if scan.direction == DOWN:
        return (False,)
    return (True, False)


def stroke_latcher(scan, moving_up):
    """A function from an output change at position z to the latched position."""
    if scan.mode == SLOW:
        return lambda z: z  # read at rest
    if scan.latch == STEP:
        lag = scan.latch_lag
        return (lambda z: z + lag) if moving_up else (lambda z: z - lag)
    stroke = Stroke(scan.start_z, scan.final_z, scan.scan_speed, scan.acceleration) if moving_up \
        else Stroke(scan.final_z, scan.start_z, scan.scan_speed, scan.acceleration)
    return lambda z: stroke.latched(z, scan.sensor_response, scan.latch, scan.sample_period)


def _ideal_output(layout, window):
    """ON stretches of the ideal line beam (the same both ways: b is 0 or 1), per-wafer spans
    and the runs' wafers, from the analytic engine."""
    from .scan_result import exact_intervals, run_wafers, stepped_intervals

    hits = analytic_engine(layout)
    if isinstance(hits, ExactHits):
        spans, wafer_spans = exact_intervals(hits, window)
    else:
        spans, wafer_spans = stepped_intervals(hits, layout.scan, window)
    names = run_wafers(spans, layout.wafers, wafer_spans)
    return [(a, b, n) for (a, b), n in zip(spans, names)], wafer_spans


def _spot_output(layout, spot, amplifier, window, moving, ray_ranges=None):
    """Per stroke direction, the ON stretches (bottom, top, wafer names) of the output with a
    beam spot; and the signal's groups."""
    import numpy as np

    scan = layout.scan
    z0 = layout.beam.emitter[2]
    az = layout.lift_axis[2]
    low, high = scan.start_z, scan.final_z
    if window is not None:
        low, high = max(low, window[0]), min(high, window[1])
    on_level, off_level = amplifier.threshold_on, amplifier.off_level
    # Every wafer: the accessibility check is made for the line beam, not for a spot.
    candidates = layout.wafers
    groups = wafer_groups(layout, candidates, spot, ray_ranges=ray_ranges)
    out = {up: [] for up in moving}
    signal, fractions, spans, names = [], [], [], []
    spacing = max(2.0 * spot.half_height, 1e-6) / SAMPLES_PER_SPOT
    for members, ranges, (tau_lo, tau_hi) in groups:
        wafers = [candidates[i] for i in members]
        fraction = BlockedFraction(layout, wafers, spot, ranges, ray_ranges=ray_ranges)
        z_lo, z_hi = z0 + tau_lo * az, z0 + tau_hi * az
        names.append(tuple(w.name for w in wafers))
        signal.append(SignalGroup(fraction, z0, az, (z_lo, z_hi), names[-1]))
        fractions.append(fraction)
        spans.append((max(z_lo, low), min(z_hi, high)))
    together = GroupedFraction(fractions)
    if not fractions:
        pass
    elif scan.exact or scan.latch != STEP:
        tau_spans = [((lo - z0) / az, (hi - z0) / az) for lo, hi in spans]
        on, peaks = grouped_level_intervals(together, tau_spans, on_level, spacing / az)
        off = on if off_level == on_level else \
            grouped_level_intervals(together, tau_spans, off_level, spacing / az)[0]
        for g, group in enumerate(signal):
            group.peak = peaks[g]
            for up in moving:
                for a, b in output_intervals(on[g], off[g], up):
                    out[up].append((z0 + a * az, z0 + b * az, names[g]))
    else:
        positions, owners = [], []
        for g, (lo, hi) in enumerate(spans):
            k_lo = max(0, math.ceil((lo - scan.start_z) / scan.z_step))
            k_hi = min(scan.last_step, math.floor((hi - scan.start_z) / scan.z_step))
            positions.append(scan.position(np.arange(k_lo, k_hi + 1, dtype=float)))
            owners.append(np.full(len(positions[-1]), g))
        z_all = np.concatenate(positions)
        values_all = together((z_all - z0) / az, np.concatenate(owners)) if z_all.size \
            else z_all
        offset = 0
        for g, z in enumerate(positions):
            values = values_all[offset:offset + len(z)]
            offset += len(z)
            if not len(z):
                continue
            signal[g].peak = float(values.max())
            for up in moving:
                for first, last in stepped_output(values, on_level, off_level, up):
                    out[up].append((float(z[first]), float(z[last]), names[g]))
    for up in moving:
        out[up].sort()
    return out, signal


def sensed_scan(layout, engine="analytic", progress=None, ray_ranges=None):
    """Scan a layout with a real sensor (SPEC §10) and map its slots: the ``ScanResult`` of
    core/scan/layout_scan.py with ``edges`` (every latched ON/OFF edge in the order latched) and ``signal``
    (b along the scan)."""
    from .scan_result import (
        ScanResult,
        SensorRun,
        WaferInterval,
        missed_by_beam,
        pocket_window,
        protruding_slots,
        scan_warnings,
        scanned_range,
        slot_plan,
    )

    if engine != "analytic":
        raise ValueError(f"a beam spot or latching in motion is computed by the analytic "
                         f"engine only, not {engine!r}")
    asked = None
    if layout.scan.latch != STEP:
        # Edges are continuous positions in a continuous stroke (SPEC §10): no grid. What was
        # asked is kept for the result's files (results.txt echoes parameters.txt).
        if layout.scan.z_step != 0.0:
            asked = layout.scan
        layout = layout.with_scan(z_step=0.0)
    scan = layout.scan
    if scan.final_z < scan.start_z:
        raise ValueError("final_z is below start_z")
    spot = layout.spot or IDEAL_SPOT
    amplifier = layout.amplifier or DEFAULT_AMPLIFIER
    carrier = layout.scanned_carrier
    plan = slot_plan(carrier, layout.mapping)
    window = pocket_window(plan) if scan.mode == SLOW else None
    moving = strokes(scan)

    ideal_runs, wafer_spans = _ideal_output(layout, window)
    if spot.ideal:
        outputs = {up: ideal_runs for up in moving}
        signal = SignalTrace([], tuple((a, b) for a, b, _ in ideal_runs), 1.0, 1.0)
    else:
        outputs, groups = _spot_output(layout, spot, amplifier, window, moving, ray_ranges)
        signal = SignalTrace(groups, (), amplifier.threshold_on, amplifier.off_level)

    edges = []
    latched = {}
    for up in moving:
        at = stroke_latcher(scan, up)
        runs = [(at(a), at(b)) if up else (at(b), at(a)) for a, b, _ in outputs[up]]
        latched[up] = runs
        stroke = "up" if up else "down"
        for z_in, z_out in (runs if up else reversed(runs)):
            edges += [{"z": z_in, "edge": "on", "stroke": stroke},
                      {"z": z_out, "edge": "off", "stroke": stroke}]

    warnings = []
    first = moving[0]
    runs = []
    if len(moving) == 2 and len(outputs[True]) == len(outputs[False]) and all(
            u[0] <= d[1] and d[0] <= u[1] for u, d in zip(outputs[True], outputs[False])):
        # Up then down: the mean of the two strokes' IN and OUT (SPEC §3), the lag cancels.
        for (a, b, names), (in_u, out_u), (in_d, out_d) in zip(outputs[True], latched[True],
                                                               latched[False]):
            runs.append(SensorRun(0.5 * (in_u + out_d), 0.5 * (out_u + in_d), names, (a, b)))
    else:
        if len(moving) == 2:
            warnings.append("the up and down strokes saw different runs (hysteresis or a "
                            "threshold at a wafer's peak): the up stroke's are reported")
        for (a, b, names), (z_in, z_out) in zip(outputs[first], latched[first]):
            runs.append(SensorRun(z_in, z_out, names, (a, b)))

    wafers = tuple(WaferInterval(w.name, *(span if span is not None else (None, None)))
                   for w, span in zip(layout.wafers, wafer_spans))
    flagged, protrusions = protruding_slots(carrier, plan, layout.wafers)
    scanned = (scan.start_z, scan.final_z)
    unscanned = unscanned_slots(plan, scanned)
    spans = [(r.bottom, r.top) for r in runs]
    slot_map = map_slots(plan, spans, flagged, unscanned)
    warnings = list(scan_warnings(layout, plan, [(a, b) for a, b, _ in outputs[first]], scanned,
                                  unscanned, scanned_range(scan, window))) + warnings
    warnings += missed_wafer_warnings(signal, outputs[first], plan, amplifier)
    warnings += missed_by_beam(layout, layout.beam, wafer_spans)
    warnings += two_run_warnings(plan, slot_map, spans)  # "boundary" rules only
    return ScanResult(layout, engine, plan, tuple(runs), wafers, slot_map, protrusions,
                      tuple(warnings), edges=tuple(edges), signal=signal, asked_scan=asked)


def missed_wafer_warnings(signal, output, plan, amplifier):
    """A group of wafers the beam partly blocked without ever switching the output: the slot
    reads empty, and the warning says how much of the spot was blocked at most (SPEC §10)."""
    warnings = []
    for group in signal.groups:
        if group.peak <= 0.0:
            continue
        if any(a <= group.z_range[1] and b >= group.z_range[0] for a, b, _ in output):
            continue
        slot = plan.nearest_slot(0.5 * (group.z_range[0] + group.z_range[1]))
        warnings.append(f"{', '.join(group.names)} near slot {slot} blocked at most "
                        f"{group.peak:.1%} of the beam spot, below threshold_on "
                        f"{amplifier.threshold_on:g}: missed, the slot reads as if empty")
    return warnings


def scan_edges(result):
    """Every ON/OFF edge in the order latched: the real sensor's own list, or for the ideal
    sensor the runs' IN and OUT stroke by stroke (updown: the up stroke, then the down one)."""
    if result.edges:
        return list(result.edges)
    scan = result.layout.scan
    moving = strokes(scan)
    edges = []
    for up in moving:
        stroke = "up" if up else "down"
        at = stroke_latcher(scan, up) if len(moving) == 2 else None
        ordered = sorted(result.runs, key=lambda r: r.bottom, reverse=not up)
        for run in ordered:
            if at is None:
                z_in, z_out = run.z_in, run.z_out
            else:
                bottom, top = run.unlatched
                z_in, z_out = (at(bottom), at(top)) if up else (at(top), at(bottom))
            edges += [{"z": z_in, "edge": "on", "stroke": stroke},
                      {"z": z_out, "edge": "off", "stroke": stroke}]
    return edges


def slot_readings(result):
    """Per slot, as a load port reports it: (thickness, bottom) in mm of the run the slot was
    judged by (its first), the thickness the ON-to-OFF distance, the bottom the run's lower
    latched edge (base-frame Z); (None, None) for a slot without a run."""
    readings = []
    for slot in result.slot_map.slots:
        if slot.runs:
            run = result.runs[slot.runs[0]]
            readings.append((run.diff, run.bottom))
        else:
            readings.append((None, None))
    return readings
