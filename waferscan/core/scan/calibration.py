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

A reference is one wafer of nominal thickness: the lowest run must lie in the taught slot 1's
window, alone there, with its diff within the recipe's thickness window (after its correction);
the highest run likewise in slot n's. Anything else is refused before a recipe is computed
from it (a double taken as a reference makes a correction of 2, which then reads doubles as
present). Then a check scan with the new recipe must read every slot holding a wafer present
(the references and any other wafer: a loaded slot read thin, double, cross-slotted, off its
seat or protruding fails the check, as does an unscanned slot or a run in no slot). Each
failure has its own kind (``CalibrationError.kind``) and words: no wafer in the bottom slot,
none in the top slot, the check scan failed (which slots read what).

The seats measured are latched edges: they carry the sensor's latch lag and the step grid, as
every later scan with the same settings does, so the recipe matches what those scans see. The
taught seat must be within half a pitch of the real one: the references are found as the slots
nearest their runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import InputError, WaferScanError
from ..mapping import EMPTY, LIMIT_SLACK, PRESENT, STATE_NAMES, UNSCANNED
from ..model import FAST
from ..recipe import RECIPE_KEYS, resolved_values

NO_BOTTOM_WAFER = "no-bottom-wafer"
NO_TOP_WAFER = "no-top-wafer"
CHECK_FAILED = "check-failed"
# The command line's exit status for each failure (docs/tutorials/recipes-calibration.md); 2 stays
# bad input, 1 an internal fault.
EXIT_CODES = {NO_BOTTOM_WAFER: 3, NO_TOP_WAFER: 4, CHECK_FAILED: 5}

# A recipe as a controller holds it (DOMAIN-NOTES: recipes in µm): lengths at the encoder's
# resolution, 1 µm; the thickness correction, a ratio of two such lengths (about 0.7 mm), to
# 1e-6, below a nanometre on a wafer's reading. What the check scan judges by, what --out and
# CAL write and a person reads; JSON keeps the measurement at full precision beside it.
LENGTH_DECIMALS = 3
CORRECTION_DECIMALS = 6

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
    first_slot_z: float     # mm, measured slot-1 seat, at 1 µm (the recipe's)
    pitch: float            # mm, measured, at 1 µm (the recipe's)
    thickness_correction: float  # measured, to CORRECTION_DECIMALS (the recipe's)
    references: tuple       # the bottom and top references' SensorRuns
    scan: object            # the calibration scan's ScanResult
    check: object           # the check scan's ScanResult
    # first_slot_z, slot_pitch and thickness_correction as measured, at full precision (the
    # recipe holds them at 1 µm and CORRECTION_DECIMALS): for JSON
    measured: dict = None

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

    def changes(self):
        """The rows whose value the calibration changes, as a person reads them
        (``shown_value``): empty when the layout already holds the calibrated recipe."""
        return [(key, old, new) for key, old, new in self.rows()
                if shown_value(key, old) != shown_value(key, new)]


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


def _nearest_taught_slot(taught, z):
    """The taught slot (a Carrier's or a SlotPlan's) whose seat is nearest z: 0 or n + 1 and
    beyond for a z outside the outer windows."""
    return int(math.floor((z - taught.first_slot_z) / taught.pitch + 0.5)) + 1


def _where(run):
    return f"{run.diff:.3f} mm at z = {run.bottom:.3f}"


def references_of(layout, runs):
    """The bottom and top reference runs among a calibration scan's ``runs`` (SensorRuns), or a
    CalibrationError naming what the scan saw instead. A reference is one wafer of nominal
    thickness: the lowest run must be the taught slot 1's (its bottom within slot 1's window),
    alone there, and its diff (after the recipe's correction) within the recipe's thickness
    window; the highest run likewise slot n's. Their seats are not judged against the taught
    ones (that is what a calibration corrects); the check scan judges them and every other
    loaded slot with the new recipe."""
    carrier = layout.scanned_carrier
    plan = _plan(layout)
    n = carrier.slot_count
    ordered = sorted(runs, key=lambda r: r.bottom)
    if not ordered:
        raise CalibrationError(NO_BOTTOM_WAFER, "no wafer in the bottom slot (slot 1): the "
                                                "calibration scan saw no wafer at all")
    low, high = ordered[0], ordered[-1]
    step = layout.scan.z_step
    _reference(plan, ordered, low, 1, "bottom", "lowest", NO_BOTTOM_WAFER, step)
    if n == 1:
        return low, low
    if high is low:
        slot = _nearest_taught_slot(carrier, high.bottom)
        raise CalibrationError(NO_TOP_WAFER, f"no wafer in the top slot (slot {n}): the highest "
                                             f"run, {_where(high)}, is nearest slot {slot}'s "
                                             f"seat")
    _reference(plan, ordered, high, n, "top", "highest", NO_TOP_WAFER, step)
    return low, high


