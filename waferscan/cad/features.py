"""The document objects WaferScan builds: a carrier body with slot supports, the scanner's beam
and the scan settings. Each is a FeaturePython whose proxy only rebuilds its shape from its
properties; everything it knows lives in properties, so it survives save and reload.

Proxy state, FreeCAD quirk: 0.20 saves a proxy through ``__getstate__``/``__setstate__``, 0.21
and later prefer ``dumps``/``loads``. Both are defined here, once, in ``_Proxy``.

Versions (as freecad.gears does): each object carries the version of its proxy's properties
(``WaferScanVersion``). When a proxy's properties change, raise its ``version`` and add to its
``migrations`` the step that brings an object saved at the version before up to date; opening
a document runs the steps its objects need (``_Proxy.onDocumentRestored``).
"""

from __future__ import annotations

import FreeCAD as App
import Part

from ..core.geometry.carrier_body import carrier_boxes
from ..core.model import DIRECTIONS, MODES
from . import roles
from .role_properties import PLAIN_NAMES, PER_CORE_UNIT, SETTINGS, property_named, to_property


def object_name(text):
    """The FreeCAD object name ``text`` becomes: ASCII letters, digits and underscores, not
    starting with a digit (what FreeCAD itself would make of it)."""
    name = "".join(c if (c.isascii() and c.isalnum()) or c == "_" else "_" for c in text)
    return name if name and not name[0].isdigit() else "_" + name


def add_named(doc, kind, label):
    """``doc.addObject(kind, ...)`` under a name made from ``label``, labelled ``label``.

    FreeCAD quirk (FREECAD-NOTES): an object name already taken makes ``addObject`` search
    every object for a free one: O(n) a call, O(n^2) for a layout (10,000 wafers took minutes).
    A layout's labels are unique, so the names made from them are too, but for labels that differ
    only in characters a name cannot have. (The other O(n) search, of every label, is what
    ``builder.unchecked_labels`` turns off.)"""
    name = object_name(label)
    # A taken name (two labels making one name, a document built into twice) falls back on
    # FreeCAD's own search, slow but correct.
    obj = doc.addObject(kind, name)
    if obj.Label != label:
        obj.Label = label
    return obj


# The GUI's view providers (an icon per role), given by the GUI layer when it is up, as Draft
# attaches its own only then; this layer does not import the GUI. None: FreeCAD's default.
view_provider = None
# FreeCAD quirk: a document saved without a GUI opens in the GUI with every object hidden. The
# GUI layer gives here how to show what the file says is visible.
show_saved_visibility = None


def _give_view_provider(obj, restored=False):
    if not App.GuiUp or obj.ViewObject is None or obj.ViewObject.Proxy:
        return
    if restored and obj.ViewObject.Proxy is None and show_saved_visibility is not None:
        show_saved_visibility(obj.Document)  # saved without a GUI: no view data in the file
    if view_provider is not None and view_provider(obj):
        return
    if obj.ViewObject.Proxy is None:
        # FreeCAD quirk: a FeaturePython made in a GUI session is drawn only once its view
        # object has a proxy; 0 asks for the default view provider.
        obj.ViewObject.Proxy = 0


VERSION_PROPERTY = "WaferScanVersion"


def saved_version(obj):
    """The version of its proxy's properties the object was made or last migrated at; 0 for one
    saved before objects carried a version."""
    return getattr(obj, VERSION_PROPERTY, 0) if VERSION_PROPERTY in obj.PropertiesList else 0


def _set_version(obj, version):
    roles.add_property(obj, "App::PropertyInteger", VERSION_PROPERTY,
                       "Version of WaferScan's properties on this object (for migrations)")
    obj.setEditorMode(VERSION_PROPERTY, 2)  # hidden: the user has nothing to do with it
    if getattr(obj, VERSION_PROPERTY) != version:
        setattr(obj, VERSION_PROPERTY, version)


def rename_property(obj, old, new):
    """A migration step: the property ``old`` becomes ``new`` (same type, group and tooltip),
    keeping its value; nothing happens when ``old`` is gone already."""
    if old not in obj.PropertiesList:
        return
    if new not in obj.PropertiesList:
        obj.addProperty(obj.getTypeIdOfProperty(old), new, obj.getGroupOfProperty(old),
                        obj.getDocumentationOfProperty(old))
        if obj.getTypeIdOfProperty(old) == "App::PropertyEnumeration":
            setattr(obj, new, obj.getEnumerationsOfProperty(old))
    setattr(obj, new, getattr(obj, old))
    obj.removeProperty(old)


