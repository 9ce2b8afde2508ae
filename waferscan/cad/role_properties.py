"""Every WaferScan role's properties, in one place: name, FreeCAD type, unit and meaning (as
freecad.cross lists a joint's). A role is a set of properties in the "WaferScan" group that any
object can carry (roles.py); these tables are what tagging adds and what the reader reads.

=================  ====================================================================
role               properties
=================  ====================================================================
every role         WaferScanRole (its name); WaferScan's own objects also WaferScanVersion
Wafer              none: the disc (centre, normal, diameter, thickness) is read from its solid
Carrier            CARRIER
Scanner            SCANNER
Robot              ROBOT (and RobotLink on each link's shape)
ScanSettings       SETTINGS (its scan and mapping fields: features.SETTINGS_PROPERTIES; the
                   recipe: RECIPE_PROPERTIES); one the GUI's Run scan added also has
                   features.RANGE_FROM_CARRIER (its range follows the carrier)
=================  ====================================================================
"""

from __future__ import annotations

from typing import NamedTuple


class RoleProperty(NamedTuple):
    """One property of a role: ``unit`` is "" for a count, a name or a direction."""

    name: str
    kind: str  # the FreeCAD property type
    unit: str
    tip: str  # the tooltip the property editor shows


CARRIER = (
    RoleProperty("SlotCount", "App::PropertyInteger", "", "Number of slots"),
    RoleProperty("Pitch", "App::PropertyLength", "mm", "Distance between slots"),
    RoleProperty("WaferDiameter", "App::PropertyLength", "mm", "Nominal wafer diameter"),
    RoleProperty("WaferThickness", "App::PropertyLength", "mm", "Nominal wafer thickness"),
    RoleProperty("SupportSpan", "App::PropertyLength", "mm",
                 "Distance between the left and right slot supports' inner edges"),
    RoleProperty("SlotOrigin", "App::PropertyPlacement", "mm",
                 "Slot 1's seat centre in this object's frame (X across, -Y to the opening)"),
)

SCANNER = (
    RoleProperty("Emitter", "App::PropertyVector", "mm", "Beam emitter in this object's frame"),
    RoleProperty("Receiver", "App::PropertyVector", "mm", "Beam receiver in this object's frame"),
    RoleProperty("LiftAxis", "App::PropertyVector", "",
                 "Global direction of the scan motion when no robot carries the scanner"),
)

ROBOT = (
    RoleProperty("Urdf", "App::PropertyString", "", "The robot's URDF; empty: the bundled robot"),
    RoleProperty("JointNames", "App::PropertyStringList", "", "Joints in order"),
    RoleProperty("StartJoints", "App::PropertyFloatList", "mm or degrees",
                 "Taught start-scanning pose (mm for prismatic, degrees for revolute joints)"),
    RoleProperty("LiftJoint", "App::PropertyString", "", "The joint a scan moves"),
)

SETTINGS = (
    RoleProperty("StartZ", "App::PropertyDistance", "mm",
                 "Scan position (emitter Z) of the first step"),
    RoleProperty("FinalZ", "App::PropertyDistance", "mm", "Scan position of the last step"),
    RoleProperty("ZStep", "App::PropertyLength", "mm",
                 "Step between scan positions; 0 for exact edges"),
    RoleProperty("ScanSpeed", "App::PropertySpeed", "mm/s", "Speed of a fast scan"),
    RoleProperty("SensorResponseMs", "App::PropertyFloat", "ms",
                 "Sensor response time in ms (0: an ideal sensor, no delay)"),
    RoleProperty("PositionTolerance", "App::PropertyLength", "mm", "Slot position tolerance"),
    RoleProperty("ProtrusionLimit", "App::PropertyLength", "mm", "Protrusion limit"),
    RoleProperty("ClearanceMin", "App::PropertyLength", "mm",
                 "Least distance the robot may come to a wafer along any motion of the scan "
                 "(SPEC 15)"),
    RoleProperty("Mode", "App::PropertyEnumeration", "",
                 "fast: one stroke; slow: pocket by pocket"),
    RoleProperty("Direction", "App::PropertyEnumeration", "", "Direction of a fast scan"),
    RoleProperty("ThicknessTolerance", "App::PropertyLength", "mm",
                 "Wafer thickness tolerance (used when ThicknessToleranceSet is ticked; "
                 "otherwise half the nominal wafer thickness)"),
    RoleProperty("ThicknessToleranceSet", "App::PropertyBool", "",
                 "Ticked: ThicknessTolerance is the tolerance; not ticked: half the nominal "
                 "wafer thickness"),
    RoleProperty("Carrier", "App::PropertyString", "", "Name (label) of the carrier to scan"),
)

