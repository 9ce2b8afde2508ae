"""What a scan result looks like to a person (a table like the paper's Table 1) and to a program
(one JSON object, SPEC §7)."""

from __future__ import annotations

import math

from ..mapping import STATE_NAMES, UNSCANNED
from ..scan.slow_scan import lift_acceleration
from .mcs import reported_parameters

# The paper's Table 1: slot -> (wafer #, IN, OUT, diff) in mm; slots not listed were empty.
PAPER_TABLE_1 = {
    1: (1, 293.96, 294.62, 0.66), 2: (2, 303.97, 304.63, 0.66), 4: (3, 323.99, 324.65, 0.66),
    5: (4, 336.53, 341.92, 5.38), 7: (5, 353.96, 354.62, 0.66), 10: (6, 383.98, 384.64, 0.66),
    11: (7, 396.58, 401.96, 5.38), 16: (8, 443.98, 444.64, 0.66), 18: (9, 463.99, 464.65, 0.66),
    24: (10, 523.99, 524.65, 0.66),
}
PAPER_CODE = "1101221001220001010000010"

# Colours of the slot states (code -> RGB) wherever results are drawn: the GUI's table, strip
# and side view.
STATE_COLOURS = {0: (235, 235, 235), 1: (120, 200, 120), 2: (230, 90, 80), 3: (240, 170, 60),
                 4: (120, 170, 230), 5: (200, 120, 220), 6: (250, 220, 70),
                 UNSCANNED: (160, 160, 160)}


def result_dict(result):
    """The JSON object of ``--json``: code, e87, slots, runs, wafers, params, engine, warnings.
    A slot's ``state`` is its code character's value: 0-6, or "?" when unscanned. SPEC §13:
    a slot's ``front`` (mm) and ``sweep`` ([first, last] deg), null without a jab or sweep,
    and ``sweep_strike`` ([[from, to], …] deg where a tine was inside a wafer, or null);
    ``durations``: simulated seconds of a fast and a slow scan."""
    data = _result_dict(result)
    pockets = {p.slot: p for p in result.pockets}
    for slot in data["slots"]:
        probe = pockets.get(slot["slot"])
        slot["front"] = None if probe is None else probe.front
        slot["sweep"] = None if probe is None or probe.sweep is None else list(probe.sweep)
        # The wrist angles the sweep turned to: short of ±sweep where the fork would have come
        # within clearance_min (SPEC §13 amended).
        slot["sweep_reached"] = (None if probe is None or probe.reached is None
                                 else list(probe.reached))
        # The wrist-angle ranges over which a tine was inside a wafer (a real fork strikes it).
        slot["sweep_strike"] = ([list(span) for span in probe.strike]
                                if probe is not None and probe.strike else None)
    data["durations"] = result.durations
    if result.clearance is not None:  # SPEC §15
        data["clearance"] = result.clearance.as_dict()
    return data


def format_pockets(result):
    """A slow scan's jab and sweep per pocket as a text table (SPEC §13)."""
    lines = [f"{'slot':>4}  {'jab Z':>8}  {'front':>7}  {'seated':>7}  {'sweep first':>11}  "
             f"{'last':>8}  {'shift':>7}  {'turned':>17}",
             "(mm from the start pose; degrees, counter-clockwise seen from above; shift: mm "
             "to the right; turned: the wrist angles the sweep reached)"]
    for p in result.pockets:
        sweep = p.sweep or (None, None)
        cells = [_mm(p.front) or "-", _mm(p.expected_front) or "-",
                 *(f"{a:+.3f}" if a is not None else "-" for a in sweep),
                 "-" if p.shift is None else f"{p.shift:+.3f}"]
        turned = "-" if p.reached is None else f"{p.reached[0]:+.3f} .. {p.reached[1]:+.3f}"
        lines.append(f"{p.slot:>4}  {p.z:8.3f}  {cells[0]:>7}  {cells[1]:>7}  {cells[2]:>11}  "
                     f"{cells[3]:>8}  {cells[4]:>7}  {turned:>17}")
    return "\n".join(lines)


