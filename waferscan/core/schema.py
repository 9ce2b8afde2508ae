"""Checks for the values a user gives, shared by the scenario format and parameters.txt.

Each check takes the raw value (a TOML value, or the text after ``=`` in parameters.txt) and
returns the clean value or raises ValueError with a message that says what was expected; the
reader that called it adds the file and line.
"""

from __future__ import annotations

import math

from .errors import WaferScanError
from .mapping import RULE_SETS
from .model import DIRECTIONS, MODES

# A scan is at most this many stepped positions (0.001 mm over 100 m); more is a typo.
MAX_POSITIONS = 100_000_000
# A travel longer than this (mm) is a typo in the range, not a step too fine for it.
MAX_TRAVEL = 100_000.0


def _as_number(value):
    if isinstance(value, bool):
        raise ValueError(f"expected a number, got {value!r}")
    if isinstance(value, (int, float)):
        number = float(value)
    elif isinstance(value, str):
        try:
            number = float(value.strip())
        except ValueError:
            raise ValueError(f"expected a number, got {value.strip()!r}") from None
    else:
        raise ValueError(f"expected a number, got {value!r}")
    if not math.isfinite(number):
        raise ValueError(f"expected a finite number, got {value!r}")
    return number


def number(value):
    return _as_number(value)


def positive(value):
    x = _as_number(value)
    if x <= 0.0:
        raise ValueError(f"must be greater than 0, got {value!r}")
    return x


def non_negative(value):
    x = _as_number(value)
    if x < 0.0:
        raise ValueError(f"must not be negative, got {value!r}")
    return x


def count(value):
    """A whole number of at least 1 (a slot count)."""
    x = _as_number(value)
    if x != math.floor(x) or x < 1 or x > 10_000:
        raise ValueError(f"expected a whole number from 1 to 10000, got {value!r}")
    return int(x)


def name(value):
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"expected a name, got {value!r}")
    return value.strip()


def carrier_name(value):
    """A carrier's name: it is written to parameters.txt, where ``#`` starts a comment, so it
    holds neither ``#`` nor a line break."""
    text = name(value)
    if "#" in text or len(text.splitlines()) != 1 or any(ord(c) < 32 for c in text):
        raise ValueError(f"a carrier's name cannot hold '#' or control characters (it is "
                         f"written to parameters.txt, where '#' starts a comment), got {value!r}")
    return text


def choice(options):
    def check(value):
        text = value.strip().lower() if isinstance(value, str) else value
        if text not in options:
            raise ValueError(f"expected one of {', '.join(options)}, got {value!r}")
        return text
    return check


def vector(size, nonzero=False):
    def check(value):
        if not isinstance(value, (list, tuple)) or len(value) != size:
            raise ValueError(f"expected a list of {size} numbers, got {value!r}")
        items = tuple(_as_number(v) for v in value)
        if nonzero and not any(items):
            raise ValueError(f"must not be the zero vector, got {list(value)}")
        return items
    return check


# Scan parameters: the same keys in a scenario's [scan] table and in parameters.txt.
SCAN_KEYS = {
    "start_z": number,
    "final_z": number,
    "z_step": non_negative,
    "mode": choice(MODES),
    "direction": choice(DIRECTIONS),
    "scan_speed": positive,
    "sensor_response": non_negative,
}

# Mapping tolerances: a scenario's [mapping] table and parameters.txt.
MAPPING_KEYS = {
    "thickness_tolerance": non_negative,
    "position_tolerance": non_negative,
    "protrusion_limit": non_negative,
    # SPEC §11's recipe (core/recipe.py); how they fit together: validation.mapping_problems
    "thickness_min": non_negative,
    "thickness_max": positive,
    "double_threshold": positive,
    "position_below": non_negative,
    "position_above": non_negative,
    "rules": choice(RULE_SETS),
    "thickness_correction": positive,
    "clearance_min": non_negative,  # SPEC §15, mm (core/scan/clearance.py)
}


class ScanRangeError(WaferScanError, ValueError):
    """A scan range that makes no sensible scan; ``key`` is the value to blame: ``z_step`` when
    the range is plausible and the step too fine for it, ``final_z`` otherwise."""

    def __init__(self, message, key):
        super().__init__(message)
        self.key = key


def check_scan_range(start_z, final_z, z_step):
    """Raise ScanRangeError unless the scan's range and step make a sensible scan."""
    if final_z < start_z:
        raise ScanRangeError(f"final_z ({final_z:g}) is below start_z ({start_z:g})", "final_z")
    if z_step > 0.0 and not (final_z - start_z) / z_step + 1 <= MAX_POSITIONS:
        positions = (final_z - start_z) / z_step + 1
        positions = f"{positions:,.0f}" if math.isfinite(positions) else "too many"
        raise ScanRangeError(
            f"z_step {z_step:g} over {final_z - start_z:g} mm makes {positions} positions; at "
            f"most {MAX_POSITIONS:,} (use z_step = 0 for exact edges)",
            "z_step" if final_z - start_z <= MAX_TRAVEL else "final_z")
