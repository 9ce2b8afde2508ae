"""The link to the robot's motion control software (MCS): three text files in one folder.

- ``parameters.txt``: ``key = value`` lines the user sets; a key left out keeps the layout's value.
- ``commands.txt``: ``<seq> <COMMAND> [ARGS]`` lines the MCS appends.
- ``results.txt``: written by the simulator, atomically, for the MCS to read.

All three are UTF-8 (a BOM is tolerated), with LF or CRLF line ends; ``#`` starts a comment.
"""

from __future__ import annotations

import datetime as _dt
import re
from dataclasses import dataclass, replace

from .. import recipe, schema
from ..errors import InputError
from ..rules import SEVERAL_CARRIERS, UNKNOWN_CARRIER, carrier_choice_problem, thickness_fits_pitch
from ..scan import slow_scan
from ..sensor import settings as sensor_settings
from . import validation
from .text_files import read_text

PARAMETERS, COMMANDS, RESULTS = "parameters.txt", "commands.txt", "results.txt"

COMMAND_NAMES = {"SCF": "fast scan", "SCS": "slow scan", "STOP": "stop the running scan",
                 "CAL": "calibrate from reference wafers (SPEC §11)",
                 "LOAD": "place a carrier on a load port of the host link (SPEC §14)"}

# Keys of parameters.txt besides the scan and mapping keys: the scanned carrier and its nominal
# slots as the MCS knows them (they change what the mapping judges against, not the geometry).
CARRIER_KEYS = {
    "carrier": schema.name,
    "slot_count": schema.count,
    "slot_pitch": schema.positive,
    "first_slot_z": schema.number,
    "wafer_thickness": schema.positive,
    "wafer_diameter": schema.positive,
}
PARAMETER_KEYS = {**schema.SCAN_KEYS, **CARRIER_KEYS, **schema.MAPPING_KEYS,
                  **sensor_settings.SETTING_KEYS}  # the last: SPEC §10's sensor and latch
PARAMETER_KEYS.update(slow_scan.SETTING_KEYS)  # SPEC §13: jab, sweep and the arm's motion
_CARRIER_FIELDS = {"slot_count": "slot_count", "slot_pitch": "pitch",
                   "first_slot_z": "first_slot_z", "wafer_thickness": "wafer_thickness",
                   "wafer_diameter": "wafer_diameter"}


def _content_lines(text):
    """(line number, text without comment, stripped) for each non-blank line."""
    # Only LF ends a line (SPEC §5: LF or CRLF); str.splitlines would also break at CR alone,
    # form feeds and Unicode separators, and miscount the lines.
    for number, line in enumerate(text.split("\n"), start=1):
        content = line.split("#", 1)[0].strip()
        if content:
            yield number, content


@dataclass(frozen=True)
class Parameters:
    """The values of a parameters.txt, with the line each came from."""

    values: dict
    lines: dict
    source: str

    def error(self, key, message):
        return InputError(self.source, self.lines.get(key), f"{key}: {message}")


MAX_VALUE = 256  # characters of one parameters.txt value; a longer one is not read
_KEY_LIKE = re.compile(r"[a-z][a-z0-9_]{0,39}")


def parse_parameters(text, source=PARAMETERS):
    """Parse parameters.txt text; unknown keys, repeated keys and bad values are errors. An
    error quotes no more of the file than a recognised key and a bounded value: a line that is
    not ``key = value`` is not quoted at all, an unknown key only when it looks like a key (a
    file that was never a parameters file, such as a hard link to a private one, is not
    repeated into results.txt)."""
    values, lines = {}, {}
    for number, content in _content_lines(text.lstrip("\ufeff")):
        key, sep, value = content.partition("=")
        key = key.strip().lower()
        if not sep or not key:
            first = content.split(None, 1)[0].lower()
            if first in PARAMETER_KEYS:  # "start_z 280": the key is recognised, and named
                raise InputError(source, number, f"expected 'key = value', got {first} "
                                                 "without '='")
            raise InputError(source, number, f"expected 'key = value' (a line of "
                                             f"{len(content):,} characters)")
        if key not in PARAMETER_KEYS:
            shown = repr(key) if _KEY_LIKE.fullmatch(key) else f"({len(key):,} characters)"
            raise InputError(source, number, f"unknown key {shown} (known: "
                             f"{', '.join(sorted(PARAMETER_KEYS))})")
        if key in values:
            raise InputError(source, number, f"{key}: given twice (first on line {lines[key]})")
        if not value.strip():
            raise InputError(source, number, f"{key}: no value")
        if len(value.strip()) > MAX_VALUE:
            raise InputError(source, number, f"{key}: a value of {len(value.strip()):,} "
                                             f"characters: not read (at most {MAX_VALUE})")
        try:
            values[key] = PARAMETER_KEYS[key](value)
        except ValueError as exc:
            raise InputError(source, number, f"{key}: {exc}") from None
        lines[key] = number
    return Parameters(values, lines, str(source))


