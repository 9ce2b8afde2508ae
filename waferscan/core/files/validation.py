"""One check of a whole ``Layout`` for every reader: scenario files, parameters.txt and FreeCAD
layouts.

Each value a reader takes is checked on its own where it is read (``schema``); what only shows
once the values meet — a lag ``scan_speed × sensor_response`` that overflows, a carrier whose
slots run past the float range, a lift axis with no vertical component — is checked here, with
the same limits for every reader. ``layout_problems`` returns ``Problem(key, message, index)``
tuples in the scenario format's words (``slots``, ``pitch``, ``sensor_response``…); each reader
turns them into its own file, line, key or object property.

The limits also bound what one scan may cost (docs/reliability.md lists them): at most
``MAX_SLOTS`` slots a carrier, ``MAX_CARRIERS`` carriers, ``MAX_WAFERS`` wafers, and
``schema.MAX_POSITIONS`` stepped positions.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .. import schema
from ..rules import thickness_fits_pitch

MAX_SLOTS = 10_000
MAX_CARRIERS = 1_000
MAX_WAFERS = 10_000
# No coordinate or length of a layout is beyond 1 km (mm): a larger one is a typo, and keeping
# every value this small keeps sums and products of them (a carrier's top slot, a beam's end,
# a latch lag) finite, so no engine meets inf or NaN.
MAX_COORDINATE = 1_000_000.0
MIN_LENGTH = 1e-6  # mm: a length (pitch, thickness, diameter) below a nanometre is no length
# thickness_correction is the measured thickness over the true one (SPEC §11): beyond a factor
# of 100 either way the sensor measures nothing a correction could mend.
CORRECTION_RANGE = (0.01, 100.0)
# A lift axis must climb: within about 84° of vertical (a Z component of at least 0.1).
MIN_LIFT_Z = 0.1
MAX_BASE_YAW = 360.0  # degrees
# A jab or a sweep (SPEC §13) moves the fork across the beam, into the carrier: the beam must be
# within about 84° of horizontal (a horizontal part of at least 0.1 after normalising), and the
# fork's heading across it within about 84° of the way into the carrier's opening.
MIN_BEAM_ACROSS = 0.1
MIN_HEADING_INTO = 0.1


class Problem(NamedTuple):
    """What is wrong with one value. ``key`` is the scenario format's name of the value (a
    carrier's ``slots``, ``pitch``…, the beam's ``emitter``, the scan's ``sensor_response``);
    ``group`` the scenario table it belongs to (``carrier``, ``sensor``, ``scan``, ``robot``,
    ``wafer``); ``index`` the carrier's or wafer's index in the layout, else None."""

    key: str
    message: str
    index: int | None = None
    group: str | None = None


def _finite(values):
    return all(isinstance(v, (int, float)) and math.isfinite(v) for v in values)


def _coordinate_problem(values, what):
    """A message when a number or vector is not finite or beyond MAX_COORDINATE, else None."""
    values = tuple(values) if isinstance(values, (tuple, list)) else (values,)
    if not _finite(values):
        return f"{what} must be finite, got {_show(values)}"
    if any(abs(v) > MAX_COORDINATE for v in values):
        return f"{what} must be within ±{MAX_COORDINATE:,.0f} mm, got {_show(values)}"
    return None


def _show(values):
    return f"{values[0]:g}" if len(values) == 1 else "[" + ", ".join(f"{v:g}" for v in values) + "]"


def _positive_length(value, what):
    if not _finite((value,)) or not 0.0 < value <= MAX_COORDINATE:
        return f"{what} must be greater than 0 and at most {MAX_COORDINATE:,.0f} mm, got {value:g}"
    if value < MIN_LENGTH:  # 1e-320 is "greater than 0" and makes nonsense of every division
        return f"{what} must be at least {MIN_LENGTH:g} mm (1 nm), got {value:g}"
    return None


def carrier_problems(carrier, index=None):
    """The problems of one carrier's values and of the slots they make."""
    found = []

    def add(key, message):
        if message:
            found.append(Problem(key, message, index, "carrier"))

    count = carrier.slot_count
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_SLOTS:
        add("slots", f"expected a whole number of slots from 1 to {MAX_SLOTS:,}, got {count!r}")
        count = None
    add("pitch", _positive_length(carrier.pitch, "the pitch"))
    add("wafer_diameter", _positive_length(carrier.wafer_diameter, "the wafer diameter"))
    add("wafer_thickness", _positive_length(carrier.wafer_thickness, "the wafer thickness"))
    add("support_span", _positive_length(carrier.support_span, "the support span"))
    add("first_slot_z", _coordinate_problem(carrier.first_slot_z, "first_slot_z"))
    add("center", _coordinate_problem(carrier.center, "the centre"))
    if not _finite(carrier.front) or not any(carrier.front):
        add("front", f"must be a finite, non-zero direction, got {_show(tuple(carrier.front))}")
    if found:
        return found
    if not thickness_fits_pitch(carrier.wafer_thickness, carrier.pitch):
        add("wafer_thickness", f"wafer_thickness {carrier.wafer_thickness:g} must be less than "
                               f"the pitch {carrier.pitch:g}")
    if carrier.support_span > carrier.wafer_diameter:
        add("support_span", f"support_span {carrier.support_span:g} is wider than the wafer "
                            f"({carrier.wafer_diameter:g}): the wafer would fall through")
    top = carrier.first_slot_z + count * carrier.pitch
    if abs(top) > MAX_COORDINATE:
        add("slots" if count * carrier.pitch > MAX_COORDINATE else "first_slot_z",
            f"the carrier's {count:,} slots at {carrier.pitch:g} mm from z = "
            f"{carrier.first_slot_z:g} reach z = {top:g}, beyond ±{MAX_COORDINATE:,.0f} mm")
    return found


