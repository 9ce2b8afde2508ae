"""Auto-calibration from reference wafers (SPEC §11; DOMAIN-NOTES: MAP ACAL).

A controller's taught slots drift from the carrier's real ones (a seat 0.3 mm high, a pitch of
10.02 mm instead of 10). With a reference wafer in the bottom slot and one in the top slot, one
scan over the whole carrier measures where they really are:

- slot-1 seat = the bottom edge of the bottom reference's run, as latched;
- pitch = (top reference's bottom − bottom reference's bottom) / (n − 1);
- scan start and end = one pitch below slot 1's new seat and one pitch above slot n's: half a
  pitch beyond the outer slots' windows, so that every window is wholly scanned (SPEC §3);
  the start is put on the calibration scan's step grid (at or below), the end on the grid at
  or above, so later scans latch the references where the calibration did;
- thickness correction = the references' mean measured diff / the nominal thickness.

Then a check scan with the new recipe must read both references present. Each failure has its
own kind (``CalibrationError.kind``) and words: no wafer in the bottom slot, none in the top
slot, the check scan failed (which slots read what).

The seats measured are latched edges: they carry the sensor's latch lag and the step grid, as
every later scan with the same settings does, so the recipe matches what those scans see. The
taught seat must be within half a pitch of the real one: the references are found as the slots
nearest their runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .errors import InputError, WaferScanError
from .mapping import PRESENT, STATE_NAMES, UNSCANNED
from .model import FAST
from .recipe import RECIPE_KEYS, resolved_values

NO_BOTTOM_WAFER = "no-bottom-wafer"
NO_TOP_WAFER = "no-top-wafer"
CHECK_FAILED = "check-failed"
# The command line's exit status for each failure (docs/tutorials/recipes-calibration.md); 2 stays
# bad input, 1 an internal fault.
EXIT_CODES = {NO_BOTTOM_WAFER: 3, NO_TOP_WAFER: 4, CHECK_FAILED: 5}

# The keys a calibration sets or reports, in the order they are shown: the taught slots, the
# scan range, then the recipe's windows (resolved) and the correction.
REPORTED_KEYS = ("first_slot_z", "slot_pitch", "start_z", "final_z") + RECIPE_KEYS


class CalibrationError(WaferScanError):
    """A calibration that could not be made or did not check out. ``kind`` is one of
    NO_BOTTOM_WAFER, NO_TOP_WAFER, CHECK_FAILED; ``words`` says what the scan saw; ``check`` is
    the check scan's ScanResult when there was one."""

    def __init__(self, kind, words, check=None):
        self.kind = kind
        self.words = words
        self.check = check
        super().__init__(str(self))

    def __str__(self):
        return f"{self.kind}: {self.words}"


@dataclass(frozen=True)
class Calibration:
    """A calibration's outcome: the layout before and with the new recipe, what was measured
    and both scans."""

    before: object          # Layout with the recipe it started from
    after: object           # Layout with the new recipe (slots, scan range, correction)
    first_slot_z: float     # mm, measured slot-1 seat
    pitch: float            # mm, measured
    thickness_correction: float
    references: tuple       # the bottom and top references' SensorRuns
    scan: object            # the calibration scan's ScanResult
    check: object           # the check scan's ScanResult

    def values(self, layout):
        """The REPORTED_KEYS of a layout's recipe (windows resolved), for showing side by side."""
        carrier = layout.scanned_carrier
        plan = _plan(layout)
        values = {"first_slot_z": carrier.first_slot_z, "slot_pitch": carrier.pitch,
                  "start_z": layout.scan.start_z, "final_z": layout.scan.final_z}
        values.update(resolved_values(plan))
        return values

    def rows(self):
        """(key, current value, new value) for every REPORTED_KEYS key."""
        old, new = self.values(self.before), self.values(self.after)
        return [(key, old[key], new[key]) for key in REPORTED_KEYS]


def _plan(layout):
    from .scan_result import slot_plan

    return slot_plan(layout.scanned_carrier, layout.mapping)


def calibration_layout(layout):
    """The calibration scan: a fast stroke from one pitch below the taught slot 1 to one pitch
    above the taught slot n (the real seats may lie up to half a pitch off the taught ones)."""
    carrier = layout.scanned_carrier
    start = carrier.seat_z(1) - carrier.pitch
    end = carrier.seat_z(carrier.slot_count) + carrier.pitch
    return layout.with_scan(mode=FAST, start_z=start, final_z=_on_grid(start, end,
                                                                       layout.scan.z_step))


def _on_grid(start, end, step):
    """``end`` raised to the next scan position of the grid start + k·step (exact mode: as is),
    so that the last step lies at or beyond it."""
    if step <= 0.0:
        return end
    steps = math.ceil((end - start) / step - 1e-9)
    return start + steps * step


def _nearest_taught_slot(carrier, z):
    return int(math.floor((z - carrier.first_slot_z) / carrier.pitch + 0.5)) + 1


def _where(run):
    return f"{run.diff:.3f} mm at z = {run.bottom:.3f}"


