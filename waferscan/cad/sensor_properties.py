"""SPEC §10's sensor settings on the document's ScanSettings object, in units: the beam spot
(lengths), the amplifier's thresholds (fractions), the latch, the stroke's acceleration and the
controller's read period. Kept apart from features.py so that the settings of §10 are added and
read in one place; a document made before them reads as the ideal sensor.
"""

from __future__ import annotations

import math

from ..core.sensor import settings as sensor_settings
from ..core.sensor.motion import LATCHES
from . import roles

# (property, kind, key of core.sensor.settings, tooltip), listed with the role's other properties
from .role_properties import LATCH_TIP, SENSOR_PROPERTIES, from_property, to_property


def add_sensor_properties(obj, layout):
    """Add the §10 properties to a ScanSettings object, filled from the layout."""
    add_sensor_values(obj, sensor_settings.current_values(layout))


def add_sensor_values(obj, values):
    """Add the §10 properties to a ScanSettings object, filled from ``values`` (every key of
    ``core.sensor.settings``, as ``current_values`` or ``values_with_defaults`` give them)."""
    for prop, kind, key, tip in SENSOR_PROPERTIES:
        value = values[key]
        if key == "acceleration" and math.isinf(value):
            value = 0.0
        roles.add_property(obj, kind, prop, tip, to_property(prop, value))
    roles.add_property(obj, "App::PropertyEnumeration", "Latch",
                       LATCH_TIP)
    obj.Latch = list(LATCHES)
    obj.Latch = values["latch"]


def read_sensor_settings(scene, layout):
    """The layout with the §10 settings of the document's ScanSettings object (none: as is).
    A bad value is the scene's error, naming the object and property."""
    if len(scene.settings) != 1:
        return layout
    obj = roles.role_holder(scene.settings[0].obj)
    values = {}
    for prop, _, key, _ in SENSOR_PROPERTIES:
        if prop not in obj.PropertiesList:
            continue
        number = from_property(prop, getattr(obj, prop))
        if number == 0.0 and key in ("acceleration", "sample_period", "spot_diameter",
                                     "spot_width", "spot_height"):
            continue  # not set
        try:
            values[key] = sensor_settings.SETTING_KEYS[key](number)
        except ValueError as exc:
            raise scene.error(f"{obj.Label}.{prop}: {exc}") from None
    if "threshold_off" in values and values["threshold_off"] == values.get("threshold_on"):
        del values["threshold_off"]  # no hysteresis: OFF follows ON, wherever ON is set
    if "Latch" in obj.PropertiesList:
        values["latch"] = str(obj.Latch)
    if not values:
        return layout
    try:
        return sensor_settings.with_settings(layout, values)
    except sensor_settings.SettingsError as exc:
        prop = next((p for p, _, k, _ in SENSOR_PROPERTIES if k == exc.key), "Latch")
        raise scene.error(f"{obj.Label}.{prop}: {exc}") from None
