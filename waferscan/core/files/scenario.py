"""Scenario files (TOML, SPEC §6): a layout described without CAD, for batch runs and tests.

``read_scenario(path)`` returns a ``Layout``. Every mistake is an ``InputError`` that names the
file, the line and the key. Physical construction of the ``load`` states:

- present: a wafer on its slot's seat; double: two wafers stacked on the seat;
- thin: a wafer of THIN_FACTOR times the nominal thickness;
- misplaced (code 5): a wafer MISPLACED_RISE mm above its seat;
- protruding: a wafer pushed PROTRUDING_SHIFT mm out of the carrier's opening;
- cross ("22"): a wafer resting on the left support of one slot and the right support of the
  slot above. Its bottom face runs through the two supports' inner edges, ``support_span``
  apart, so it is tilted about the front axis by atan(pitch / support_span).
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import replace
from pathlib import Path

from .. import schema
from ..errors import InputError
from ..model import Beam, Carrier, Layout, MappingTolerances, RobotSpec, ScanParameters, Wafer, unit
from ..rules import SEVERAL_CARRIERS, carrier_choice_problem, thickness_fits_pitch
from ..scan import slow_scan
from ..sensor import settings as sensor_settings
from . import validation
from .text_files import read_text

THIN_FACTOR = 0.25
MISPLACED_RISE = 2.0
PROTRUDING_SHIFT = 5.0
# By default the slot supports reach this far (mm) under the wafer's rim on each side.
SUPPORT_OVERLAP = 3.75

LOAD_DIGITS = {"0": "absent", "1": "present", "3": "double", "4": "thin", "5": "misplaced",
               "6": "protruding"}
WAFER_STATES = ("present", "cross", "double", "thin", "misplaced", "protruding", "absent")

_TABLES = {"scan", "sensor", "robot", "mapping", "carrier", "wafer"}
_ARRAY_TABLES = {"carrier", "wafer"}
_BARE_KEY = re.compile(r"[A-Za-z0-9_\-]+")


def _key_path(line, i):
    """The dotted key starting at ``line[i]`` as a tuple of its parts (quotes taken off) and the
    index after it, or None where there is no key."""
    parts = []
    while True:
        while i < len(line) and line[i] in " \t":
            i += 1
        if i < len(line) and line[i] in "\"'":
            quote, i, part = line[i], i + 1, []
            while i < len(line) and line[i] != quote:
                if quote == '"' and line[i] == "\\" and i + 1 < len(line):
                    i += 1
                part.append(line[i])
                i += 1
            if i == len(line):
                return None
            parts.append("".join(part))
            i += 1
        else:
            bare = _BARE_KEY.match(line, i)
            if not bare:
                return None
            parts.append(bare.group())
            i = bare.end()
        while i < len(line) and line[i] in " \t":
            i += 1
        if i < len(line) and line[i] == ".":
            i += 1
            continue
        return tuple(parts), i


class _Lines:
    """Where each table and key of a TOML file starts, for error messages. tomllib gives values
    without positions, so this reads the raw text as TOML does: only LF (or CRLF) ends a line,
    strings (multi-line ones too), comments and brackets are skipped, headers may be quoted."""

    def __init__(self, text):
        self.keys = {}
        self.tables = {}
        counters = {}
        table, index = None, None
        pending, depth = None, 0  # an open multi-line string's quotes; open brackets
        for number, line in enumerate(text.split("\n"), start=1):
            line = line[:-1] if line.endswith("\r") else line
            i = 0
            if pending is None and depth == 0:
                stripped = len(line) - len(line.lstrip(" \t"))
                if line.startswith("[", stripped):
                    double = line.startswith("[[", stripped)
                    found = _key_path(line, stripped + (2 if double else 1))
                    if found:
                        name = ".".join(found[0])
                        if double:
                            index = counters.get(name, 0)
                            counters[name] = index + 1
                        else:
                            index = None
                        table = name
                        self.tables.setdefault((table, index), number)
                    continue
                found = _key_path(line, stripped)
                if found and line.startswith("=", found[1]):
                    parts = found[0]
                    self.keys.setdefault((table, index, parts[0]), number)
                    if len(parts) > 1 and table is None:  # scan.z_step = ... makes [scan]
                        self.keys.setdefault((".".join(parts[:-1]), None, parts[-1]), number)
                    i = found[1] + 1
            pending, depth = self._skip_value(line, i, pending, depth)

    @staticmethod
    def _skip_value(line, i, pending, depth):
        """Read a value's text to the end of the line; the state it leaves open."""
        while i < len(line):
            if pending:
                if pending == '"""' and line[i] == "\\":
                    i += 2
                elif line.startswith(pending, i):
                    i += 3
                    while i < len(line) and line[i] == pending[0]:
                        i += 1  # up to two quotes may end the string's content
                    pending = None
                else:
                    i += 1
                continue
            c = line[i]
            if c == "#":
                break
            if c in "\"'":
                if line.startswith(c * 3, i):
                    pending, i = c * 3, i + 3
                    continue
                i += 1
                while i < len(line) and line[i] != c:
                    i += 2 if c == '"' and line[i] == "\\" else 1
            elif c in "[{":
                depth += 1
            elif c in "]}":
                depth = max(depth - 1, 0)
            i += 1
        return pending, depth

    def of(self, table, index=None, key=None):
        if key is not None and (table, index, key) in self.keys:
            return self.keys[(table, index, key)]
        return self.tables.get((table, index))


