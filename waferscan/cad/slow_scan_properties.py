"""SPEC §13's slow-scan settings on the document's ScanSettings object: the jab, the sweep, the
wrist's distance behind the beam and the arm's and wrist's motion, as properties in units. A
document made before them has none and scans with the defaults (core/slow_scan.py)."""

from __future__ import annotations

from dataclasses import replace

from ..core import slow_scan
from . import roles

PROPERTIES = (
    # (property, kind, ScanParameters field, tooltip)
    ("Jab", "App::PropertyLength", "jab", "Slow scan: how far the fork advances into each "
     "pocket along its heading (0: no jab)"),
    ("Sweep", "App::PropertyAngle", "sweep", "Slow scan: the wrist turns by plus and minus "
     "this at each pocket (0: no sweep)"),
    ("SweepRadius", "App::PropertyLength", "sweep_radius", "Distance from the wrist axis to the "
     "beam's midpoint along the fork's heading"),
    ("ArmSpeed", "App::PropertySpeed", "arm_speed", "Speed of the jab's straight advance"),
    ("ArmAcceleration", "App::PropertyAcceleration", "arm_acceleration",
     "Acceleration of the jab's straight advance"),
    ("WristSpeed", "App::PropertyFloat", "wrist_speed", "Speed of the sweep in degrees/s"),
    ("WristAcceleration", "App::PropertyFloat", "wrist_acceleration",
     "Acceleration of the sweep in degrees/s²"),
)


def add_to(obj, scan):
    """Add the properties to a ScanSettings object, set from core ScanParameters."""
    for prop, kind, field, tip in PROPERTIES:
        roles.add_property(obj, kind, prop, tip, getattr(scan, field))


def read(obj, scan, error):
    """``scan`` with the values of the object's properties (those it has), each checked as a
    scenario's would be; ``error(message)`` makes the exception naming object and property."""
    values = {}
    for prop, _, field, _ in PROPERTIES:
        if prop not in obj.PropertiesList:
            continue
        raw = getattr(obj, prop)
        try:
            value = slow_scan.SETTING_KEYS[field](float(getattr(raw, "Value", raw)))
            problem = slow_scan.setting_problem(field, value)
            if problem:
                raise ValueError(problem)
        except ValueError as exc:
            raise error(f"{obj.Label}.{prop}: {exc}") from None
        values[field] = value
    return replace(scan, **values)