def read_parameters(path):
    return parse_parameters(read_text(path), str(path))


def apply_parameters(layout, parameters):
    """The layout with the parameters' values in place of its own; checks that the result makes
    a scan (the error names the parameter's line)."""
    v = parameters.values
    scan = replace(layout.scan, **{k: v[k] for k in schema.SCAN_KEYS if k in v})
    for key in slow_scan.SETTING_KEYS:  # SPEC §13
        if key in v:
            problem = slow_scan.setting_problem(key, v[key])
            if problem:
                raise parameters.error(key, problem)
            scan = replace(scan, **{key: v[key]})
    mapping = replace(layout.mapping, **{k: v[k] for k in schema.MAPPING_KEYS if k in v})
    chosen = v.get("carrier", layout.carrier)
    names = [c.name for c in layout.carriers]
    problem = carrier_choice_problem(names, chosen)
    if problem == UNKNOWN_CARRIER:
        raise parameters.error("carrier", f"no carrier named {chosen!r} in the layout "
                               f"(carriers: {', '.join(names)})")
    if problem == SEVERAL_CARRIERS:
        raise InputError(parameters.source, None,
                         f"the layout has several carriers ({', '.join(names)}): "
                         "say which with carrier = NAME")
    layout = replace(layout, scan=scan, mapping=mapping, carrier=chosen)
    carrier = before = layout.scanned_carrier
    nominal = {field: v[key] for key, field in _CARRIER_FIELDS.items() if key in v}
    if nominal:
        carrier = replace(carrier, **nominal)
        layout = replace(layout, carriers=tuple(carrier if c.name == chosen else c
                                                for c in layout.carriers))
    if not thickness_fits_pitch(carrier.wafer_thickness, carrier.pitch):
        # Blame the line that broke it: a new pitch under the layout's own thickness.
        pitch_broke_it = ("slot_pitch" in v and carrier.pitch != before.pitch
                          and carrier.wafer_thickness == before.wafer_thickness)
        key = "wafer_thickness" if "wafer_thickness" in v and not pitch_broke_it \
            else "slot_pitch"
        raise parameters.error(key, f"wafer thickness {carrier.wafer_thickness:g} must be "
                                    f"less than the pitch {carrier.pitch:g}")
    try:
        schema.check_scan_range(scan.start_z, scan.final_z, scan.z_step)
    except schema.ScanRangeError as exc:
        # The key to blame if this file set it, else the other keys of the range it did set.
        order = ("z_step", "final_z", "start_z") if exc.key == "z_step" \
            else ("final_z", "start_z", "z_step")
        key = next((k for k in order if k in v), None)
        if key is None:
            raise InputError(parameters.source, None, str(exc)) from None
        raise parameters.error(key, str(exc)) from None
    settings = {k: v[k] for k in sensor_settings.SETTING_KEYS if k in v}
    if settings:
        try:
            layout = sensor_settings.with_settings(layout, settings)
        except sensor_settings.SettingsError as exc:
            if exc.key in v:
                raise parameters.error(exc.key, str(exc)) from None
            raise InputError(parameters.source, None, str(exc)) from None
    _check_layout(layout, parameters)
    return layout


# parameters.txt's names for the scenario format's carrier keys (validation.Problem.key).
_PARAMETER_NAMES = {"slots": "slot_count", "pitch": "slot_pitch"}


def _check_layout(layout, parameters):
    """The values together (validation.layout_problems): the first problem, blamed on the line
    of this file that set the value when it did, else on the file."""
    # The supports are the carrier's geometry, which a nominal wafer_diameter does not move.
    problems = [p for p in validation.layout_problems(layout) if p.key != "support_span"]
    if problems:
        key = _PARAMETER_NAMES.get(problems[0].key, problems[0].key)
        if key == "sensor_response" and key not in parameters.values:
            key = "scan_speed"  # the lag is their product: blame the one this file set
        if key in parameters.values:
            raise parameters.error(key, problems[0].message)
        raise InputError(parameters.source, None, problems[0].message)