def _reference(plan, ordered, run, slot, side, extreme, kind, step):
    """Raise CalibrationError(kind) unless ``run`` (the lowest or highest of ``ordered``) is one
    wafer of nominal thickness in the taught ``slot`` (InputError when a ``step`` coarser than
    the wafer read it as one position)."""
    n = plan.slot_count
    nearest = _nearest_taught_slot(plan, run.bottom)
    if nearest < 1 or nearest > n:
        window = plan.window(1 if nearest < 1 else n)
        where = "below slot 1's" if nearest < 1 else f"above slot {n}'s"
        raise CalibrationError(kind, f"no wafer in the {side} slot (slot {slot}) can be told: "
                                     f"the {extreme} run, {_where(run)}, lies {where} window "
                                     f"({window[0]:.3f} to {window[1]:.3f} mm), in no slot")
    if nearest != slot:
        raise CalibrationError(kind, f"no wafer in the {side} slot (slot {slot}): the {extreme} "
                                     f"run, {_where(run)}, is nearest slot {nearest}'s seat")
    inside = [r for r in ordered if _nearest_taught_slot(plan, r.bottom) == slot]
    if len(inside) > 1:
        raise CalibrationError(kind, f"no single wafer in the {side} slot (slot {slot}): "
                                     f"{len(inside)} runs in its window, "
                                     f"{', '.join(_where(r) for r in inside)}")
    if run.diff == 0.0 and step > 0.0:
        raise InputError("z_step", None, f"the {side} reference reads 0 mm thick: z_step "
                                         f"{step:g} is too coarse to measure it")
    eps = LIMIT_SLACK
    diff = plan.corrected(run.diff)
    shown = "" if diff == run.diff else f" ({diff:.3f} mm corrected)"
    low, high = plan.thickness_window()
    if diff > plan.double_limit() + eps:
        why = f"is longer than the double limit {plan.double_limit():g} mm"
    elif diff > high + eps:
        why = f"is longer than thickness_max {high:g} mm (double or thick)"
    elif diff < low - eps:
        why = f"is shorter than thickness_min {low:g} mm (thin)"
    else:
        return
    raise CalibrationError(kind, f"no single wafer in the {side} slot (slot {slot}): its run, "
                                 f"{_where(run)}{shown}, {why}")


def micrometres(value):
    """A length (mm) at the encoder's resolution, 1 µm: what a recipe holds."""
    return round(value, LENGTH_DECIMALS)


def _grid_micrometres(value, start, step):
    """A scan position of the grid start + k·step at 1 µm, where that is still the grid's
    position (a whole-µm start and step: always); else the position itself."""
    rounded = micrometres(value)
    if step <= 0.0:
        return rounded
    k = round((value - start) / step)
    return rounded if abs(rounded - (start + k * step)) <= 1e-9 * max(1.0, abs(value)) else value


def recalibrated(layout, low, high, grid_start=None):
    """The layout with the recipe the references give: the scanned carrier's taught slot-1 seat
    and pitch, the scan range and the thickness correction. ``grid_start``: the calibration
    scan's start_z; the new range starts on its step grid, so that the check scan and every
    later one latch the references where the calibration did. The recipe is kept as a
    controller holds it: lengths at the encoder's 1 µm, the correction to CORRECTION_DECIMALS
    (the check scan judges by exactly what is written). Returns (layout, seat, pitch,
    correction, measured): ``measured`` the seat, pitch and correction at full precision."""
    carrier = layout.scanned_carrier
    n = carrier.slot_count
    measured_seat = low.bottom
    measured_pitch = (high.bottom - low.bottom) / (n - 1) if n > 1 else carrier.pitch
    mean = 0.5 * (low.diff + high.diff)
    if not measured_pitch > carrier.wafer_thickness:
        raise CalibrationError(NO_TOP_WAFER, f"the references are {measured_pitch:g} mm a slot "
                                             f"apart, no more than a wafer's thickness: not "
                                             f"slots 1 and {n}")
    if not mean > 0.0:
        raise InputError("z_step", None, f"the references read {mean:g} mm thick: z_step "
                                         f"{layout.scan.z_step:g} is too coarse to measure them")
    measured_correction = mean / carrier.wafer_thickness
    seat = micrometres(measured_seat)
    pitch = micrometres(measured_pitch) if n > 1 else carrier.pitch
    correction = round(measured_correction, CORRECTION_DECIMALS)
    taught = replace(carrier, first_slot_z=seat, pitch=pitch)
    start = seat - pitch
    step = layout.scan.z_step
    origin = start if grid_start is None else grid_start
    if grid_start is not None and step > 0.0:
        start = grid_start + math.floor((start - grid_start) / step + 1e-9) * step
    end = _on_grid(start, seat + n * pitch, step)
    start, end = (_grid_micrometres(start, origin, step), _grid_micrometres(end, origin, step))
    after = replace(layout, carriers=tuple(taught if c.name == carrier.name else c
                                           for c in layout.carriers),
                    mapping=replace(layout.mapping, thickness_correction=correction))
    after = after.with_scan(start_z=start, final_z=end)
    measured = {"first_slot_z": measured_seat, "slot_pitch": measured_pitch,
                "thickness_correction": measured_correction}
    return after, seat, pitch, correction, measured


