"""Tolerance files for sweeps (SPEC §12): what varies from one sampled layout to the next.

A TOL.toml has one table per quantity, each a distribution, and an optional ``[states]`` table
with the probabilities of each slot's true state:

    [seat_offset]        # mm, added to each wafer's seat height
    dist = "uniform"     # "uniform" (lo, hi) | "normal" (mean, sigma) | "fixed" (value)
    lo = -0.5
    hi = 0.5
    [states]             # absent: the INPUT's load
    present = 0.9
    empty = 0.1

Quantities drawn per wafer: seat_offset, thickness, bow, tilt, protrusion; per layout (the
sensor's): beam_z, beam_tilt, sensor_response, threshold_on. A quantity not given keeps the
INPUT's value. Every mistake is an InputError naming the file and the line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError

# Quantity -> (unit, drawn per "wafer" or per "layout", what it does).
QUANTITIES = {
    "seat_offset": ("mm", "wafer", "added to each wafer's seat height"),
    "thickness": ("mm", "wafer", "replaces the nominal thickness"),
    "bow": ("mm", "wafer", "the wafer's bow (SPEC §10)"),
    "tilt": ("deg", "wafer", "about a random horizontal axis"),
    "protrusion": ("mm", "wafer", "out of the carrier's opening"),
    "beam_z": ("mm", "layout", "teach error of the scan's start"),
    "beam_tilt": ("deg", "layout", "the beam tilted in its vertical plane"),
    "sensor_response": ("s", "layout", "replaces the scan's sensor_response"),
    "threshold_on": ("", "layout", "replaces the amplifier's threshold_on"),
}
# The order quantities are drawn in: fixed, so that a seed gives the same layouts whatever the
# order of the tables in the file.
DRAW_ORDER = tuple(QUANTITIES)

DISTRIBUTIONS = {"uniform": ("lo", "hi"), "normal": ("mean", "sigma"), "fixed": ("value",)}

# [states] names: SPEC §4's (as the summary spells them) and the scenario's words for two of
# them; each maps to the scenario's wafer state that seats it.
STATE_WORDS = {
    "empty": "absent", "absent": "absent",
    "present": "present",
    "cross": "cross",
    "double": "double",
    "thin": "thin",
    "position_error": "misplaced", "misplaced": "misplaced",
    "protruding": "protruding",
}
# The largest magnitude each quantity may take (a normal's mean +- 6 sigma too): as the other
# readers, a length is at most a carrier's size, a tilt below a right angle. threshold_on and
# tilt have their own, tighter checks below.
LIMITS = {"seat_offset": 1000.0, "thickness": 100.0, "bow": 100.0, "protrusion": 1000.0,
          "beam_z": 1000.0, "beam_tilt": 90.0, "sensor_response": 10.0}
# How many sigmas of a normal distribution are checked against a quantity's limits.
NORMAL_REACH = 6.0
# Probabilities must sum to 1 to this much.
SUM_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Distribution:
    """One quantity's distribution: ``kind`` "uniform" (a = lo, b = hi), "normal" (a = mean,
    b = sigma) or "fixed" (a = value)."""

    kind: str
    a: float
    b: float = 0.0

    def draw(self, rng, shape):
        """An array of ``shape`` drawn from ``rng`` (a numpy Generator). A fixed value draws
        nothing, so adding a fixed table does not change the other quantities' samples."""
        import numpy as np

        if self.kind == "uniform":
            return rng.uniform(self.a, self.b, shape)
        if self.kind == "normal":
            return rng.normal(self.a, self.b, shape)
        return np.full(shape, float(self.a))

    @property
    def low(self):
        """The smallest value it gives in practice: a normal's mean - 6 sigma (one draw in
        10^9 lies beyond; draws are clipped to a quantity's limits, see sweep.draw_block)."""
        if self.kind == "uniform":
            return self.a
        if self.kind == "normal":
            return self.a - NORMAL_REACH * self.b
        return self.a

    @property
    def high(self):
        """The largest value it gives in practice (a normal's mean + 6 sigma)."""
        if self.kind == "uniform":
            return self.b
        if self.kind == "normal":
            return self.a + NORMAL_REACH * self.b
        return self.a


@dataclass(frozen=True)
class Tolerances:
    """A parsed TOL.toml: ``quantities`` {name: Distribution} (only those given) and ``states``
    ((scenario state, probability), ...) or None for the INPUT's load."""

    quantities: dict = field(default_factory=dict)
    states: tuple | None = None
    source: str = "<tolerances>"
    clearance: object = None  # [clearance]: a ClearanceStudy (core/sweep/clearance.py)

    def get(self, name):
        return self.quantities.get(name)


def read_tolerances(path):
    """Read and check a TOL.toml file (InputError with file and line when it is wrong)."""
    from ..files.text_files import read_text

    path = Path(path)
    text = read_text(path, "the tolerance file")  # a regular file, bounded
    return parse_tolerances(text, str(path))


def _line_of(text, table, key=None):
    """Line (1-based) of ``key`` in [table] (or of the table's header), None if not found."""
    from ..files.scenario import key_line

    return key_line(text, table, key)


