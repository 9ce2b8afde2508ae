"""SPEC §13's slow-scan settings on the document's ScanSettings object: the jab, the sweep, the
wrist's distance behind the beam and the arm's and wrist's motion, as properties in units. A
document made before them has none and scans with the defaults (core/scan/slow_scan.py)."""

from __future__ import annotations

from dataclasses import replace

from ..core.scan import slow_scan
from . import roles
from .role_properties import SLOW_SCAN_PROPERTIES

# (property, kind, ScanParameters field, tooltip): listed with the role's other properties
# in role_properties.
PROPERTIES = SLOW_SCAN_PROPERTIES


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