# SPEC §10's sensor settings and SPEC §13's slow-scan settings on the same object, as (property,
# kind, key or field, tooltip): cad/sensor_properties.py and cad/slow_scan_properties.py add and
# read them.
_UNITS = {"SpotDiameter": "mm", "SpotWidth": "mm", "SpotHeight": "mm", "ThresholdOn": "",
          "ThresholdOff": "", "Acceleration": "mm/s²", "SamplePeriodMs": "ms", "Jab": "mm",
          "Sweep": "deg", "SweepRadius": "mm", "ArmSpeed": "mm/s", "ArmAcceleration": "mm/s²",
          "WristSpeedDegPerS": "deg/s",
          "WristAccelerationDegPerS2": "deg/s²"}


# (property, kind, key of core.sensor.settings, tooltip). Zero means "not set" for the spot's
# lengths (the ideal line), the acceleration (infinite) and the read period.
SENSOR_PROPERTIES = (
    ("SpotDiameter", "App::PropertyLength", "spot_diameter",
     "Diameter of a round beam spot; 0: the ideal line (SPEC §10)"),
    ("SpotWidth", "App::PropertyLength", "spot_width", "Width of a slit beam spot (with SpotHeight)"),
    ("SpotHeight", "App::PropertyLength", "spot_height", "Height of a slit beam spot (with SpotWidth)"),
    ("ThresholdOn", "App::PropertyFloat", "threshold_on",
     "Blocked fraction of the spot at which the amplifier's output turns ON"),
    ("ThresholdOff", "App::PropertyFloat", "threshold_off",
     "Blocked fraction below which it turns OFF again (<= ThresholdOn: hysteresis)"),
    ("Acceleration", "App::PropertyAcceleration", "acceleration",
     "Acceleration of the scan stroke; 0: full speed at once"),
    ("SamplePeriodMs", "App::PropertyFloat", "sample_period",
     "Period in ms at which the controller reads the sensor: used when Latch is sampled, "
     "which needs it greater than 0 (0: none given)"),
)

LATCH_TIP = ("step: edges on the step grid; encoder: latched in motion after the sensor's "
             "response; sampled: at the controller's next read")

SLOW_SCAN_PROPERTIES = (
    ("Jab", "App::PropertyLength", "jab", "Slow scan: how far the fork advances into each "
     "pocket along its heading (0: no jab)"),
    ("Sweep", "App::PropertyAngle", "sweep", "Slow scan: the wrist turns by plus and minus "
     "this at each pocket (0: no sweep)"),
    ("SweepRadius", "App::PropertyLength", "sweep_radius", "Distance from the wrist axis to the "
     "beam's midpoint along the fork's heading"),
    ("ArmSpeed", "App::PropertySpeed", "arm_speed", "Speed of the jab's straight advance"),
    ("ArmAcceleration", "App::PropertyAcceleration", "arm_acceleration",
     "Acceleration of the jab's straight advance"),
    ("WristSpeedDegPerS", "App::PropertyFloat", "wrist_speed",
     "Speed of the sweep's wrist turn in degrees per second (°/s)"),
    ("WristAccelerationDegPerS2", "App::PropertyFloat", "wrist_acceleration",
     "Acceleration of the sweep's wrist turn in degrees per second squared (°/s²)"),
)