def scan_problems(scan):
    """The problems of the scan's values together (each is checked on its own when read)."""
    found = []
    for key in ("start_z", "final_z"):
        message = _coordinate_problem(getattr(scan, key), key)
        if message:
            found.append(Problem(key, message, group="scan"))
    if not _finite((scan.z_step,)) or scan.z_step < 0.0:
        found.append(Problem("z_step", f"must be finite and not negative, got {scan.z_step:g}",
                             group="scan"))
    if not _finite((scan.scan_speed,)) or scan.scan_speed <= 0.0:
        found.append(Problem("scan_speed", f"must be finite and greater than 0, got "
                                           f"{scan.scan_speed:g}", group="scan"))
    if not _finite((scan.sensor_response,)) or scan.sensor_response < 0.0:
        found.append(Problem("sensor_response", f"must be finite and not negative, got "
                                                f"{scan.sensor_response:g}", group="scan"))
    if found:
        return found
    lag = scan.scan_speed * scan.sensor_response
    if not lag <= schema.MAX_TRAVEL:
        found.append(Problem("sensor_response",
                             f"scan_speed {scan.scan_speed:g} mm/s × sensor_response "
                             f"{scan.sensor_response:g} s makes the sensor latch "
                             f"{lag:g} mm late; at most {schema.MAX_TRAVEL:,.0f} mm",
                             group="scan"))
    try:
        schema.check_scan_range(scan.start_z, scan.final_z, scan.z_step)
    except schema.ScanRangeError as exc:
        found.append(Problem(exc.key, str(exc), group="scan"))
    return found


def beam_problems(beam, lift_axis):
    found = []
    message = _coordinate_problem(beam.emitter, "the emitter")
    if message:
        found.append(Problem("emitter", message, group="sensor"))
    if not _finite(beam.direction) or not any(beam.direction):
        found.append(Problem("direction", "must be a finite, non-zero direction, got "
                                          f"{_show(tuple(beam.direction))}", group="sensor"))
    message = _positive_length(beam.length, "the beam's length")
    if message:
        found.append(Problem("length", message, group="sensor"))
    if not _finite(lift_axis) or not any(lift_axis):
        found.append(Problem("lift_axis", "must be a finite, non-zero direction, got "
                                          f"{_show(tuple(lift_axis))}", group="sensor"))
    else:
        norm = math.hypot(*lift_axis)
        if lift_axis[2] / norm < MIN_LIFT_Z:
            found.append(Problem("lift_axis", f"the lift axis must point upwards (z component "
                                              f"≥ {MIN_LIFT_Z:g} after normalising), got "
                                              f"{_show(tuple(lift_axis))}", group="sensor"))
    return found


