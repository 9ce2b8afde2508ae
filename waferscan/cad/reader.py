"""FreeCAD document -> core ``Layout``, through the global placements of what the 3D view shows.

A wafer's centre, normal, diameter and thickness come from its solid (a whole cylinder's
from its properties when it has no shape: ``cylinder_read``); a carrier's slots from its
properties and the placement of its slot origin; the beam from the scanner's emitter and
receiver; the scan parameters from the ScanSettings object (defaults when there is none).
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass

import FreeCAD as App
import Part

from ..core import schema
from ..core.errors import InputError
from ..core.files import validation
from ..core.model import Beam, Carrier, Layout, MappingTolerances, ScanParameters, Wafer, unit
from ..core.rules import (SEVERAL_CARRIERS, carrier_choice_problem, slots_scan_range,
                          thickness_tolerance_from_stored)
from . import roles
from .disc import NotADisc, bowed_disc_of, cylinder_disc, disc_of, whole_disc_of
from .features import RANGE_FROM_CARRIER, SETTINGS_PROPERTIES
from .features import Wafer as FlatWafer
from .role_properties import SENSOR_PROPERTIES, SLOW_SCAN_PROPERTIES, from_property
from .scene import scene_instances
from .sensor_properties import read_sensor_settings


def _value(quantity):
    return float(getattr(quantity, "Value", quantity))


def document_source(doc):
    """How error messages name a document: its file, or its name when it was never saved."""
    return doc.FileName or doc.Name


@dataclass(frozen=True)
class DocumentScene:
    """The role-carrying instances of a document, found once."""

    doc: object
    wafers: tuple
    carriers: tuple
    scanners: tuple
    robots: tuple
    settings: tuple

    @classmethod
    def of(cls, doc):
        found = {role: [] for role in roles.ROLES}
        for instance in scene_instances(doc):
            role = roles.role_of(instance.obj)
            if role is not None:
                found[role].append(instance)
        # Wafers in the order they were made (a scenario's order, SPEC §7's JSON ``wafers``),
        # not grouped by the container they sit in; instances of one object keep tree order.
        made = {obj.Name: i for i, obj in enumerate(doc.Objects)}
        found[roles.WAFER].sort(key=lambda instance: made.get(instance.obj.Name, len(made))
                                if instance.obj.Document == doc else len(made))
        return cls(doc, *(tuple(found[r]) for r in (roles.WAFER, roles.CARRIER, roles.SCANNER,
                                                     roles.ROBOT, roles.SETTINGS)))

    def error(self, message):
        return InputError(document_source(self.doc), None, message)

    def scanner(self):
        if len(self.scanners) != 1:
            names = ", ".join(i.path for i in self.scanners) or "none"
            raise self.error(f"expected one visible scanner, found {len(self.scanners)} ({names})")
        return self.scanners[0]


def wafer_from(instance, name):
    """The core Wafer of a wafer instance, from its global shape: a flat disc, or the bowed
    solid of its ``Bow`` (SPEC §10; a flat disc with a Bow property, as documents made before
    bowed wafers were drawn bowed, reads the same)."""
    holder = roles.role_holder(instance.obj)
    bow = _value(holder.Bow) if "Bow" in holder.PropertiesList else 0.0  # SPEC §10
    reading = cylinder_read(instance)
    if reading is not None:
        center, normal, diameter, thickness = reading
        return Wafer(name=name, center=center, normal=normal, diameter=diameter,
                     thickness=thickness, bow=bow)
    shape = instance.shape()
    try:
        try:
            center, normal, diameter, thickness = disc_of(shape)
        except NotADisc:
            if not bow:
                raise
            center, normal, diameter, thickness = bowed_disc_of(shape, bow)
    except NotADisc as exc:
        raise InputError(document_source(instance.root.Document), None,
                         f"{instance.path} is tagged as a wafer but {exc}") from None
    return Wafer(name=name, center=center, normal=normal, diameter=diameter,
                 thickness=thickness, bow=bow)


_STALE = {"Invalid", "Error"}  # a recompute failed: what the properties say was never made


def cylinder_read(instance):
    """(center, normal, diameter, thickness) of a wafer instance that is a whole cylinder (a
    Part::Cylinder of 360°, not skewed; a flat WaferScan wafer), read without ``disc_of``'s
    volume integration: off its B-rep when it has one (``disc.whole_disc_of``: the same
    floats), else from its properties (``disc.cylinder_disc``: the floats of the B-rep a
    recompute would give it; a layout saved without the wafers' shapes). None when it is no
    such cylinder, or when without a B-rep it is one that the properties do not place simply
    (through a link, nested deeper than one App::Part, or left in error by a recompute):
    ``disc_of`` reads or refuses it then.

    Why not from the properties when there is a B-rep: FreeCAD 0.20 writes a Placement's
    quaternion with 16 decimals, which does not give back every component below 0.1 (a tilted
    wafer's), while the B-rep keeps its transform exactly: reopened, such a wafer's Placement
    is up to ~1e-17 off the one its B-rep was placed by, and the two readings differ in the
    last bits."""
    holder = instance.target
    kind = holder.TypeId
    if kind == "Part::Cylinder":
        # Angle: a sector; FirstAngle/SecondAngle (0.20+): the ends skewed, a slanted prism.
        skews = [p for p in ("FirstAngle", "SecondAngle") if p in holder.PropertiesList]
        if float(holder.getPropertyByName("Angle")) != 360.0 or any(
                float(holder.getPropertyByName(p)) != 0.0 for p in skews):
            return None
    elif kind != "Part::FeaturePython" or type(getattr(holder, "Proxy", None)) is not FlatWafer:
        return None
    radius = float(holder.getPropertyByName("Radius"))
    height = float(holder.getPropertyByName("Height"))
    if not (radius > 0.0 and height > 0.0):
        return None  # disc_of names what is wrong
    try:
        shape = Part.getShape(instance.root, instance.sub)
    except ReferenceError:
        return None  # gone: instance.shape() says so
    if not shape.isNull():
        try:
            return whole_disc_of(shape)
        except NotADisc:
            return None  # not a disc once placed (a link's scale): disc_of says why
    obj, sub = instance.obj, instance.sub
    if obj is not holder or _STALE.intersection(obj.State):
        return None
    if not sub:
        frame = None
    elif sub == obj.Name + "." and instance.root.TypeId == "App::Part":
        frame = instance.root.getPropertyByName("Placement").toMatrix()
    else:
        return None
    return cylinder_disc(radius, height, obj.getPropertyByName("Placement").toMatrix(), frame)


def carrier_from(instance):
    """The core Carrier of a carrier instance: its slots from its role's properties (those of
    the object the role is on, the link's target for a link), placed where the instance is."""
    role_object = roles.role_holder(instance.obj)
    anchor = instance.placement().multiply(role_object.SlotOrigin)
    back = anchor.Rotation.multVec(App.Vector(0, 1, 0))
    norm = math.hypot(back.x, back.y) or float("nan")  # standing on edge: validation refuses
    label = role_object.Label if instance.obj is role_object else instance.obj.Label
    try:
        schema.carrier_name(label)
    except ValueError as exc:
        raise InputError(document_source(instance.root.Document), None,
                         f"{instance.path}: {exc}; rename it") from None
    return Carrier(
        name=label,
        slot_count=int(role_object.SlotCount), pitch=_value(role_object.Pitch),
        first_slot_z=anchor.Base.z, center=(anchor.Base.x, anchor.Base.y),
        wafer_diameter=_value(role_object.WaferDiameter),
        wafer_thickness=_value(role_object.WaferThickness),
        front=(-back.x / norm, -back.y / norm), support_span=_value(role_object.SupportSpan))


def beam_from(instance, ends=None):
    """The beam of a scanner instance, in global coordinates, as its placement in the document
    puts it now; an InputError when its emitter and receiver coincide. ``ends``: the scanner's
    (Emitter, Receiver) when read once for a whole scan (each read of a vector property leaks a
    little in FreeCAD 0.20)."""
    if ends is None:
        holder = roles.role_holder(instance.obj)
        ends = (App.Vector(holder.Emitter), App.Vector(holder.Receiver))
    placement = instance.placement()
    emitter = placement.multVec(ends[0])
    receiver = placement.multVec(ends[1])
    length = (receiver - emitter).Length
    if length == 0.0:
        raise InputError(document_source(instance.root.Document), None,
                         f"{instance.path}: the beam's emitter and receiver coincide")
    try:
        direction = unit(receiver - emitter)
    except ValueError:  # non-finite Emitter or Receiver: validation names the property
        direction = (math.nan,) * 3
    return Beam((emitter.x, emitter.y, emitter.z), direction, length)


def _unique_names(instances):
    """Each wafer's name: its label, or its path where several share the label. Counted once
    (``list.count`` per wafer was O(n^2))."""
    labels = [i.obj.Label for i in instances]
    counts = Counter(labels)
    return [label if counts[label] == 1 else i.path for label, i in zip(labels, instances)]


def _settings(scene, beam, carriers):
    """Scan parameters, mapping tolerances and scanned carrier from the ScanSettings object."""
    if len(scene.settings) > 1:
        raise scene.error("more than one ScanSettings object")
    if not scene.settings:
        top = max((c.seat_z(c.slot_count) + c.pitch for c in carriers), default=beam.emitter[2])
        return (ScanParameters(start_z=beam.emitter[2], final_z=max(top, beam.emitter[2])),
                MappingTolerances(), None)
    obj = roles.role_holder(scene.settings[0].obj)
    values = {}
    checks = {**schema.SCAN_KEYS, **schema.MAPPING_KEYS}
    for prop, _, field, _ in SETTINGS_PROPERTIES:
        if prop in obj.PropertiesList:
            try:  # a value typed into the property editor is checked as a scenario's would be
                values[field] = checks[field](from_property(prop, getattr(obj, prop)))
            except ValueError as exc:
                raise scene.error(f"{obj.Label}.{prop}: {exc}") from None
    followed = _followed_carrier(obj, carriers)
    if followed is not None:  # the range follows the carrier until the user sets it
        values["start_z"], values["final_z"] = slots_scan_range(followed)
    try:
        schema.check_scan_range(values.get("start_z", 0.0), values.get("final_z", 0.0),
                                values.get("z_step", 0.0))
    except ValueError as exc:
        raise scene.error(f"{obj.Label}: {exc}") from None
    scan = ScanParameters(**{k: v for k, v in values.items()
                             if k in ScanParameters.__dataclass_fields__},
                          mode=obj.Mode, direction=obj.Direction)
    from . import slow_scan_properties  # SPEC §13: Jab, Sweep and the arm's motion

    scan = slow_scan_properties.read(obj, scan, scene.error)
    tolerance = None  # not set: half the nominal wafer thickness (SPEC §4)
    if "ThicknessToleranceSet" not in obj.PropertiesList:  # not migrated (features.ScanSettings)
        tolerance = thickness_tolerance_from_stored(float(obj.ThicknessTolerance))
    elif obj.ThicknessToleranceSet:
        try:
            tolerance = schema.MAPPING_KEYS["thickness_tolerance"](
                float(obj.ThicknessTolerance))
        except ValueError as exc:
            raise scene.error(f"{obj.Label}.ThicknessTolerance: {exc}") from None
    mapping = MappingTolerances(thickness_tolerance=tolerance,
                                **{k: v for k, v in values.items()
                                   if k in MappingTolerances.__dataclass_fields__})
    from . import recipe_properties  # SPEC §11: the mapping recipe

    mapping = recipe_properties.read(obj, mapping, scene.error)
    return scan, mapping, obj.Carrier or None


def _followed_carrier(obj, carriers):
    """The carrier whose slots a ScanSettings object's range follows (RangeFromCarrier on), or
    None: off, or which carrier is not clear (read_layout says so)."""
    if not getattr(obj, RANGE_FROM_CARRIER, False):
        return None
    chosen = [c for c in carriers if c.name == obj.Carrier] if obj.Carrier else carriers
    return chosen[0] if len(chosen) == 1 else None


def read_layout(doc, scene=None):
    """The document's layout as a core ``Layout``."""
    scene = scene or DocumentScene.of(doc)
    scanner = scene.scanner()
    beam = beam_from(scanner)
    lift_axis = tuple(App.Vector(roles.role_holder(scanner.obj).LiftAxis))
    carriers = [carrier_from(i) for i in scene.carriers]
    _check_values(scene, scanner, carriers, beam, lift_axis)
    lift_axis = unit(lift_axis)
    wafers = [wafer_from(i, name) for i, name in zip(scene.wafers, _unique_names(scene.wafers))]
    scan, mapping, chosen = _settings(scene, beam, carriers)
    names = [c.name for c in carriers]
    if not carriers:
        raise scene.error("no carrier: tag one with the carrier role")
    problem = carrier_choice_problem(names, chosen)
    if problem == SEVERAL_CARRIERS:
        raise scene.error(f"several carriers ({', '.join(names)}): set ScanSettings.Carrier")
    if problem:
        raise scene.error(f"ScanSettings.Carrier is {chosen!r}, but the carriers are "
                          f"{', '.join(names)}")
    # The scan starts at StartZ: the beam as it stands is moved along the lift axis to there.
    travel = (scan.start_z - beam.emitter[2]) / lift_axis[2]
    emitter = tuple(e + travel * a for e, a in zip(beam.emitter, lift_axis))
    beam = Beam((emitter[0], emitter[1], scan.start_z), beam.direction, beam.length)
    layout = Layout(carriers=tuple(carriers), wafers=tuple(wafers), beam=beam, scan=scan,
                    lift_axis=lift_axis, mapping=mapping, carrier=chosen or names[0])
    layout = read_sensor_settings(scene, layout)  # SPEC §10: spot, thresholds, latch
    _check_values(scene, scanner, carriers, beam, lift_axis, layout)
    return layout


# The properties that hold validation.Problem keys: a carrier's, the scanner's, ScanSettings'.
_CARRIER_PROPERTIES = {"slots": "SlotCount", "pitch": "Pitch", "wafer_diameter": "WaferDiameter",
                       "wafer_thickness": "WaferThickness", "support_span": "SupportSpan",
                       "first_slot_z": "SlotOrigin", "center": "SlotOrigin",
                       "front": "SlotOrigin"}
_SCANNER_PROPERTIES = {"emitter": "Emitter", "direction": "Receiver", "length": "Receiver",
                       "lift_axis": "LiftAxis"}


def _check_values(scene, scanner, carriers, beam, lift_axis, layout=None):
    """validation.layout_problems on what was read, the first problem named by the object and
    property it came from. Before the layout is whole (``layout`` None) only the carriers and
    the beam are checked: the rest of the reading needs them sound."""
    if layout is None:
        problems = [p for i, c in enumerate(carriers) for p in validation.carrier_problems(c, i)]
        problems += validation.beam_problems(beam, lift_axis)
    else:
        problems = validation.layout_problems(layout)
    if not problems:
        return
    key, message, index, group = problems[0]
    if group == "carrier" and index is not None and index < len(scene.carriers):
        holder = roles.role_holder(scene.carriers[index].obj)
        raise scene.error(f"{holder.Label}.{_CARRIER_PROPERTIES.get(key, key)}: {message}")
    if group == "sensor":
        holder = roles.role_holder(scanner.obj)
        raise scene.error(f"{holder.Label}.{_SCANNER_PROPERTIES.get(key, key)}: {message}")
    if group == "scan" and scene.settings:
        holder = roles.role_holder(scene.settings[0].obj)
        prop = next((p for p, _, field, _ in SETTINGS_PROPERTIES + SENSOR_PROPERTIES
                     + SLOW_SCAN_PROPERTIES if field == key), key)
        raise scene.error(f"{holder.Label}.{prop}: {message}")
    if group == "mapping" and scene.settings:  # SPEC §11's recipe, or SPEC §4's tolerances
        from .recipe_properties import property_of

        holder = roles.role_holder(scene.settings[0].obj)
        prop = property_of(key) or next((p for p, _, field, _ in SETTINGS_PROPERTIES
                                         if field == key), "ThicknessTolerance")
        raise scene.error(f"{holder.Label}.{prop}: {message}")
    if group == "wafer" and index is not None and index < len(scene.wafers):
        raise scene.error(f"{scene.wafers[index].path}: {message}")
    raise scene.error(message)