def used_parameters(layout):
    """Every parameters.txt key with the value the layout's scan uses, in the file's order."""
    scan, carrier, mapping = layout.scan, layout.scanned_carrier, layout.mapping
    values = {"carrier": carrier.name}
    values.update({key: getattr(scan, key) for key in schema.SCAN_KEYS})
    values.update({key: getattr(carrier, field) for key, field in _CARRIER_FIELDS.items()})
    values["thickness_tolerance"] = mapping.thickness_tolerance_for(carrier.wafer_thickness)
    values["position_tolerance"] = mapping.position_tolerance
    values["protrusion_limit"] = mapping.protrusion_limit
    # SPEC §11's recipe keys only where they differ from their defaults, as the settings below.
    values.update(recipe.given_values(mapping))
    # SPEC §10's settings only where they differ from the ideal sensor: a scan without them
    # lists what it always did.
    values.update(sensor_settings.given_values(layout))
    # SPEC §13's settings only where they differ from their defaults: a scan without them
    # lists what it always did.
    values.update(slow_scan.given_values(scan))
    return values


def reported_parameters(result):
    """The parameters a scan result lists (results.txt's header, JSON's ``params``): every key as
    asked, as parameters.txt has it, and right after a key the scan ran with another value of,
    ``<key>_used`` with that value (SPEC §10: latching in motion scans with z_step 0, its edges
    continuous, whatever z_step asked)."""
    used = used_parameters(result.layout)
    asked = result.asked_scan
    if asked is None:
        return used
    values = {}
    for key, value in used.items():
        if key in schema.SCAN_KEYS and getattr(asked, key) != value:
            values[key] = getattr(asked, key)
            values[f"{key}_used"] = value
        else:
            values[key] = value
    return values


def _text(value):
    return repr(float(value)) if isinstance(value, float) else str(value)


def format_parameters(layout):
    """parameters.txt text with every key set to the layout's value."""
    lines = ["# WaferScan scan parameters: key = value, lengths in mm, times in s, speeds in mm/s"]
    lines += [f"{key} = {_text(value)}" for key, value in used_parameters(layout).items()]
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class Command:
    """One line of commands.txt. ``problem`` says why it cannot be carried out, if so."""

    seq: int | None
    name: str
    args: tuple
    line: int
    problem: str | None = None


def parse_commands(text):
    """The complete lines of commands.txt, in order. A last line without its newline is still
    being written and is left out. A seq that is not an integer or not above the one before is
    reported in ``problem``, as is an unknown command."""
    text = text.lstrip("\ufeff")
    complete = text[:text.rfind("\n") + 1]
    commands = []
    last_seq = None
    for number, content in _content_lines(complete):
        words = content.split()
        name = words[1].upper() if len(words) > 1 else ""
        try:
            seq = int(words[0])
        except ValueError:
            commands.append(Command(None, name, tuple(words[2:]), number,
                                    f"seq must be a whole number, got {words[0]!r}"))
            continue
        problem = None
        if last_seq is not None and seq <= last_seq:
            problem = f"seq {seq} is not above the one before ({last_seq})"
        else:
            last_seq = seq
            if not name:
                problem = "no command after the seq"
            elif name not in COMMAND_NAMES:
                problem = f"unknown command {words[1]!r} (known: {', '.join(COMMAND_NAMES)})"
        commands.append(Command(seq, name, tuple(words[2:]), number, problem))
    return commands


RESULT_COLUMNS = ("slot", "slot_z", "wafer", "in", "out", "diff", "state")
# SPEC §10's raw data, as load ports report it: added when the scan uses a real sensor (a spot,
# thresholds or latching in motion), so that the paper's results.txt stays as it was.
READING_COLUMNS = ("thickness", "bottom")
# SPEC §13: added when a slow scan jabbed or swept its pockets (mm from the start pose; degrees).
POCKET_COLUMNS = ("front", "sweep_first", "sweep_last", "sweep_low", "sweep_high")


def _cell(text):
    """A table cell: a wafer's label may hold anything, but a tab or a line break in it would
    make a column or a row of its own (a label ``seq = 9`` would even read as a header line),
    so backslashes and control characters are written as escapes (``\\t``, ``\\n``, ``\\x1b``)."""
    if text.isprintable() and "\\" not in text:
        return text
    named = {"\\": "\\\\", "\t": "\\t", "\n": "\\n", "\r": "\\r"}
    return "".join(named.get(c) or (c if c.isprintable() else f"\\x{ord(c):02x}" if ord(c) < 256
                                    else f"\\u{ord(c):04x}") for c in text)