def wafer_problems(wafer, index):
    found = []
    for key, message in (("center", _coordinate_problem(wafer.center, "the centre")),
                         ("diameter", _positive_length(wafer.diameter, "the diameter")),
                         ("thickness", _positive_length(wafer.thickness, "the thickness"))):
        if message:
            found.append(Problem(key, f"wafer {wafer.name!r}: {message}", index, "wafer"))
    if not _finite(wafer.normal) or not any(wafer.normal):
        found.append(Problem("normal", f"wafer {wafer.name!r}: the normal must be a finite, "
                                       f"non-zero direction", index, "wafer"))
    return found


def robot_problems(robot):
    if robot is None:
        return []
    found = []
    message = _coordinate_problem(robot.base, "the base")
    if message:
        found.append(Problem("base", message, group="robot"))
    if not _finite((robot.base_yaw,)) or abs(robot.base_yaw) > MAX_BASE_YAW:
        found.append(Problem("base_yaw", f"must be within ±{MAX_BASE_YAW:g} degrees, got "
                                         f"{robot.base_yaw:g}", group="robot"))
    return found


def _slow_key(scan):
    """The setting a jab's or sweep's problem is blamed on: the jab when one is made."""
    return "jab" if scan.jab > 0.0 else "sweep"


def _tine_entry(end, heading, center, radius):
    """The advance (mm, >= 0) along ``heading`` at which the plan point ``end`` enters the disc
    of ``radius`` about ``center``: 0 when it already is inside, None when it never does."""
    dx, dy = end[0] - center[0], end[1] - center[1]
    outside = dx * dx + dy * dy - radius * radius
    if outside < 0.0:
        return 0.0
    along = dx * heading[0] + dy * heading[1]
    disc = along * along - outside
    if along >= 0.0 or disc < 0.0:  # moving away, or passing beside the disc
        return None
    return -along - math.sqrt(disc)


def max_jab(layout, heading):
    """The deepest jab (mm) that keeps the fork's tines (the beam's two ends, seen from above)
    outside a wafer seated in the scanned carrier: the beam is between the tines, and a tine
    that reaches the wafer's rim at the beam's height would strike it. None: never."""
    beam, carrier = layout.beam, layout.scanned_carrier
    ends = [(beam.emitter[0] + lam * beam.direction[0], beam.emitter[1] + lam * beam.direction[1])
            for lam in (0.0, beam.length)]
    entries = [e for e in (_tine_entry(end, heading, carrier.center,
                                       0.5 * carrier.wafer_diameter) for end in ends)
               if e is not None]
    return min(entries) if entries else None


