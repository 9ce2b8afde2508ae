"""One check of a whole ``Layout`` for every reader: scenario files, parameters.txt and FreeCAD
layouts.

Each value a reader takes is checked on its own where it is read (``schema``); what only shows
once the values meet — a lag ``scan_speed × sensor_response`` that overflows, a carrier whose
slots run past the float range, a lift axis with no vertical component — is checked here, with
the same limits for every reader. ``layout_problems`` returns ``Problem(key, message, index)``
tuples in the scenario format's words (``slots``, ``pitch``, ``sensor_response``…); each reader
turns them into its own file, line, key or object property.

The limits also bound what one scan may cost (RELIABILITY.md lists them): at most
``MAX_SLOTS`` slots a carrier, ``MAX_CARRIERS`` carriers, ``MAX_WAFERS`` wafers, and
``schema.MAX_POSITIONS`` stepped positions.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from . import schema
from .rules import thickness_fits_pitch

MAX_SLOTS = 10_000
MAX_CARRIERS = 1_000
MAX_WAFERS = 10_000
# No coordinate or length of a layout is beyond 1 km (mm): a larger one is a typo, and keeping
# every value this small keeps sums and products of them (a carrier's top slot, a beam's end,
# a latch lag) finite, so no engine meets inf or NaN.
MAX_COORDINATE = 1_000_000.0
# A lift axis must climb: within about 84° of vertical (a Z component of at least 0.1).
MIN_LIFT_Z = 0.1
MAX_BASE_YAW = 360.0  # degrees


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


def mapping_problems(mapping, thickness):
    """The problems of a mapping recipe (SPEC §11) against the scanned carrier's nominal wafer
    ``thickness`` (mm): its limits resolved as ``mapping.SlotPlan`` resolves them must make a
    thin < present < double < cross-slotted order. The key blamed is the one that was given."""
    from .mapping import RULE_SETS, SlotPlan

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
