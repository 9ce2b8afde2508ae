"""The settings of SPEC §10 as a user gives them: keys, checks, defaults, and the layout that
carries them. One place for the scenario reader, parameters.txt and the document.

[sensor] (and parameters.txt): spot_diameter, or spot_width and spot_height (mm, 0 = the ideal
line); threshold_on, threshold_off (blocked fractions, 0 < threshold_off <= threshold_on <= 1).
[scan] (and parameters.txt): latch = step | encoder | sampled; acceleration (mm/s², default
infinite); sample_period (s, needed by ``sampled``).
"""

from __future__ import annotations

import math
from dataclasses import replace

from .. import schema
from .motion import LATCHES, SAMPLED, STEP
from .spot import DEFAULT_AMPLIFIER, IDEAL_SPOT, Amplifier, BeamSpot


def fraction(value):
    """A blocked fraction: greater than 0, at most 1."""
    x = schema.number(value)
    if not 0.0 < x <= 1.0:
        raise ValueError(f"must be a fraction of the spot greater than 0 and at most 1, got "
                         f"{value!r}")
    return x


SPOT_KEYS = {
    "spot_diameter": schema.non_negative,
    "spot_width": schema.non_negative,
    "spot_height": schema.non_negative,
    "threshold_on": fraction,
    "threshold_off": fraction,
}
MOTION_KEYS = {
    "latch": schema.choice(LATCHES),
    "acceleration": schema.positive,
    "sample_period": schema.positive,
}
SETTING_KEYS = {**SPOT_KEYS, **MOTION_KEYS}


def settings_problem(values):
    """The first problem of a set of §10 values taken together, as (key, message), or None.
    ``values`` maps the keys above to checked values (keys absent: not given)."""
    diameter = values.get("spot_diameter", 0.0)
    width, height = values.get("spot_width", 0.0), values.get("spot_height", 0.0)
    if diameter > 0.0 and (width > 0.0 or height > 0.0):
        key = "spot_width" if width > 0.0 else "spot_height"
        return key, "give spot_diameter (a round spot) or spot_width and spot_height (a slit), " \
                    "not both"
    if (width > 0.0) != (height > 0.0):
        key = "spot_width" if width > 0.0 else "spot_height"  # the one given
        return key, "a slit spot needs both spot_width and spot_height greater than 0"
    on = values.get("threshold_on", DEFAULT_AMPLIFIER.threshold_on)
    off = values.get("threshold_off")
    if off is not None and off > on:
        key = "threshold_off" if "threshold_off" in values else "threshold_on"
        return key, f"threshold_off {off:g} must not exceed threshold_on {on:g}"
    if values.get("latch") == SAMPLED and "sample_period" not in values:
        return "latch", "latch = sampled needs sample_period (s)"
    return None


def current_values(layout):
    """The layout's §10 values as a dict of every key (defaults included)."""
    spot = layout.spot or IDEAL_SPOT
    amplifier = layout.amplifier or DEFAULT_AMPLIFIER
    scan = layout.scan
    values = {"spot_diameter": spot.diameter, "spot_width": spot.width,
              "spot_height": spot.height, "threshold_on": amplifier.threshold_on,
              "threshold_off": amplifier.off_level, "latch": scan.latch,
              "acceleration": scan.acceleration, "sample_period": scan.sample_period}
    return values


def given_values(layout):
    """The layout's §10 values that differ from the defaults (the ideal sensor), in the keys'
    order: what parameters.txt and results.txt list, so that a scan without them reads as it
    always did."""
    values = current_values(layout)
    defaults = {"spot_diameter": 0.0, "spot_width": 0.0, "spot_height": 0.0,
                "threshold_on": DEFAULT_AMPLIFIER.threshold_on,
                "threshold_off": values["threshold_on"], "latch": STEP,
                "acceleration": math.inf, "sample_period": 0.0}
    return {k: v for k, v in values.items() if v != defaults[k]}


def with_settings(layout, values):
    """The layout with the given §10 values in place of its own (keys absent keep the layout's;
    a new spot's shape replaces the old one's). ValueError(key, message) from
    ``settings_problem`` is the caller's to report: see ``SettingsError``."""
    merged = current_values(layout)
    if "spot_diameter" in values and values["spot_diameter"] > 0.0:
        merged["spot_width"] = merged["spot_height"] = 0.0
    if ("spot_width" in values or "spot_height" in values) and (
            values.get("spot_width", 0.0) > 0.0 or values.get("spot_height", 0.0) > 0.0):
        merged["spot_diameter"] = 0.0
    # threshold_off follows threshold_on unless it was set (here or in the layout before).
    off_set = "threshold_off" in values or (layout.amplifier is not None
                                             and layout.amplifier.threshold_off is not None)
    merged.update(values)
    if not off_set:
        merged["threshold_off"] = merged["threshold_on"]
    given = dict(values)
    for key in ("spot_width", "spot_height", "spot_diameter", "threshold_off"):
        given.setdefault(key, merged[key]) if merged[key] else None
    if merged["latch"] == SAMPLED and merged["sample_period"] > 0.0:
        given.setdefault("sample_period", merged["sample_period"])
    given.setdefault("threshold_on", merged["threshold_on"])
    given.setdefault("latch", merged["latch"])
    problem = settings_problem(given)
    if problem is not None:
        raise SettingsError(*problem)
    spot = BeamSpot(merged["spot_diameter"], merged["spot_width"], merged["spot_height"])
    amplifier = Amplifier(merged["threshold_on"], merged["threshold_off"] if off_set else None)
    scan = replace(layout.scan, latch=merged["latch"], acceleration=merged["acceleration"],
                   sample_period=merged["sample_period"])
    return replace(layout, scan=scan, spot=None if spot.ideal else spot,
                   amplifier=None if amplifier == DEFAULT_AMPLIFIER else amplifier)


# The §10 values that go together, and the scan's sensor_response, for defaults given from
# outside a scenario (the GUI's preferences): a default fills a group only when the scenario
# gives none of the group's keys, so that a default never mixes with the scenario's own choice
# (a preferred round spot with the scenario's slit, a preferred OFF level above its ON level, a
# preferred read period with its latch).
DEFAULT_GROUPS = (("spot_diameter", "spot_width", "spot_height"),
                  ("threshold_on", "threshold_off"), ("latch", "sample_period"),
                  ("acceleration",), ("sensor_response",))


def defaults_not_given(defaults, given):
    """The ``defaults`` (a dict of §10 keys and sensor_response, checked values) of the groups
    none of whose keys is in ``given`` (the keys a scenario sets)."""
    return {key: defaults[key] for group in DEFAULT_GROUPS
            if not any(k in given for k in group) for key in group if key in defaults}


def values_with_defaults(defaults):
    """Every §10 key's value for a new scan-settings object: the ideal sensor's, with the
    ``defaults`` given in place (threshold_off follows threshold_on unless given)."""
    values = {"spot_diameter": 0.0, "spot_width": 0.0, "spot_height": 0.0,
              "threshold_on": DEFAULT_AMPLIFIER.threshold_on, "latch": STEP,
              "acceleration": math.inf, "sample_period": 0.0}
    values.update({k: v for k, v in defaults.items() if k in SETTING_KEYS})
    values.setdefault("threshold_off", values["threshold_on"])
    return values


class SettingsError(ValueError):
    """A §10 setting that does not fit the others; ``key`` is the one to blame."""

    def __init__(self, key, message):
        super().__init__(message)
        self.key = key
