"""Scenario -> FreeCAD document: carriers as solids with slot supports, each with its wafers in
an App::Part placed at the carrier's slot 1 seat; the scanner; the scan settings."""

from __future__ import annotations

import math
from contextlib import contextmanager

import FreeCAD as App

from . import features, roles, sensor_properties


def carrier_placement(carrier):
    """Placement of a carrier's frame: origin at slot 1's seat centre, -Y along ``front``."""
    fx, fy = carrier.front
    angle = math.degrees(math.atan2(fx, -fy))
    return App.Placement(App.Vector(carrier.center[0], carrier.center[1], carrier.first_slot_z),
                         App.Rotation(App.Vector(0, 0, 1), angle))


def wafer_placement(wafer):
    """A wafer object's placement (a Part::Cylinder's): origin at its bottom-face centre, Z its
    normal."""
    return App.Placement(App.Vector(*wafer.center),
                         App.Rotation(App.Vector(0, 0, 1), App.Vector(*wafer.normal)))


def beam_placement(beam):
    """Placement of a scanner whose beam runs along local +X from its origin."""
    return App.Placement(App.Vector(*beam.emitter),
                         App.Rotation(App.Vector(1, 0, 0), App.Vector(*beam.direction)))


@contextmanager
def document_preference_on(name):
    """FreeCAD's boolean preference Document/``name`` turned on for the block, and put back as
    it was afterwards (removed again when it was not set)."""
    group = App.ParamGet("User parameter:BaseApp/Preferences/Document")
    was_set = name in group.GetBools()
    before = group.GetBool(name)
    group.SetBool(name, True)
    try:
        yield
    finally:
        if was_set:
            group.SetBool(name, before)
        else:
            group.RemBool(name)


@contextmanager
def unchecked_labels():
    """FreeCAD quirk: every label set, ``addObject``'s own included, compares the new label with
    every other object's unless the preference Document/DuplicateLabels is on: O(n) an object.
    Turned on while WaferScan builds a layout, whose labels are unique already (the scenario
    checks its names), and put back as it was afterwards."""
    with document_preference_on("DuplicateLabels"):
        yield


def add_wafer(doc, wafer, container=None, frame=None):
    """A wafer with the wafer role, placed as a Part::Cylinder is: a flat one as a
    ``features.Wafer``, a bowed one as a BowedWafer, drawn bowed; ``frame`` is the container's
    placement."""
    if wafer.bow:
        from .bowed_solid import make_bowed_wafer

        obj = make_bowed_wafer(doc, wafer.name, wafer.radius, wafer.thickness)
    else:
        obj = features.make_wafer(doc, wafer.name, wafer.radius, wafer.thickness)
    placement = wafer_placement(wafer)
    obj.Placement = placement if frame is None else frame.inverse().multiply(placement)
    roles.set_role(obj, roles.WAFER)
    if wafer.bow:
        # SPEC §10: Radius, Height and Placement as a cylinder's, the bow a property of its
        # own; the BowedWafer's shape is the solid of revolution they make (cad/bowed_solid.py).
        roles.add_property(obj, "App::PropertyDistance", "Bow", "Height of the wafer's centre "
                           "above its rim (paraboloid bow; negative: centre down)", wafer.bow)
    if container is not None:
        container.addObject(obj)
    return obj


def build_document(layout, name="WaferScanLayout", doc=None):
    """A new (or the given) document holding the layout. Returns the document, recomputed."""
    if layout.robot is not None:
        from ..addon import require_pinocchio

        require_pinocchio()  # without pinocchio, stop before the document exists, not half-way
    with unchecked_labels():
        return _build(layout, name, doc)


def _build(layout, name, doc):
    doc = doc or App.newDocument(name)
    settings = features.make_settings(doc, layout.scan, layout.mapping, layout.carrier)
    sensor_properties.add_sensor_properties(settings, layout)  # SPEC §10
    # The assemblies first, while the document is small: each App::Part makes an origin whose
    # six features FreeCAD names itself (X_Axis, ...), searching every object's name for a free
    # one. With the wafers already there, 400 carriers took 1.5 s of that search.
    parts = [features.add_named(doc, "App::Part", f"{c.name} assembly") for c in layout.carriers]
    assemblies = {}
    for carrier, assembly in zip(layout.carriers, parts):
        frame = carrier_placement(carrier)
        assembly.Placement = frame
        body = features.make_carrier(doc, carrier.name, carrier.slot_count, carrier.pitch,
                                     carrier.wafer_diameter, carrier.wafer_thickness,
                                     carrier.support_span)
        assembly.addObject(body)
        assemblies[carrier.name] = (assembly, frame)
    # The wafers in the layout's order, so that the document reads back in the input's order
    # (a free wafer that names a carrier goes into its assembly but keeps its place).
    for wafer in layout.wafers:
        if wafer.carrier in assemblies:
            add_wafer(doc, wafer, *assemblies[wafer.carrier])
        else:
            add_wafer(doc, wafer)
    if layout.robot is not None:
        from .robot import build_robot  # pinocchio is imported only when a robot is there
        build_robot(doc, layout.robot, layout.beam, layout.lift_axis)
    else:
        scanner = features.make_scanner(doc, layout.beam.length, layout.lift_axis)
        scanner.Placement = beam_placement(layout.beam)
    doc.recompute()
    return doc