def slow_scan_problems(layout):
    """The problems of a jab or a sweep (SPEC §13) with the layout's beam and scanned carrier:
    a fork with no heading (a beam too steep), a heading that runs along the carrier's opening,
    a jab that would drive the tines into a seated wafer, a jab or a wrist radius beyond the
    layout's limits, a motion whose simulated time overflows. Checked whenever a jab or a sweep
    is set, whatever the mode: a mode given later (``--mode slow``) must not meet them first."""
    scan = layout.scan
    if not (scan.jab > 0.0 or scan.sweep > 0.0):
        return []
    key = _slow_key(scan)
    value = f"{getattr(scan, key):g} {'mm' if key == 'jab' else 'degrees'}"
    motion = ("the jab advances the fork across the beam" if key == "jab"
              else "the sweep turns the beam about a vertical wrist axis behind it")
    found = []
    for k in ("jab", "sweep_radius"):
        v = getattr(scan, k)
        if abs(v) > MAX_COORDINATE:
            found.append(Problem(k, f"must be at most {MAX_COORDINATE:,.0f} mm, got {v:g}",
                                 group="scan"))
    if found:
        return found
    ex, ey, ez = layout.beam.direction
    norm = math.sqrt(ex * ex + ey * ey + ez * ez)
    across = math.hypot(ex, ey) / norm
    if across < MIN_BEAM_ACROSS:
        return [Problem(key, f"{value} needs a beam that crosses the pocket: {motion}, "
                             f"but the beam's direction "
                             f"{_show(tuple(layout.beam.direction))} is (nearly) vertical: "
                             f"its horizontal part is {across:.3g} after normalising, at least "
                             f"{MIN_BEAM_ACROSS:g} needed", group="scan")]
    hx, hy = -ey / (across * norm), ex / (across * norm)
    carrier = layout.scanned_carrier
    fx, fy = carrier.front
    into = abs(hx * fx + hy * fy) / math.hypot(fx, fy)
    if into < MIN_HEADING_INTO:
        return [Problem(key, f"{value} needs a beam across the carrier's opening: the "
                             f"fork's heading (across the beam "
                             f"{_show(tuple(layout.beam.direction))}) runs along carrier "
                             f"{carrier.name}'s opening (front {_show(tuple(carrier.front))}), "
                             f"not into it", group="scan")]
    if hx * fx + hy * fy > 0.0:
        hx, hy = -hx, -hy
    # The carrier must lie ahead of the start pose's beam along the heading: behind it (a front
    # facing away from the robot) the jab would draw back and the wrist stand in the carrier.
    beam = layout.beam
    mid = [e + 0.5 * beam.length * d for e, d in zip(beam.emitter, beam.direction)]
    ahead = (carrier.center[0] - mid[0]) * hx + (carrier.center[1] - mid[1]) * hy
    if ahead <= 0.0:
        return [Problem(key, f"{value} needs the carrier ahead of the fork: carrier "
                             f"{carrier.name}'s centre is {-ahead:.3f} mm behind the start "
                             f"pose's beam along the fork's heading into its opening (front "
                             f"{_show(tuple(carrier.front))}): the opening faces away",
                        group="scan")]
    if scan.jab > 0.0:
        deepest = max_jab(layout, (hx, hy))
        if deepest is not None and scan.jab > deepest:
            where = ("already stands inside" if deepest == 0.0
                     else f"reaches it after {deepest:.3f} mm")
            found.append(Problem("jab", f"{scan.jab:g} mm would drive the fork's tines (the "
                                        f"beam's ends) into a wafer seated in carrier "
                                        f"{carrier.name!r}: a tine {where}", group="scan"))
    from ..scan.slow_scan import move_time  # the durations' own arithmetic

    for k, distance, speed, acceleration in (
            ("arm_speed", scan.jab, scan.arm_speed, scan.arm_acceleration),
            ("wrist_speed", 2.0 * scan.sweep, scan.wrist_speed, scan.wrist_acceleration)):
        seconds = move_time(distance, speed, acceleration) * 4.0 * MAX_SLOTS
        if not math.isfinite(seconds):
            bad = k if not math.isfinite(distance / speed) else k.replace("speed", "acceleration")
            found.append(Problem(bad, f"must be larger: {getattr(scan, bad):g} makes the "
                                      f"simulated time of a pocket's motion overflow",
                                 group="scan"))
    return found


def duration_problems(scan):
    """The lift's speed and acceleration must keep the simulated durations (SPEC §13: a fast and
    a slow scan's, reported for every scan) finite: bounded here by every stepped position and
    every slot moving the whole travel."""
    from ..scan.slow_scan import lift_acceleration, move_time

    travel = max(abs(scan.final_z - scan.start_z), scan.z_step)
    moves = 4.0 * (MAX_SLOTS + schema.MAX_POSITIONS)
    seconds = moves * (move_time(travel, scan.scan_speed, lift_acceleration(scan))
                       + scan.sensor_response)
    if math.isfinite(seconds):
        return []
    if not math.isfinite(moves * scan.sensor_response):
        key = "sensor_response"
    elif not math.isfinite(moves * travel / scan.scan_speed):
        key = "scan_speed"
    else:
        key = "acceleration"
    way = "smaller" if key == "sensor_response" else "larger"
    return [Problem(key, f"must be {way}: {getattr(scan, key):g} makes the scan's simulated "
                         f"duration overflow", group="scan")]