class _Reader:
    def __init__(self, source, text, folder=None):
        self.source = source
        self.lines = _Lines(text)
        self.folder = folder  # where relative paths in the file start from

    def error(self, message, table=None, index=None, key=None):
        where = f"[{table}] " if table and index is None else (
            f"[[{table}]] #{index + 1} " if table else "")
        what = f"{key}: " if key else ""
        return InputError(self.source, self.lines.of(table, index, key), f"{where}{what}{message}")

    def table(self, data, table, allowed, index=None):
        """Check that a table has only allowed keys; return it."""
        for key in data:
            if key not in allowed:
                raise self.error(f"unknown key (known: {', '.join(sorted(allowed))})",
                                 table, index, key)
        return data

    def value(self, data, table, key, check, index=None, default=None, required=False):
        if key not in data:
            if required:
                raise self.error(f"missing key {key!r}", table, index)
            return default
        try:
            return check(data[key])
        except ValueError as exc:
            raise self.error(str(exc), table, index, key) from None


def key_line(text, table, key):
    """The line (1-based) of ``key`` in the [table] of scenario text, else the table's line, else
    None: for errors found after reading (a [robot] that contradicts [sensor])."""
    return _Lines(text.lstrip("\ufeff")).of(table, None, key)


def read_scenario(path, default_mapping=None, default_sensor=None):
    """Read a scenario file into a ``Layout``; ``default_mapping`` and ``default_sensor`` as in
    ``parse_scenario``."""
    path = Path(path)
    text = read_text(path, "the scenario")
    return parse_scenario(text, str(path), folder=path.resolve().parent,
                          default_mapping=default_mapping, default_sensor=default_sensor)


def parse_scenario(text, source="<scenario>", folder=None, default_mapping=None,
                   default_sensor=None):
    """Parse scenario text into a ``Layout``; ``source`` names it in error messages, ``folder``
    is where relative paths start (the current folder when None). ``default_mapping``: the
    ``MappingTolerances`` a scenario without a [mapping] table gets (None: the core's).
    ``default_sensor``: SPEC §10 values (and sensor_response) for what the scenario does not
    set, by ``sensor_settings.DEFAULT_GROUPS`` (None: the ideal sensor's)."""
    data = parse_toml(text, source)
    reader = _Reader(source, text, Path(folder) if folder is not None else Path.cwd())
    _check_tables(reader, data)

    carriers = [_carrier(reader, c, i) for i, c in enumerate(data.get("carrier", []))]
    if not carriers:
        raise InputError(source, None, "no [[carrier]] table: a scenario needs a carrier")
    names = [c.name for c in carriers]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise reader.error(f"a second carrier named {name!r}", "carrier", i, "name")

    beam, scan = _beam_and_scan(reader, data)
    mapping_data = reader.table(data.get("mapping", {}), "mapping", schema.MAPPING_KEYS)
    mapping = MappingTolerances(**{k: reader.value(mapping_data, "mapping", k, check,
                                                   default=getattr(MappingTolerances(), k))
                                   for k, check in schema.MAPPING_KEYS.items()})
    chosen = _scanned_carrier(reader, data, names)
    lift_axis = _lift_axis(reader, data)

    wafers = _wafers(reader, data, carriers)
    robot = _robot(reader, data["robot"]) if "robot" in data else None
    layout = Layout(carriers=tuple(carriers), wafers=tuple(wafers), beam=beam, scan=scan,
                    lift_axis=lift_axis, mapping=mapping, carrier=chosen, robot=robot)
    layout = _sensor_settings(reader, layout, data.get("sensor", {}), data.get("scan", {}),
                              default_sensor)
    _check_layout(reader, layout, len(data.get("wafer", [])))
    if default_mapping is not None and "mapping" not in data:
        layout = replace(layout, mapping=default_mapping)
    return layout