def check_problems(result):
    """What a check scan read wrong: every slot holding a run must read present (a loaded slot
    read thin, double, cross-slotted, off its seat or protruding is a recipe that does not fit,
    or a carrier that cannot check one), the bottom and top slots must hold their references,
    every run must lie in a slot, and no slot may be unscanned. A list of sentences (empty: the
    check passed)."""
    n = result.plan.slot_count
    slots = result.slot_map.slots
    wrong = [f"slot {s.slot} read {s.state} ({STATE_NAMES[s.state]})" for s in slots
             if s.state not in (PRESENT, UNSCANNED)
             and (s.state != EMPTY or s.slot in (1, n))]
    unscanned = [s.slot for s in slots if s.state == UNSCANNED]
    if unscanned:
        wrong.append(f"slots {', '.join(map(str, unscanned))} unscanned")
    held = {i for s in slots for i in s.runs}
    wrong += [f"the run {_where(run)} lies in no slot" for i, run in enumerate(result.runs)
              if i not in held]
    return wrong


def calibrate(layout, scan):
    """Calibrate the layout's recipe from its reference wafers. ``scan(layout)`` returns a
    ScanResult (core.scan.layout_scan.scan_layout, or a scan through a document). Returns a Calibration or
    raises CalibrationError."""
    first = scan(calibration_layout(layout))
    low, high = references_of(layout, first.runs)
    after, seat, pitch, correction, measured = recalibrated(layout, low, high,
                                                            first.layout.scan.start_z)
    check = scan(after)
    wrong = check_problems(check)
    if wrong:
        raise CalibrationError(CHECK_FAILED, f"check scan failed: {'; '.join(wrong)} "
                                             f"(code {check.code})", check)
    return Calibration(layout, after, seat, pitch, correction, (low, high), first, check,
                       measured)


def shown_value(key, value):
    """A recipe value as a person or an MCS reads it: lengths (mm) to the micrometre, the
    correction to CORRECTION_DECIMALS, words as they are (no float noise: t + Δt = 0.7 + 0.35 is
    1.0499999999999998 in binary)."""
    if not isinstance(value, float):
        return str(value)
    if key == "thickness_correction":
        return f"{value:.{CORRECTION_DECIMALS}f}"
    return f"{value:.{LENGTH_DECIMALS}f}"


def recipe_values(values):
    """``Calibration.values`` as a file lists them (CAL's results.txt header): floats rounded
    as ``shown_value`` shows them."""
    return {key: (round(value, CORRECTION_DECIMALS if key == "thickness_correction"
                        else LENGTH_DECIMALS) if isinstance(value, float) else value)
            for key, value in values.items()}


def format_calibration(calibration):
    """The recipe before and after, one key a line, and the check scan's code: what
    ``waferscan calibrate`` prints."""
    rows = calibration.rows()
    width = max(len(key) for key, _, _ in rows)
    lines = [f"{'key':<{width}}  {'current':>14}  {'calibrated':>14}"]
    for key, old, new in rows:
        lines.append(f"{key:<{width}}  {shown_value(key, old):>14}  {shown_value(key, new):>14}")
    check = calibration.check
    lines += ["", f"check scan code {check.code}", f"check scan E87  {check.e87}"]
    return "\n".join(lines)