def references_of(layout, runs):
    """The bottom and top reference runs among a calibration scan's ``runs`` (SensorRuns), or a
    CalibrationError: the lowest run must be the taught slot 1's and one wafer long (not longer
    than the recipe's double limit), the highest slot n's and the same."""
    carrier = layout.scanned_carrier
    plan = _plan(layout)
    n = carrier.slot_count
    ordered = sorted(runs, key=lambda r: r.bottom)
    if not ordered:
        raise CalibrationError(NO_BOTTOM_WAFER, "no wafer in the bottom slot (slot 1): the "
                                                "calibration scan saw no wafer at all")
    low, high = ordered[0], ordered[-1]
    slot = _nearest_taught_slot(carrier, low.bottom)
    if slot != 1:
        raise CalibrationError(NO_BOTTOM_WAFER, f"no wafer in the bottom slot (slot 1): the "
                                                f"lowest run, {_where(low)}, is nearest slot "
                                                f"{slot}'s seat")
    if plan.corrected(low.diff) > plan.double_limit():
        raise CalibrationError(NO_BOTTOM_WAFER, f"no single wafer in the bottom slot (slot 1): "
                                                f"its run, {_where(low)}, is longer than the "
                                                f"double limit {plan.double_limit():g} mm")
    if n == 1:
        return low, low
    slot = _nearest_taught_slot(carrier, high.bottom)
    if high is low or slot != n:
        raise CalibrationError(NO_TOP_WAFER, f"no wafer in the top slot (slot {n}): the highest "
                                             f"run, {_where(high)}, is nearest slot {slot}'s "
                                             f"seat")
    if plan.corrected(high.diff) > plan.double_limit():
        raise CalibrationError(NO_TOP_WAFER, f"no single wafer in the top slot (slot {n}): its "
                                             f"run, {_where(high)}, is longer than the double "
                                             f"limit {plan.double_limit():g} mm")
    return low, high


def recalibrated(layout, low, high, grid_start=None):
    """The layout with the recipe the references give: the scanned carrier's taught slot-1 seat
    and pitch, the scan range and the thickness correction. ``grid_start``: the calibration
    scan's start_z; the new range starts on its step grid, so that the check scan and every
    later one latch the references where the calibration did. Returns (layout, seat, pitch,
    correction)."""
    carrier = layout.scanned_carrier
    n = carrier.slot_count
    seat = low.bottom
    pitch = (high.bottom - low.bottom) / (n - 1) if n > 1 else carrier.pitch
    mean = 0.5 * (low.diff + high.diff)
    if not pitch > carrier.wafer_thickness:
        raise CalibrationError(NO_TOP_WAFER, f"the references are {pitch:g} mm a slot apart, no "
                                             f"more than a wafer's thickness: not slots 1 and {n}")
    if not mean > 0.0:
        raise InputError("z_step", None, f"the references read {mean:g} mm thick: z_step "
                                         f"{layout.scan.z_step:g} is too coarse to measure them")
    correction = mean / carrier.wafer_thickness
    taught = replace(carrier, first_slot_z=seat, pitch=pitch)
    start = seat - pitch
    step = layout.scan.z_step
    if grid_start is not None and step > 0.0:
        start = grid_start + math.floor((start - grid_start) / step + 1e-9) * step
    end = _on_grid(start, seat + n * pitch, layout.scan.z_step)
    after = replace(layout, carriers=tuple(taught if c.name == carrier.name else c
                                           for c in layout.carriers),
                    mapping=replace(layout.mapping, thickness_correction=correction))
    after = after.with_scan(start_z=start, final_z=end)
    return after, seat, pitch, correction


def check_problems(result):
    """What a check scan read wrong: the bottom and top slots must read present and no slot
    may be unscanned. A list of sentences (empty: the check passed)."""
    n = result.plan.slot_count
    states = {s.slot: s.state for s in result.slot_map.slots}
    wrong = [f"slot {slot} read {states[slot]} ({STATE_NAMES[states[slot]]})"
             for slot in sorted({1, n}) if states[slot] != PRESENT]
    unscanned = [s for s, state in states.items() if state == UNSCANNED]
    if unscanned:
        wrong.append(f"slots {', '.join(map(str, unscanned))} unscanned")
    return wrong


def calibrate(layout, scan):
    """Calibrate the layout's recipe from its reference wafers. ``scan(layout)`` returns a
    ScanResult (core.scan.scan_layout, or a scan through a document). Returns a Calibration or
    raises CalibrationError."""
    first = scan(calibration_layout(layout))
    low, high = references_of(layout, first.runs)
    after, seat, pitch, correction = recalibrated(layout, low, high, first.layout.scan.start_z)
    check = scan(after)
    wrong = check_problems(check)
    if wrong:
        raise CalibrationError(CHECK_FAILED, f"check scan failed: {'; '.join(wrong)} "
                                             f"(code {check.code})", check)
    return Calibration(layout, after, seat, pitch, correction, (low, high), first, check)


def format_calibration(calibration):
    """The recipe before and after, one key a line, and the check scan's code: what
    ``waferscan calibrate`` prints."""
    rows = calibration.rows()
    width = max(len(key) for key, _, _ in rows)
    lines = [f"{'key':<{width}}  {'current':>14}  {'calibrated':>14}"]
    for key, old, new in rows:
        lines.append(f"{key:<{width}}  {_shown(old):>14}  {_shown(new):>14}")
    check = calibration.check
    lines += ["", f"check scan code {check.code}", f"check scan E87  {check.e87}"]
    return "\n".join(lines)


def _shown(value):
    return f"{value:.4f}" if isinstance(value, float) else str(value)
