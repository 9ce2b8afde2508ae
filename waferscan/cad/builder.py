"""Scenario -> FreeCAD document: carriers as solids with slot supports, each with its wafers in
an App::Part placed at the carrier's slot 1 seat; the scanner; the scan settings."""

from __future__ import annotations

import math

import FreeCAD as App

from . import features, roles


def carrier_placement(carrier):
    """Placement of a carrier's frame: origin at slot 1's seat centre, -Y along ``front``."""
    fx, fy = carrier.front
    angle = math.degrees(math.atan2(fx, -fy))
    return App.Placement(App.Vector(carrier.center[0], carrier.center[1], carrier.first_slot_z),
                         App.Rotation(App.Vector(0, 0, 1), angle))


def wafer_placement(wafer):
    """A Part::Cylinder's placement for a wafer: origin at its bottom-face centre, Z its normal."""
    return App.Placement(App.Vector(*wafer.center),
                         App.Rotation(App.Vector(0, 0, 1), App.Vector(*wafer.normal)))


def beam_placement(beam):
    """Placement of a scanner whose beam runs along local +X from its origin."""
    return App.Placement(App.Vector(*beam.emitter),
                         App.Rotation(App.Vector(1, 0, 0), App.Vector(*beam.direction)))


def add_wafer(doc, wafer, container=None, frame=None):
    """A wafer as a Part::Cylinder with the wafer role; ``frame`` is the container's placement."""
    obj = doc.addObject("Part::Cylinder", "Wafer")
    obj.Label = wafer.name
    obj.Radius = wafer.radius
    obj.Height = wafer.thickness
    placement = wafer_placement(wafer)
    obj.Placement = placement if frame is None else frame.inverse().multiply(placement)
    roles.set_role(obj, roles.WAFER)
    if container is not None:
        container.addObject(obj)
    return obj


def build_document(layout, name="WaferScanLayout", doc=None):
    """A new (or the given) document holding the layout. Returns the document, recomputed."""
    if layout.robot is not None:
        from ..addon import require_pinocchio

        require_pinocchio()  # without pinocchio, stop before the document exists, not half-way
    doc = doc or App.newDocument(name)
    features.make_settings(doc, layout.scan, layout.mapping, layout.carrier)
    carrier_wafers = {c.name: [] for c in layout.carriers}
    loose = []
    for wafer in layout.wafers:
        (carrier_wafers[wafer.carrier] if wafer.carrier in carrier_wafers else loose).append(wafer)
    for carrier in layout.carriers:
        assembly = doc.addObject("App::Part", "CarrierAssembly")
        assembly.Label = f"{carrier.name} assembly"
        frame = carrier_placement(carrier)
        assembly.Placement = frame
        body = features.make_carrier(doc, carrier.name, carrier.slot_count, carrier.pitch,
                                     carrier.wafer_diameter, carrier.wafer_thickness,
                                     carrier.support_span)
        assembly.addObject(body)
        for wafer in carrier_wafers[carrier.name]:
            add_wafer(doc, wafer, assembly, frame)
    for wafer in loose:
        add_wafer(doc, wafer)
    if layout.robot is not None:
        from .robot import build_robot  # pinocchio is imported only when a robot is there
        build_robot(doc, layout.robot, layout.beam)
    else:
        scanner = features.make_scanner(doc, layout.beam.length, layout.lift_axis)
        scanner.Placement = beam_placement(layout.beam)
    doc.recompute()
    return doc
