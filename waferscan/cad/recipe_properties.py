"""SPEC §11's mapping recipe on the document's ScanSettings object: the thickness and position
windows, the double threshold, the rule set and the thickness correction. Each limit is a length
(App::PropertyLength, shown in the user's unit schema) with a box beside it, ``ThicknessMinSet``
and so on: not ticked, the limit is not set and SPEC §4's rule from t, Δt and Δp applies. A
document made before the recipe has none of them and judges by SPEC §4.

Documents saved by earlier versions hold the limits as App::PropertyFloat in mm, a negative
number meaning "not set": ``read`` reads both, and ``upgrade`` turns such an object's limits into
today's properties (the recipe unchanged)."""

from __future__ import annotations

from dataclasses import replace

from ..core import schema
from ..core.mapping import RULE_SETS
from ..core.recipe import DEFAULTS
from . import roles
from .role_properties import RECIPE_PROPERTIES, RECIPE_SET_PROPERTIES

# The limits that follow t, Δt and Δp when not set.
_OPTIONAL = tuple(key for key, value in DEFAULTS.items() if value is None)
_SET_TIPS = {limit: tip for _, limit, tip in RECIPE_SET_PROPERTIES}
LIMITS = tuple(_SET_TIPS)  # the limit properties, each with its "...Set" box
OLD_KIND = "App::PropertyFloat"  # the limits' type before (negative: not set)
OLD_NOT_SET = -1.0  # what the GUI wrote for "not set" into such a limit


def holds_old_limits(obj):
    """Whether ``obj`` holds the limits as an earlier version did (floats, negative: not
    set)."""
    return obj is not None and obj.getTypeIdOfProperty(LIMITS[0]) == OLD_KIND


def set_flag(prop):
    """The box beside a limit property: "ThicknessMin" -> "ThicknessMinSet"."""
    return f"{prop}Set"


def add_to(obj, mapping):
    """Add the recipe's properties to a ScanSettings object, set from core MappingTolerances."""
    for prop, kind, key, tip in RECIPE_PROPERTIES:
        value = getattr(mapping, key)
        if key == "rules":
            roles.add_property(obj, kind, prop, tip)
            setattr(obj, prop, list(RULE_SETS))
            setattr(obj, prop, value)
        elif prop in _SET_TIPS:
            roles.add_property(obj, kind, prop, tip, 0.0 if value is None else value)
            roles.add_property(obj, "App::PropertyBool", set_flag(prop), _SET_TIPS[prop],
                               value is not None)
        else:
            roles.add_property(obj, kind, prop, tip, value)


def set_values(obj, mapping):
    """Write a mapping's recipe into an object that has the properties (a calibration's). A
    limit saved by an earlier version keeps its kind (a float in mm, ``OLD_NOT_SET``: not set),
    as the Recipe section writes it: FreeCAD's Undo cannot take back a property's change of
    type (the upgraded property went, the old one did not come back)."""
    for prop, _, key, _ in RECIPE_PROPERTIES:
        value = getattr(mapping, key)
        if prop in _SET_TIPS and obj.getTypeIdOfProperty(prop) == OLD_KIND:
            setattr(obj, prop, OLD_NOT_SET if value is None else float(value))
        elif prop in _SET_TIPS:
            setattr(obj, prop, 0.0 if value is None else value)
            setattr(obj, set_flag(prop), value is not None)
        else:
            setattr(obj, prop, value)


def limit_value(obj, prop):
    """A limit property's value in mm, or None when it is not set (today's box, or an earlier
    version's negative float)."""
    raw = getattr(obj, prop)
    number = float(getattr(raw, "Value", raw))
    if set_flag(prop) in obj.PropertiesList:
        return number if getattr(obj, set_flag(prop)) else None
    return None if number < 0.0 else number


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
        if prop in _SET_TIPS:
            number = limit_value(obj, prop)
            if number is None and key in _OPTIONAL:
                continue  # not set
        else:
            number = float(getattr(raw, "Value", raw))
        try:
            values[key] = schema.MAPPING_KEYS[key](number)
        except ValueError as exc:
            raise error(f"{obj.Label}.{prop}: {exc}") from None
    return replace(mapping, **values)


def upgrade(obj):
    """Bring an object saved by an earlier version (limits as floats, negative: not set) up to
    today's properties, its recipe unchanged. True when something was changed."""
    changed = False
    for prop, kind, _, tip in RECIPE_PROPERTIES:
        if prop not in _SET_TIPS or prop not in obj.PropertiesList or \
                obj.getTypeIdOfProperty(prop) != OLD_KIND:
            continue
        value = limit_value(obj, prop)
        obj.removeProperty(prop)
        roles.add_property(obj, kind, prop, tip, 0.0 if value is None else value)
        roles.add_property(obj, "App::PropertyBool", set_flag(prop), _SET_TIPS[prop],
                           value is not None)
        changed = True
    return changed


def property_of(key):
    """The ScanSettings property that holds a recipe key (None: not a recipe key)."""
    return next((prop for prop, _, k, _ in RECIPE_PROPERTIES if k == key), None)