class _Proxy:
    """Base of WaferScan's feature proxies: a type to save, and the version of its properties.

    ``version``: raise it when the subclass's properties change. ``migrations``: {version: step}
    where ``step(obj)`` brings an object saved at ``version`` to ``version + 1``."""

    version = 1
    migrations = {}

    def __init__(self, obj):
        obj.Proxy = self
        _set_version(obj, self.version)
        _give_view_provider(obj)

    def migrate(self, obj):
        """Bring an object saved at an older version up to this proxy's (run on restore)."""
        saved = saved_version(obj)
        for version in range(saved, self.version):
            step = self.migrations.get(version)
            if step is not None:
                step(obj)
        if saved != self.version:
            _set_version(obj, self.version)

    def dumps(self):
        return {"type": type(self).__name__}

    def loads(self, state):
        return None

    __getstate__ = dumps
    __setstate__ = loads

    def onDocumentRestored(self, obj):
        obj.Proxy = self
        self.migrate(obj)
        # A document built headless has no view providers saved: the GUI gives them now.
        _give_view_provider(obj, restored=True)


def carrier_solids(slot_count, pitch, wafer_diameter, support_span):
    """A FOUP-like body in the carrier's frame (origin at slot 1's seat centre, X across, -Y out
    of the opening, Z up): side walls, back wall, floor, roof, and a left and a right support
    ledge under every slot whose inner edges are ``support_span`` apart; the boxes of
    ``core.geometry.carrier_body.carrier_boxes``, which the clearance check of a scenario
    scanned without its document takes too."""
    return Part.makeCompound([Part.makeBox(*size, App.Vector(*corner))
                              for _, corner, size in carrier_boxes(slot_count, pitch,
                                                                   wafer_diameter, support_span)])


class CarrierBody(_Proxy):
    """A carrier (FOUP or cassette) whose shape follows its slot properties."""

    def execute(self, obj):
        obj.Shape = carrier_solids(obj.SlotCount, float(obj.Pitch), float(obj.WaferDiameter),
                                   float(obj.SupportSpan))


class ScannerBeam(_Proxy):
    """The through-beam: a thin rod from emitter to receiver with a small head at each end."""

    def execute(self, obj):
        emitter, receiver = App.Vector(obj.Emitter), App.Vector(obj.Receiver)
        direction = receiver - emitter
        length = direction.Length
        if length == 0.0:
            obj.Shape = Part.Shape()
            return
        direction.normalize()
        rod = Part.makeCylinder(0.4, length, emitter, direction)
        heads = [Part.makeSphere(3.0, p) for p in (emitter, receiver)]
        obj.Shape = Part.makeCompound([rod] + heads)


RANGE_FROM_CARRIER = "RangeFromCarrier"
RANGE_FROM_CARRIER_TIP = ("True: StartZ and FinalZ follow the scanned carrier's slots (slot 1's "
                          "seat - pitch/2 to the top slot's seat + pitch/2) at every scan; "
                          "setting StartZ or FinalZ yourself turns it off")
_following = []  # non-empty while WaferScan itself writes a range that follows the carrier


class following_carrier:  # noqa: N801 (used as a ``with`` block)
    """WaferScan writes StartZ and FinalZ from the carrier: not the user setting the range."""

    def __enter__(self):
        _following.append(True)

    def __exit__(self, *exc):
        _following.pop()


# What version 1 of ScanSettings held as a float: the thickness tolerance in mm, a negative
# value meaning "half the nominal wafer thickness".
OLD_HALF_THICKNESS = -1.0


def _units_and_not_set(obj):
    """ScanSettings' migration 1 -> 2 (issue 27 item 13): the times become ms with the unit in
    their name (SensorResponse in s -> SensorResponseMs, SamplePeriod -> SamplePeriodMs), the
    wrist's rates name theirs (WristSpeed -> WristSpeedDegPerS, WristAcceleration ->
    WristAccelerationDegPerS2), and ThicknessTolerance, a float in mm whose negative value meant
    half the thickness, becomes a length with ThicknessToleranceSet beside it. What the document
    scans is unchanged."""
    for new, old in PLAIN_NAMES.items():
        if old not in obj.PropertiesList or new in obj.PropertiesList:
            continue
        value = float(getattr(obj, old)) * PER_CORE_UNIT.get(new, 1.0)
        obj.removeProperty(old)
        prop = property_named(SETTINGS, new)
        roles.add_property(obj, prop.kind, new, prop.tip, value)
    if "ThicknessTolerance" in obj.PropertiesList and \
            obj.getTypeIdOfProperty("ThicknessTolerance") == "App::PropertyFloat":
        old = float(obj.ThicknessTolerance)
        obj.removeProperty("ThicknessTolerance")
        _add_thickness_tolerance(obj, None if old < 0.0 else old)


def _add_thickness_tolerance(obj, tolerance):
    """ThicknessTolerance (mm) and ThicknessToleranceSet: None is half the wafer thickness."""
    for name, value in (("ThicknessTolerance", tolerance or 0.0),
                        ("ThicknessToleranceSet", tolerance is not None)):
        prop = property_named(SETTINGS, name)
        roles.add_property(obj, prop.kind, name, prop.tip, value)


