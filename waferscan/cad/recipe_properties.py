"""SPEC §11's mapping recipe on the document's ScanSettings object: the thickness and position
windows, the double threshold, the rule set and the thickness correction. A limit that is not
set is stored as a negative number (the property editor has no "empty"), as ThicknessTolerance
is; a document made before the recipe has none of them and judges by SPEC §4."""

from __future__ import annotations

from dataclasses import replace

from ..core import schema
from ..core.mapping import RULE_SETS
from ..core.recipe import DEFAULTS
from . import roles
from .role_properties import RECIPE_PROPERTIES

# The limits that follow t, Δt and Δp when not set (stored negative).
_OPTIONAL = tuple(key for key, value in DEFAULTS.items() if value is None)
NOT_SET = -1.0


def add_to(obj, mapping):
    """Add the recipe's properties to a ScanSettings object, set from core MappingTolerances."""
    for prop, kind, key, tip in RECIPE_PROPERTIES:
        value = getattr(mapping, key)
        if key == "rules":
            roles.add_property(obj, kind, prop, tip)
            setattr(obj, prop, list(RULE_SETS))
            setattr(obj, prop, value)
        else:
            roles.add_property(obj, kind, prop, tip, NOT_SET if value is None else value)


def set_values(obj, mapping):
    """Write a mapping's recipe into an object that has the properties (a calibration's)."""
    for prop, _, key, _ in RECIPE_PROPERTIES:
        value = getattr(mapping, key)
        setattr(obj, prop, NOT_SET if value is None else value)


def read(obj, mapping, error):
    """``mapping`` with the recipe of the object's properties (those it has), each checked as a
    scenario's value would be; ``error(message)`` makes the exception naming object and
    property."""
    values = {}
    for prop, _, key, _ in RECIPE_PROPERTIES:
        if prop not in obj.PropertiesList:
            continue
        raw = getattr(obj, prop)
        if key == "rules":
            values[key] = str(raw)
            continue
        number = float(getattr(raw, "Value", raw))
        if key in _OPTIONAL and number < 0.0:
            continue  # not set
        try:
            values[key] = schema.MAPPING_KEYS[key](number)
        except ValueError as exc:
            raise error(f"{obj.Label}.{prop}: {exc}") from None
    return replace(mapping, **values)


def property_of(key):
    """The ScanSettings property that holds a recipe key (None: not a recipe key)."""
    return next((prop for prop, _, k, _ in RECIPE_PROPERTIES if k == key), None)