def duration_note(result):
    """Why the durations may mislead, or None: with the lift's acceleration not set (SPEC §10's
    default, infinite) the slow scan's stops from rest to rest take no time, so a slow scan can
    come out shorter than a fast one (which strokes on to final_z)."""
    if math.isinf(lift_acceleration(result.layout.scan)):
        return "lift acceleration not set ([scan] acceleration): the slow scan's stops take no time"
    return None


def format_durations(result):
    """One line: the simulated duration of a fast and of a slow scan (SPEC §13), and why they
    may mislead (``duration_note``)."""
    d = result.durations
    note = duration_note(result)
    return (f"simulated duration: fast {d['fast']:.2f} s, slow {d['slow']:.2f} s "
            f"(this scan: {result.layout.scan.mode}{'; ' + note if note else ''})")


def _result_dict(result):
    from ..scan.sensing import scan_edges, slot_readings

    readings = slot_readings(result)
    return {
        "code": result.code,
        "e87": result.e87,
        "engine": result.engine,
        "slots": [{"slot": s.slot, "z": s.seat_z, "state": s.state,
                   "state_name": STATE_NAMES[s.state], "runs": list(s.runs),
                   "thickness": thickness, "bottom": bottom}
                  for s, (thickness, bottom) in zip(result.slot_map.slots, readings)],
        "runs": [{"in": r.z_in, "out": r.z_out, "diff": r.diff, "wafers": list(r.wafers)}
                 for r in result.runs],
        "wafers": [{"name": w.name, "in": w.z_in, "out": w.z_out, "diff": w.diff}
                   for w in result.wafers],
        "protrusions": [{"name": name, "mm": amount} for name, amount in result.protrusions],
        "params": reported_parameters(result),  # as asked; ``<key>_used`` where it differs
        "warnings": list(result.warnings),
        "edges": scan_edges(result),  # SPEC §10: every ON/OFF edge in the order latched
    }


def paper_test_beside_exact(paper, exact):
    """Where the paper's own mid-plane test (``paper``, a ScanResult of the paper engine) and
    the exact test (``exact``) differ, wafer by wafer, and why: a list of text lines."""
    lines = ["The paper's own test (paper engine) beside the exact test (analytic engine), per "
             "wafer; IN/OUT in mm:",
             f"{'wafer':<10} {'exact IN':>9} {'exact OUT':>9} {'paper IN':>9} {'paper OUT':>9}"
             f"  why they differ"]
    e = exact.layout.beam.direction
    for mine, theirs, wafer in zip(exact.wafers, paper.wafers, exact.layout.wafers):
        if mine.z_in is None and theirs.z_in is None:
            continue
        same = (mine.z_in is not None and theirs.z_in is not None
                and abs(mine.z_in - theirs.z_in) < 1e-9 and abs(mine.z_out - theirs.z_out) < 1e-9)
        tilt = abs(sum(a * b for a, b in zip(e, wafer.normal)))
        if same:
            why = "same"
        elif tilt > 1e-12:
            why = (f"tilted wafer: the paper's test meets its mid-plane only and ignores its "
                   f"{wafer.thickness:g} mm thickness")
        else:
            why = "level wafer: the paper's test tells the disc by its centre distance alone"
        cells = [f"{v:9.3f}" if v is not None else f"{'-':>9}"
                 for v in (mine.z_in, mine.z_out, theirs.z_in, theirs.z_out)]
        lines.append(f"{mine.name:<10} {' '.join(cells)}  {why}")
    return lines


def _mm(x, digits=3):
    return "" if x is None else f"{x:.{digits}f}"