class ScanSettings(_Proxy):
    """The scan's parameters and mapping tolerances, stored in the document. A range that
    follows the carrier (RangeFromCarrier) stops following it once the user sets it."""

    version = 2
    migrations = {1: _units_and_not_set}

    def onChanged(self, obj, prop):  # noqa: N802 (FreeCAD's name)
        if (prop in ("StartZ", "FinalZ") and not _following
                and RANGE_FROM_CARRIER in obj.PropertiesList and obj.RangeFromCarrier
                and "Restore" not in obj.State  # opened from a file
                and not getattr(obj.Document, "Transacting", False)):  # an undo or redo
            obj.RangeFromCarrier = False


class Wafer(_Proxy):
    """A flat wafer: the disc of its Radius and Height, placed by its Placement as a
    Part::Cylinder is (origin at its bottom face's centre, Z its normal). A Python feature
    rather than a Part::Cylinder so that the tree shows it with the wafer's icon: FreeCAD 0.20
    lets Python give a view provider (and so an icon) only to Python features."""

    def execute(self, obj):
        obj.Shape = Part.makeCylinder(float(obj.Radius), float(obj.Height))


def make_wafer(doc, label, radius, thickness, proxy=Wafer):
    """A wafer object labelled ``label`` with a Part::Cylinder's ``Radius`` and ``Height``
    (``proxy``: ``Wafer`` for a flat one, ``BowedWafer`` for a bowed one); the caller places it
    and gives it its role."""
    obj = add_named(doc, "Part::FeaturePython", label)
    for name, value, tip in (("Radius", radius, "Radius of the wafer's rim"),
                             ("Height", thickness, "Thickness of the wafer along its normal")):
        obj.addProperty("App::PropertyLength", name, "Wafer", tip)
        setattr(obj, name, value)
    proxy(obj)
    return obj


def make_carrier(doc, name, slot_count, pitch, wafer_diameter, wafer_thickness, support_span):
    obj = add_named(doc, "Part::FeaturePython", name)
    CarrierBody(obj)
    roles.tag_carrier(obj, slot_count, pitch, wafer_diameter, wafer_thickness, support_span)
    return obj


def make_scanner(doc, length, lift_axis=(0.0, 0.0, 1.0)):
    """A scanner whose beam runs along its local +X from its origin, ``length`` long."""
    obj = doc.addObject("Part::FeaturePython", "Scanner")
    ScannerBeam(obj)
    roles.tag_scanner(obj, (0.0, 0.0, 0.0), (length, 0.0, 0.0), lift_axis)
    return obj


SETTINGS_PROPERTIES = (
    # (property, kind, scan or mapping field, tooltip)
    ("StartZ", "App::PropertyDistance", "start_z", "Scan position (emitter Z) of the first step"),
    ("FinalZ", "App::PropertyDistance", "final_z", "Scan position of the last step"),
    ("ZStep", "App::PropertyLength", "z_step", "Step between scan positions; 0 for exact edges"),
    ("ScanSpeed", "App::PropertySpeed", "scan_speed", "Speed of a fast scan"),
    ("SensorResponseMs", "App::PropertyFloat", "sensor_response",
     property_named(SETTINGS, "SensorResponseMs").tip),
    ("PositionTolerance", "App::PropertyLength", "position_tolerance", "Slot position tolerance"),
    ("ProtrusionLimit", "App::PropertyLength", "protrusion_limit", "Protrusion limit"),
    ("ClearanceMin", "App::PropertyLength", "clearance_min",
     "Least distance the robot may come to a wafer along any motion of the scan (SPEC 15)"),
)


def make_settings(doc, scan, mapping, carrier, range_from_carrier=False):
    """The scan settings object, filled from core ScanParameters and MappingTolerances;
    ``range_from_carrier``: its range follows the carrier's slots until the user sets it."""
    obj = doc.addObject("App::FeaturePython", "ScanSettings")
    ScanSettings(obj)
    roles.set_role(obj, roles.SETTINGS)
    for prop, kind, field, tip in SETTINGS_PROPERTIES:
        source = mapping if hasattr(mapping, field) else scan
        roles.add_property(obj, kind, prop, tip, to_property(prop, getattr(source, field)))
    roles.add_property(obj, "App::PropertyEnumeration", "Mode", "fast: one stroke; slow: pocket "
                       "by pocket")
    obj.Mode = list(MODES)
    obj.Mode = scan.mode
    roles.add_property(obj, "App::PropertyEnumeration", "Direction", "Direction of a fast scan")
    obj.Direction = list(DIRECTIONS)
    obj.Direction = scan.direction
    _add_thickness_tolerance(obj, mapping.thickness_tolerance)
    roles.add_property(obj, "App::PropertyString", "Carrier", "Name (label) of the carrier to scan",
                       carrier or "")
    if range_from_carrier:
        roles.add_property(obj, "App::PropertyBool", RANGE_FROM_CARRIER, RANGE_FROM_CARRIER_TIP,
                           True)
    from . import slow_scan_properties  # SPEC §13: Jab, Sweep and the arm's motion

    slow_scan_properties.add_to(obj, scan)
    from . import recipe_properties  # SPEC §11: the mapping recipe

    recipe_properties.add_to(obj, mapping)
    return obj