def parse_toml(text, source):
    """The TOML text as data; an InputError with the line tomllib names otherwise."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"\(at line (\d+), column \d+\)", str(exc))
        line = int(match.group(1)) if match else None
        message = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(exc))
        raise InputError(source, line, f"not valid TOML: {message}") from None


def _check_tables(reader, data):
    """Only the known tables, each written as a table ([scan]) or an array of them
    ([[carrier]]) as it must be."""
    for key, value in data.items():
        if key not in _TABLES:
            raise reader.error(f"unknown table or key {key!r} (known tables: "
                               f"{', '.join(sorted(_TABLES))})", key if isinstance(value, (dict, list)) else None,
                               key=None if isinstance(value, (dict, list)) else key)
        if key in _ARRAY_TABLES and not (isinstance(value, list)
                                         and all(isinstance(v, dict) for v in value)):
            raise reader.error(f"write it as [[{key}]] tables", key)
        if key not in _ARRAY_TABLES and not isinstance(value, dict):
            raise reader.error(f"write it as a [{key}] table", key=key)


def _scanned_carrier(reader, data, names):
    """The name of the carrier to scan: [scan] carrier, or the only carrier (rules'
    carrier_choice_problem)."""
    chosen = reader.value(data.get("scan", {}), "scan", "carrier", schema.carrier_name)
    problem = carrier_choice_problem(names, chosen)
    if problem == SEVERAL_CARRIERS:
        raise reader.error(f"several carriers ({', '.join(names)}): say which one to scan "
                           "with carrier = \"NAME\"", "scan")
    if problem:
        raise reader.error(f"no carrier named {chosen!r} (carriers: {', '.join(names)})",
                           "scan", key="carrier")
    return chosen or names[0]


def _lift_axis(reader, data):
    """[sensor] lift_axis as a unit vector (vertical when not given); it must climb."""
    sensor = data.get("sensor", {})
    if "lift_axis" not in sensor:
        return (0.0, 0.0, 1.0)
    lift_axis = unit(reader.value(sensor, "sensor", "lift_axis", schema.vector(3, nonzero=True)))
    if lift_axis[2] < validation.MIN_LIFT_Z:
        raise reader.error("the lift axis must point upwards (z component > 0.1 after "
                           "normalising)", "sensor", key="lift_axis")
    return lift_axis


def _check_layout(reader, layout, free_count):
    """The values together (validation.layout_problems), the first problem named by its table
    and key. Wafers from load strings come first in the layout, then the [[wafer]] tables."""
    problems = validation.layout_problems(layout)
    if not problems:
        return
    key, message, index, group = problems[0]
    if group == "wafer":
        free = None if index is None else index - (len(layout.wafers) - free_count)
        if free is not None and free >= 0:
            raise reader.error(message, "wafer", free, key)
    elif group is not None:
        raise reader.error(message, group, index if group == "carrier" else None, key)
    raise InputError(reader.source, None, message)


_ROBOT_KEYS = {"urdf", "base", "base_yaw"}


def _robot(reader, data):
    """The [robot] table: ``urdf`` (relative to the scenario's folder; default the bundled
    robot), ``base`` [x, y, z] in mm and ``base_yaw`` in degrees."""
    reader.table(data, "robot", _ROBOT_KEYS)
    urdf = reader.value(data, "robot", "urdf", schema.name)
    if urdf is not None:
        path = Path(urdf)
        if not path.is_absolute() and reader.folder is not None:
            path = reader.folder / path
        if not path.is_file():
            raise reader.error(f"no such file: {path}", "robot", key="urdf")
        urdf = str(path)
    return RobotSpec(urdf=urdf,
                     base=reader.value(data, "robot", "base", schema.vector(3),
                                       default=(0.0, 0.0, 0.0)),
                     base_yaw=reader.value(data, "robot", "base_yaw", schema.number, default=0.0))


_CARRIER_KEYS = {"name", "slots", "pitch", "first_slot_z", "center", "wafer_diameter",
                 "wafer_thickness", "load", "front", "support_span", "wafer_bow"}


def _carrier(reader, data, i):
    reader.table(data, "carrier", _CARRIER_KEYS, i)

    def get(key, check, **kw):
        return reader.value(data, "carrier", key, check, index=i, **kw)

    name = get("name", schema.carrier_name, default=f"C{i + 1}")
    slots = get("slots", schema.count, default=25)
    pitch = get("pitch", schema.positive, default=10.0)
    diameter = get("wafer_diameter", schema.positive, default=300.0)
    thickness = get("wafer_thickness", schema.positive, default=0.775)
    if not thickness_fits_pitch(thickness, pitch):
        raise reader.error(f"wafer_thickness {thickness:g} must be less than the pitch "
                           f"{pitch:g}", "carrier", i, "wafer_thickness")
    front = get("front", schema.vector(2, nonzero=True), default=(0.0, -1.0))
    norm = math.hypot(*front)
    support_span = get("support_span", schema.positive, default=diameter - 2 * SUPPORT_OVERLAP)
    if support_span > diameter:
        raise reader.error(f"support_span {support_span:g} is wider than the wafer "
                           f"({diameter:g}): the wafer would fall through", "carrier", i,
                           "support_span")
    return Carrier(
        name=name, slot_count=slots, pitch=pitch,
        first_slot_z=get("first_slot_z", schema.number, required=True),
        center=get("center", schema.vector(2), required=True),
        wafer_diameter=diameter, wafer_thickness=thickness,
        front=(front[0] / norm, front[1] / norm), support_span=support_span,
    )


_SENSOR_KEYS = {"emitter", "direction", "length", "lift_axis"} | set(sensor_settings.SPOT_KEYS)


def _sensor_settings(reader, layout, sensor, scan_table, defaults=None):
    """SPEC §10's [sensor] spot and threshold keys and [scan] latch keys, on the layout;
    ``defaults`` fill what neither table sets."""
    values = sensor_settings.defaults_not_given(defaults or {}, set(sensor) | set(scan_table))
    if "sensor_response" in values:
        layout = replace(layout, scan=replace(layout.scan,
                                              sensor_response=values.pop("sensor_response")))
    values.update({k: reader.value(sensor, "sensor", k, check)
                   for k, check in sensor_settings.SPOT_KEYS.items() if k in sensor})
    values.update({k: reader.value(scan_table, "scan", k, check)
                   for k, check in sensor_settings.MOTION_KEYS.items() if k in scan_table})
    if not values:
        return layout
    try:
        return sensor_settings.with_settings(layout, values)
    except sensor_settings.SettingsError as exc:
        table = "scan" if exc.key in sensor_settings.MOTION_KEYS else "sensor"
        raise reader.error(str(exc), table, key=exc.key) from None


def _beam_and_scan(reader, data):
    if "sensor" not in data:
        raise InputError(reader.source, None, "no [sensor] table: a scenario needs the beam at "
                                              "the scan's start (a [robot] is taught to put its "
                                              "beam there)")
    sensor = reader.table(data["sensor"], "sensor", _SENSOR_KEYS)
    scan_data = reader.table(data.get("scan", {}), "scan", set(schema.SCAN_KEYS) | {"carrier"}
                             | set(sensor_settings.MOTION_KEYS)
                             | set(slow_scan.SETTING_KEYS))  # the last: SPEC §13's jab, sweep

    emitter = sensor.get("emitter")
    if not isinstance(emitter, list) or len(emitter) not in (2, 3):
        raise reader.error("expected [x, y] or [x, y, z] in mm", "sensor", key="emitter") \
            if "emitter" in sensor else reader.error("missing key 'emitter'", "sensor")
    emitter = reader.value(sensor, "sensor", "emitter", schema.vector(len(emitter)))
    direction = reader.value(sensor, "sensor", "direction", schema.vector(3, nonzero=True),
                             required=True)
    length = reader.value(sensor, "sensor", "length", schema.positive, required=True)

    values = {k: reader.value(scan_data, "scan", k, check) for k, check in schema.SCAN_KEYS.items()}
    start_z = values["start_z"]
    if len(emitter) == 3:
        if start_z is None:
            start_z = emitter[2]
        elif abs(start_z - emitter[2]) > 1e-9:
            raise reader.error(f"start_z {start_z:g} differs from the emitter's z "
                               f"{emitter[2]:g}: give one, or both equal", "scan", key="start_z")
    elif start_z is None:
        raise reader.error("give the emitter's z, or start_z in [scan]", "sensor", key="emitter")
    if values["final_z"] is None:
        raise reader.error("missing key 'final_z'", "scan")
    values["start_z"] = start_z
    # SPEC §13: slow scanning's jab, sweep and arm motion (core/scan/slow_scan.py).
    for key, check in slow_scan.SETTING_KEYS.items():
        value = reader.value(scan_data, "scan", key, check)
        if value is not None:
            problem = slow_scan.setting_problem(key, value)
            if problem:
                raise reader.error(problem, "scan", key=key)
            values[key] = value
    scan = ScanParameters(**{k: v for k, v in values.items() if v is not None})
    try:
        schema.check_scan_range(scan.start_z, scan.final_z, scan.z_step)
    except schema.ScanRangeError as exc:
        raise reader.error(str(exc), "scan", key=exc.key) from None
    beam = Beam(emitter=(emitter[0], emitter[1], start_z), direction=unit(direction),
                length=length)
    return beam, scan


def _load_states(reader, carrier, text, i):
    """Per-slot wafer states from a load string: {slot: state}; "22" is one cross wafer."""
    if not isinstance(text, str) or len(text) != carrier.slot_count:
        raise reader.error(f"expected a string of {carrier.slot_count} digits (one per slot), "
                           f"got {text!r}", "carrier", i, "load")
    states = {}
    slot = 1
    while slot <= carrier.slot_count:
        digit = text[slot - 1]
        if digit == "2":
            if slot == carrier.slot_count or text[slot] != "2":
                raise reader.error(f"slot {slot}: a cross-slotted wafer spans two slots and is "
                                   f"written 22, got {text!r}", "carrier", i, "load")
            states[slot] = "cross"
            slot += 2
            continue
        if digit not in LOAD_DIGITS:
            raise reader.error(f"slot {slot}: {digit!r} is not a slot state (0-6)", "carrier",
                               i, "load")
        states[slot] = LOAD_DIGITS[digit]
        slot += 1
    return states


def seated_wafers(carrier, slot, state, first_index, bow=0.0):
    """The wafer solids a slot holds in a given state (see the module's docstring); ``bow``
    (mm, SPEC §10) bows them, their rims seated as a flat wafer's."""
    cx, cy = carrier.center
    seat = carrier.seat_z(slot)
    t, d = carrier.wafer_thickness, carrier.wafer_diameter
    up = (0.0, 0.0, 1.0)

    def wafer(k, center, normal=up, thickness=t):
        return Wafer(name=f"{carrier.name}_W{first_index + k:02d}", center=center, normal=normal,
                     diameter=d, thickness=thickness, carrier=carrier.name, slot=slot, bow=bow)

    if state == "absent":
        return []
    if state == "present":
        return [wafer(0, (cx, cy, seat))]
    if state == "double":
        return [wafer(0, (cx, cy, seat)), wafer(1, (cx, cy, seat + t))]
    if state == "thin":
        return [wafer(0, (cx, cy, seat), thickness=THIN_FACTOR * t)]
    if state == "misplaced":
        return [wafer(0, (cx, cy, seat + MISPLACED_RISE))]
    if state == "protruding":
        fx, fy = carrier.front
        return [wafer(0, (cx + PROTRUDING_SHIFT * fx, cy + PROTRUDING_SHIFT * fy, seat))]
    if state == "cross":
        slope = carrier.pitch / carrier.support_span
        s = slope / math.sqrt(1.0 + slope * slope)
        c = 1.0 / math.sqrt(1.0 + slope * slope)
        lx, ly = carrier.lateral
        return [wafer(0, (cx, cy, seat + 0.5 * carrier.pitch), (-s * lx, -s * ly, c))]
    raise ValueError(f"unknown wafer state {state!r}")


_WAFER_KEYS = {"carrier", "slot", "state", "name", "center", "normal", "diameter", "thickness",
               "bow"}


def _seat_wafer(reader, w, i, by_name, plans):
    """A [[wafer]] table given as carrier + slot + state: its state put in its carrier's plan
    ({slot: state}), in place of what the load string put in its slot(s). Returns (carrier
    name, slot)."""
    names = list(by_name)
    carrier_name = reader.value(w, "wafer", "carrier", schema.carrier_name, index=i)
    problem = carrier_choice_problem(names, carrier_name)
    if problem == SEVERAL_CARRIERS:
        raise reader.error("several carriers: say which with carrier = \"NAME\"", "wafer", i)
    if problem:
        raise reader.error(f"no carrier named {carrier_name!r}", "wafer", i, "carrier")
    carrier_name = carrier_name or names[0]
    carrier = by_name[carrier_name]
    slot = reader.value(w, "wafer", "slot", schema.count, index=i, required=True)
    if slot > carrier.slot_count:
        raise reader.error(f"slot {slot} is beyond the carrier's {carrier.slot_count} "
                           "slots", "wafer", i, "slot")
    state = reader.value(w, "wafer", "state", schema.choice(WAFER_STATES), index=i,
                         default="present")
    if state == "cross" and slot == carrier.slot_count:
        raise reader.error(f"a cross-slotted wafer in slot {slot} needs a slot above",
                           "wafer", i, "slot")
    for key in ("center", "normal", "diameter", "thickness", "name"):
        if key in w:
            raise reader.error("give either carrier + slot + state, or a free "
                               "placement (center, normal, diameter, thickness)",
                               "wafer", i, key)
    plan = plans[carrier_name]
    # An explicit wafer replaces what the load string put in its slot(s).
    for other, other_state in list(plan.items()):
        if other == slot or (other_state == "cross" and other + 1 == slot) or (
                state == "cross" and other == slot + 1):
            del plan[other]
    plan[slot] = state
    return carrier_name, slot


def _wafers(reader, data, carriers):
    by_name = {c.name: c for c in carriers}
    plans = {c.name: {} for c in carriers}  # carrier -> {slot: state}
    # SPEC §10: each carrier's wafer_bow, and a [[wafer]]'s own bow by (carrier, slot).
    carrier_bows = {c.name: reader.value(data["carrier"][i], "carrier", "wafer_bow",
                                         schema.number, index=i, default=0.0)
                    for i, c in enumerate(carriers)}
    slot_bows = {}
    for i, c in enumerate(carriers):
        raw = data["carrier"][i]
        if "load" in raw:
            plans[c.name] = _load_states(reader, c, raw["load"], i)
    free = []
    for i, w in enumerate(data.get("wafer", [])):
        reader.table(w, "wafer", _WAFER_KEYS, i)
        if "slot" in w or "state" in w:
            carrier_name, slot = _seat_wafer(reader, w, i, by_name, plans)
            if "bow" in w:
                slot_bows[(carrier_name, slot)] = reader.value(w, "wafer", "bow", schema.number,
                                                               index=i)
            continue
        name = reader.value(w, "wafer", "name", schema.name, index=i, default=f"W{i + 1}")
        center = reader.value(w, "wafer", "center", schema.vector(3), index=i, required=True)
        normal = unit(reader.value(w, "wafer", "normal", schema.vector(3, nonzero=True), index=i,
                                   default=(0.0, 0.0, 1.0)))
        carrier_name = reader.value(w, "wafer", "carrier", schema.carrier_name, index=i)
        if carrier_name is not None and carrier_name not in by_name:
            raise reader.error(f"no carrier named {carrier_name!r}", "wafer", i, "carrier")
        default = by_name[carrier_name] if carrier_name else carriers[0]
        free.append(Wafer(
            name=name, center=center, normal=normal,
            diameter=reader.value(w, "wafer", "diameter", schema.positive, index=i,
                                  default=default.wafer_diameter),
            thickness=reader.value(w, "wafer", "thickness", schema.positive, index=i,
                                   default=default.wafer_thickness),
            carrier=carrier_name,
            bow=reader.value(w, "wafer", "bow", schema.number, index=i,
                             default=carrier_bows[carrier_name] if carrier_name else 0.0)))
    wafers = []
    for carrier in carriers:
        index = 1
        for slot in sorted(plans[carrier.name]):
            bow = slot_bows.get((carrier.name, slot), carrier_bows[carrier.name])
            made = seated_wafers(carrier, slot, plans[carrier.name][slot], index, bow)
            wafers += made
            index += len(made)
    names = {w.name for w in wafers}
    for i, w in enumerate(free):
        if w.name in names:
            raise reader.error(f"a second wafer named {w.name!r}", "wafer", i, "name")
        names.add(w.name)
    return wafers + free