def format_table(result, paper=False):
    """The results as a text table, one line per slot (and per extra run in a slot). With
    ``paper`` the paper's own IN, OUT and diff stand beside ours."""
    head = ["slot", "slot Z", "wafer", "IN", "OUT", "diff", "state"]
    if paper:
        head += ["paper #", "paper IN", "paper OUT", "paper diff"]
    rows = []
    for slot, seat, wafers, z_in, z_out, diff, state in result.table_rows():
        row = [str(slot), _mm(seat, 2), ",".join(wafers) or "-", _mm(z_in), _mm(z_out), _mm(diff),
               state]
        if paper:
            ref = PAPER_TABLE_1.get(slot)
            row += ["", "", "", ""] if ref is None else [str(ref[0])] + [f"{v:.2f}" for v in ref[1:]]
        rows.append(row)
    widths = [max(len(r[i]) for r in rows + [head]) for i in range(len(head))]
    right = {0, 1, 3, 4, 5, 8, 9, 10}

    def line(cells):
        return "  ".join(c.rjust(w) if i in right else c.ljust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    out = [line(head), line(["-" * w for w in widths])]
    out += [line(r) for r in rows]
    return "\n".join(out)


def crosscheck_dict(check):
    """The JSON object of ``crosscheck --json``."""
    return {
        "ok": check.ok,
        "largest_deviation": check.largest_deviation,
        "allowed_deviation": check.largest_allowed,
        "code": check.result.code,
        "runs": [{"in": r.z_in, "out": r.z_out, "blocked_at_edges": r.blocked_at_edges,
                  "clear_outside": r.clear_outside} for r in check.runs],
        "wafers": [{"name": w.wafer, "edges": list(w.edges), "brep": list(w.brep),
                    "deviation": w.deviation, "allowed": w.allowed,
                    "touch_shift": list(w.touch_shift)} for w in check.wafers],
    }


def format_crosscheck(check):
    """The cross-check as text: each run confirmed or not, each wafer's edges both ways."""
    lines = ["run  IN        OUT       B-rep: blocked at IN/OUT  clear one step outside"]
    for i, r in enumerate(check.runs, start=1):
        lines.append(f"{i:3d}  {r.z_in:8.3f}  {r.z_out:8.3f}  {'yes' if r.blocked_at_edges else 'NO':>24}"
                     f"  {'yes' if r.clear_outside else 'NO':>22}")
    lines += ["", "wafer      closed-form edges (mm)          B-rep bisection (mm)            "
                  "deviation  allowed"]
    for w in check.wafers:
        lines.append(f"{w.wafer:<10} {w.edges[0]:14.9f} {w.edges[1]:14.9f}  "
                     f"{w.brep[0]:14.9f} {w.brep[1]:14.9f}  {w.deviation:.2e}   {w.allowed:.2e}"
                     f"{'' if w.ok else '  NOT confirmed'}")
    lines += ["", f"largest deviation {check.largest_deviation:.3e} mm (allowed "
                  f"{check.largest_allowed:.3e} mm: OpenCASCADE's 1e-7 mm touching tolerance, "
                  f"magnified where the beam grazes a rim); "
                  f"{'confirmed' if check.ok else 'NOT confirmed'} by FreeCAD's B-rep geometry"]
    return "\n".join(lines)


def calibration_dict(calibration):
    """``waferscan calibrate --json`` (SPEC §11): the recipe keys, each with its current and its
    calibrated value (the recipe as written: lengths at 1 µm), the measured ones (first_slot_z,
    slot_pitch, thickness_correction) also as ``measured`` at full precision, and the check scan
    as ``scan --json`` gives a scan."""
    measured = calibration.measured or {}
    return {"status": "ok",
            "recipe": {key: {"current": old, "calibrated": new,
                             **({"measured": measured[key]} if key in measured else {})}
                       for key, old, new in calibration.rows()},
            "check": result_dict(calibration.check)}


def calibration_failure_dict(error):
    """``waferscan calibrate --json`` when the calibration fails: its kind, its words and the
    check scan's code when there was one."""
    return {"status": "error", "failure": error.kind, "message": error.words,
            "code": error.check.code if error.check is not None else None}