def parse_tolerances(text, source="<tolerances>"):
    """Parse TOL.toml text into ``Tolerances``; ``source`` names it in errors."""
    from ..files.scenario import parse_toml

    data = parse_toml(text.lstrip("\ufeff"), source)

    def error(message, table, key=None):
        return InputError(source, _line_of(text, table, key), message)

    quantities = {}
    states = None
    clearance = None
    for name, table in data.items():
        if name == "states":
            if not isinstance(table, dict):
                raise error("write it as a [states] table", None, name)
            states = _states(table, error)
            continue
        if name == "clearance":
            if not isinstance(table, dict):
                raise error("write it as a [clearance] table", None, name)
            clearance = _clearance(table, error)
            continue
        if name not in QUANTITIES:
            raise InputError(source, _line_of(text, name) or _line_of(text, None, name),
                             f"unknown table {name!r} (known: "
                             f"{', '.join(list(QUANTITIES) + ['states', 'clearance'])})")
        if not isinstance(table, dict):
            raise error(f"write {name} as a [{name}] table with dist = ...", None, name)
        quantities[name] = _distribution(name, table, error)
    return Tolerances(quantities, states, source, clearance)


def _number(value, table, key, error):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise error(f"[{table}] {key}: expected a finite number, got {value!r}", table, key)
    return float(value)


def _distribution(name, table, error):
    kind = table.get("dist")
    if kind is None:
        raise error(f"[{name}]: missing key 'dist' (uniform, normal or fixed)", name)
    if not isinstance(kind, str) or kind not in DISTRIBUTIONS:
        raise error(f"[{name}] dist: {kind!r} is not a distribution (uniform, normal or fixed)",
                    name, "dist")
    wanted = DISTRIBUTIONS[kind]
    for key in table:
        if key != "dist" and key not in wanted:
            raise error(f"[{name}] {key}: unknown key for dist = {kind!r} (it takes "
                        f"{', '.join(wanted)})", name, key)
    values = []
    for key in wanted:
        if key not in table:
            raise error(f"[{name}]: missing key {key!r} for dist = {kind!r}", name)
        values.append(_number(table[key], name, key, error))
    dist = Distribution(kind, *values)
    if kind == "uniform" and dist.b < dist.a:
        raise error(f"[{name}] hi: {dist.b:g} is below lo {dist.a:g}", name, "hi")
    if kind == "normal" and dist.b < 0.0:
        raise error(f"[{name}] sigma: must not be negative, got {dist.b:g}", name, "sigma")
    # The key blamed is the one that sets the limit broken: a uniform's lo or hi, a normal's
    # mean (its mean -+ 6 sigma), a fixed value.
    low_key = {"uniform": "lo", "normal": "mean"}.get(kind, "value")
    high_key = {"uniform": "hi", "normal": "mean"}.get(kind, "value")
    limit = LIMITS.get(name)
    if limit is not None and not (-limit <= dist.low and dist.high <= limit):
        if kind == "normal":
            key = "mean" if not -limit <= dist.a <= limit else "sigma"
        else:
            key = low_key if not -limit <= dist.low else high_key
        unit = QUANTITIES[name][0]
        raise error(f"[{name}] {key}: must stay within ±{limit:,.0f} {unit}"
                    + (" (a normal's mean ± 6 sigma too)" if kind == "normal" else "")
                    + f", got {table[key]!r}", name, key)
    if name == "thickness" and dist.low <= 0.0:
        raise error(f"[thickness] {low_key}: a thickness must stay above 0 mm (a normal's "
                    f"mean - 6 sigma too), got {table[low_key]!r}", name, low_key)
    if name == "sensor_response" and dist.low < 0.0:
        raise error(f"[sensor_response] {low_key}: a response time cannot be negative "
                    f"(a normal's mean - 6 sigma neither), got {table[low_key]!r}",
                    name, low_key)
    if name == "threshold_on" and not (0.0 < dist.low and dist.high <= 1.0):
        key = low_key if not 0.0 < dist.low else high_key
        raise error(f"[threshold_on] {key}: a threshold is a blocked fraction in (0, 1] "
                    f"(a normal's mean +- 6 sigma too), got {table[key]!r}",
                    name, key)
    if name == "tilt" and not (dist.high < 90.0 and dist.low > -90.0):
        key = high_key if not dist.high < 90.0 else low_key
        raise error(f"[tilt] {key}: a tilt must stay within +-90 degrees, got {table[key]!r}",
                    name, key)
    return dist


def _clearance(table, error):
    """[clearance]: the sweep reports the rate of layouts with a contact (SPEC §15);
    ``clearance_min`` (mm, > 0) replaces the layout's [mapping] clearance_min."""
    from .clearance import ClearanceStudy

    for key in table:
        if key != "clearance_min":
            raise error(f"[clearance] {key}: unknown key (it takes clearance_min)",
                        "clearance", key)
    if "clearance_min" not in table:
        return ClearanceStudy()
    value = _number(table["clearance_min"], "clearance", "clearance_min", error)
    if not 0.0 < value <= LIMITS["protrusion"]:
        raise error(f"[clearance] clearance_min: a distance above 0 mm and at most "
                    f"{LIMITS['protrusion']:,.0f} mm, got {table['clearance_min']!r}",
                    "clearance", "clearance_min")
    return ClearanceStudy(value)


def _states(table, error):
    found = []
    for key, value in table.items():
        if key not in STATE_WORDS:
            raise error(f"[states] {key}: unknown state (known: "
                        f"{', '.join(sorted(STATE_WORDS))})", "states", key)
        p = _number(value, "states", key, error)
        if not 0.0 <= p <= 1.0:
            raise error(f"[states] {key}: a probability is in [0, 1], got {value!r}",
                        "states", key)
        state = STATE_WORDS[key]
        if any(s == state for s, _ in found):
            raise error(f"[states] {key}: the same state given twice", "states", key)
        found.append((state, p))
    total = sum(p for _, p in found)
    if abs(total - 1.0) > SUM_TOLERANCE:
        raise error(f"[states]: the probabilities sum to {total:g}, not 1", "states")
    return tuple(found)