def mapping_problems(mapping, thickness):
    """The problems of a mapping recipe (SPEC §11) against the scanned carrier's nominal wafer
    ``thickness`` (mm): its limits resolved as ``mapping.SlotPlan`` resolves them must make a
    thin < present < double < cross-slotted order. The key blamed is the one that was given."""
    from ..mapping import RULE_SETS, SlotPlan

    found = []

    def add(key, message):
        found.append(Problem(key, message, group="mapping"))

    values = {key: getattr(mapping, key) for key in
              ("thickness_tolerance", "position_tolerance", "protrusion_limit", "thickness_min",
               "thickness_max", "double_threshold", "position_below", "position_above",
               "thickness_correction")}
    for key, value in values.items():
        if value is None:
            continue
        if not _finite((value,)) or abs(value) > MAX_COORDINATE:
            add(key, f"must be finite and within ±{MAX_COORDINATE:,.0f}, got {value!r}")
        elif value < 0.0:
            add(key, f"must not be negative, got {value:g}")
    if mapping.thickness_correction is not None and _finite((mapping.thickness_correction,)) \
            and mapping.thickness_correction <= 0.0:
        add("thickness_correction", f"must be greater than 0, got {mapping.thickness_correction:g}")
    elif mapping.thickness_correction is not None \
            and _finite((mapping.thickness_correction,)) \
            and not CORRECTION_RANGE[0] <= mapping.thickness_correction <= CORRECTION_RANGE[1]:
        low, high = CORRECTION_RANGE
        add("thickness_correction", f"must be from {low:g} to {high:g} (the measured thickness "
                                    f"over the true one), got {mapping.thickness_correction:g}")
    if mapping.rules not in RULE_SETS:
        add("rules", f"expected one of {', '.join(RULE_SETS)}, got {mapping.rules!r}")
    if found or not _finite((thickness,)):
        return found
    plan = SlotPlan(1, 1.0, 0.0, thickness, mapping.thickness_tolerance_for(thickness),
                    mapping.position_tolerance, rules=mapping.rules,
                    thickness_min=mapping.thickness_min, thickness_max=mapping.thickness_max,
                    double_threshold=mapping.double_threshold)
    low, high = plan.thickness_window()
    double = plan.double_limit()
    window_given = mapping.thickness_min is not None or mapping.thickness_max is not None
    # A window of t ± 0 (thickness_tolerance 0) is SPEC §4's and stays allowed; a window given
    # as limits must be a window.
    if not (low < high if window_given else low <= high):
        key = "thickness_min" if mapping.thickness_min is not None else (
            "thickness_max" if mapping.thickness_max is not None else "thickness_tolerance")
        add(key, f"thickness_min {low:g} must be less than thickness_max {high:g}")
    elif not (double > high if mapping.double_threshold is not None or window_given
              else double >= high):  # SPEC §4's own limits meet only when t is lost to rounding
        key = "double_threshold" if mapping.double_threshold is not None else (
            "thickness_max" if mapping.thickness_max is not None else "thickness_tolerance")
        add(key, f"double_threshold {double:g} must be greater than thickness_max {high:g}")
    return found


def _scanned_thickness(layout):
    """The nominal thickness of the scanned carrier's wafers, or None when the layout does not
    say which carrier it scans (its reader reports that)."""
    try:
        return layout.scanned_carrier.wafer_thickness
    except (ValueError, StopIteration):
        return None


def layout_problems(layout):
    """Every problem of a layout, in the order a reader would meet the values: carriers, beam,
    scan, robot, wafers. An empty list means the layout makes a scan of bounded cost."""
    found = []
    if len(layout.carriers) > MAX_CARRIERS:
        found.append(Problem("carrier", f"{len(layout.carriers):,} carriers; at most "
                                        f"{MAX_CARRIERS:,}", group="carrier"))
    for i, carrier in enumerate(layout.carriers[:MAX_CARRIERS]):
        found += carrier_problems(carrier, i)
    found += beam_problems(layout.beam, layout.lift_axis)
    found += scan_problems(layout.scan)
    if not found:
        found += duration_problems(layout.scan)  # SPEC §13: every scan reports its durations
        found += slow_scan_problems(layout)  # SPEC §13: the jab and sweep with beam and carrier
    found += robot_problems(layout.robot)
    thickness = _scanned_thickness(layout)
    if thickness is not None:
        found += mapping_problems(layout.mapping, thickness)
    if len(layout.wafers) > MAX_WAFERS:
        found.append(Problem("wafer", f"{len(layout.wafers):,} wafers; at most {MAX_WAFERS:,}"))
    else:
        for i, wafer in enumerate(layout.wafers):
            found += wafer_problems(wafer, i)
            if len(found) > 20:  # the first is what a reader reports
                break
    return found