# SPEC §11's recipe (core/recipe.py), as (property, kind, key, tooltip): cad/recipe_properties.py
# adds and reads them. Each limit is a length with a box beside it (RECIPE_SET_PROPERTIES): not
# ticked, the limit is not set and SPEC §4's rule from t, Δt and Δp applies. (Documents saved
# before kept the limits as floats in mm, negative meaning "not set": the reader reads both.)
RECIPE_PROPERTIES = (
    ("ThicknessMin", "App::PropertyLength", "thickness_min",
     "Recipe: shortest run of a present wafer (used when ThicknessMinSet is ticked; "
     "otherwise t - thickness tolerance)"),
    ("ThicknessMax", "App::PropertyLength", "thickness_max",
     "Recipe: longest run of a present wafer (used when ThicknessMaxSet is ticked; "
     "otherwise t + thickness tolerance)"),
    ("DoubleThreshold", "App::PropertyLength", "double_threshold",
     "Recipe: a run longer than this is cross-slotted (used when DoubleThresholdSet is "
     "ticked; otherwise 2t + thickness tolerance, 2.5 t under the boundary rules)"),
    ("PositionBelow", "App::PropertyLength", "position_below",
     "Recipe: how far a run's bottom may lie below its seat (used when PositionBelowSet is "
     "ticked; otherwise PositionTolerance)"),
    ("PositionAbove", "App::PropertyLength", "position_above",
     "Recipe: how far a run's bottom may lie above its seat (used when PositionAboveSet is "
     "ticked; otherwise PositionTolerance)"),
    ("Rules", "App::PropertyEnumeration", "rules",
     "Recipe: waferscan (a run by its bottom edge, SPEC §4) or boundary (by its centre and the "
     "slot boundaries, SPEC §11)"),
    ("ThicknessCorrection", "App::PropertyFloat", "thickness_correction",
     "Recipe: measured diffs are divided by this before they are judged (calibration)"),
)

# The box beside each recipe limit, as (property, limit property, tooltip).
RECIPE_SET_PROPERTIES = tuple(
    (f"{prop}Set", prop, f"Recipe: ticked, {prop} is this recipe's limit; not ticked, it is not "
     "set and SPEC §4's rule applies") for prop, kind, _, _ in RECIPE_PROPERTIES
    if kind == "App::PropertyLength")

SETTINGS += tuple(RoleProperty(name, kind, _UNITS[name], tip)
                  for name, kind, _, tip in SENSOR_PROPERTIES + SLOW_SCAN_PROPERTIES)
SETTINGS += (RoleProperty("Latch", "App::PropertyEnumeration", "", LATCH_TIP),)
SETTINGS += tuple(RoleProperty(name, kind, "" if key in ("rules", "thickness_correction")
                               else "mm", tip) for name, kind, key, tip in RECIPE_PROPERTIES)
SETTINGS += tuple(RoleProperty(name, "App::PropertyBool", "", tip)
                  for name, _, tip in RECIPE_SET_PROPERTIES)

# Times and the wrist's rates are App::PropertyFloat with their unit in the name, as FreeCAD
# has no property for them in both versions: 0.20.2 has no App::PropertyTime (1.0 has), and
# neither has an angular speed or acceleration (an App::PropertyQuantity's unit is not saved
# with the document). Times are in ms, not s: the property editor shows a float with the unit
# schema's decimals (2 by default), which would show a 0.25 ms response as "0.00" s.
# {property: how many of its unit make one of the core's (s for times)}.
PER_CORE_UNIT = {"SensorResponseMs": 1000.0, "SamplePeriodMs": 1000.0}
# The names these properties had before (documents saved until then: features.ScanSettings
# migrates them on open), which are also their keywords in recorded lines (sample_period=...).
PLAIN_NAMES = {"SensorResponseMs": "SensorResponse", "SamplePeriodMs": "SamplePeriod",
               "WristSpeedDegPerS": "WristSpeed", "WristAccelerationDegPerS2": "WristAcceleration"}


def to_property(prop, value):
    """The value a property holds for a core value (a time in s becomes ms)."""
    return value * PER_CORE_UNIT.get(prop, 1.0)


def from_property(prop, value):
    """The core value of what a property holds (or a quantity's Value): ms become s."""
    return float(getattr(value, "Value", value)) / PER_CORE_UNIT.get(prop, 1.0)


BY_ROLE = {"Wafer": (), "Carrier": CARRIER, "Scanner": SCANNER, "Robot": ROBOT,
           "ScanSettings": SETTINGS}


def property_named(role_properties, name):
    """The RoleProperty called ``name`` in a role's table."""
    return next(p for p in role_properties if p.name == name)