def _mm(x):
    return "" if x is None else f"{x:.3f}"


def format_results(seq, command, result=None, error=None, timestamp=None, message="",
                   recipe=None):
    """results.txt text: ``key = value`` header lines, a blank line, then the tab-separated table
    (slot, slot_z, wafer, in, out, diff, state) in millimetres to the micrometre. With ``error``
    the status is ``error``, the message is the error, and there is no table. ``recipe``: a
    calibration's keys and values (SPEC §11, CAL), listed after the parameters used where
    these do not list them already."""
    if timestamp is None:
        timestamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    clearance = None if result is None else result.clearance
    if result is not None and not error:
        error = refusal(result)  # SPEC §15: the robot must not run a scan with a contact
    header = [("seq", "" if seq is None else str(seq)), ("command", command),
              ("status", "error" if error else "ok"),
              ("message", " ".join(str(error or message).split())),
              ("code", result.code if result and not error else ""),
              ("e87", result.e87 if result and not error else ""),
              ("timestamp", timestamp)]
    if clearance is not None and (clearance.body == "robot" or clearance.contacts):
        # SPEC §15: with a robot always; with the scanner's heads standing in, at a contact.
        # clearance_min is listed here rather than among the parameters used, so that a scan
        # without a clearance check lists what it always did.
        header.append(("clearance_min", _text(clearance.clearance_min)))
        least = clearance.least
        header.append(("clearance", "" if least is None else f"{least.distance:.3f}"))
        header += [("collision", line) for line in clearance.collision_lines()]
    if result is not None and not error:
        # One line each: why part of the result cannot be known (SPEC §3).
        header += [("warning", " ".join(w.split())) for w in result.warnings]
    pockets = {p.slot: p for p in result.pockets} if result is not None and not error else {}
    if pockets:  # SPEC §13: the engineer's trade-off, simulated seconds of either mode
        durations = result.durations
        header += [("duration_fast", f"{durations['fast']:.3f}"),
                   ("duration_slow", f"{durations['slow']:.3f}")]
    if result is not None and not error:
        header.append(("engine", result.engine))
        used = reported_parameters(result)
        header += [(k, _text(v)) for k, v in used.items()]
        header += [(k, _text(v)) for k, v in (recipe or {}).items() if k not in used]
    lines = [f"{k} = {v}".rstrip() for k, v in header]
    if result is not None and not error:
        from ..scan.sensing import slot_readings

        readings = slot_readings(result) if sensor_settings.given_values(result.layout) \
            else None
        columns = RESULT_COLUMNS + (READING_COLUMNS if readings else ()) \
            + (POCKET_COLUMNS if pockets else ())
        lines += ["", "\t".join(columns)]
        for slot, seat, wafers, z_in, z_out, diff, state in result.table_rows():
            names = _cell(",".join(wafers)) or "-"
            cells = [str(slot), _mm(seat), names, _mm(z_in), _mm(z_out), _mm(diff), state]
            if readings:
                cells += [_mm(x) for x in readings[slot - 1]]
            if pockets:
                cells += _pocket_cells(pockets.get(slot))
            lines.append("\t".join(cells))
    return "\n".join(lines) + "\n"


def refusal(result):
    """Why the robot must not run the scan (SPEC §15: a motion closer than clearance_min to a
    wafer), as the MCS's answer says it; None when it may."""
    clearance = result.clearance
    if clearance is None or not clearance.contacts:
        return None
    count = len(clearance.contacts)
    return (f"clearance: {count} motion{'s' if count > 1 else ''} closer than clearance_min "
            f"{clearance.clearance_min:g} mm to a wafer (the least "
            f"{clearance.least.distance:.3f} mm): the robot must not run this scan")


def _pocket_cells(probe):
    """results.txt's front, sweep_first, sweep_last of a pocket and the wrist angles its sweep
    reached, sweep_low and sweep_high (SPEC §13; empty where none)."""
    if probe is None:
        return ("", "", "", "", "")
    sweep = probe.sweep or (None, None)
    reached = getattr(probe, "reached", None) or (None, None)
    return (_mm(probe.front), *("" if a is None else f"{a:.4f}" for a in (*sweep, *reached)))
