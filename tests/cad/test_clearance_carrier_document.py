"""SPEC §15 through the document: the scanned carrier's solids read from it (a built carrier's
walls, floor, roof and ledges, each a box; an engineer's own carrier's untagged solids, not its
wafers) and checked with the wafers by every scan through a document.

Hand numbers (tests/robot/test_clearance_carrier.py): the paper's stroke (280 to 550) keeps its
tines (4 mm, from the beam up) 6.06 mm over the floor (top at 273.94) and 4.94 mm under the roof
(558.94); on to 560 they end 4.0 mm inside the roof; from 274.5 to 554.5 they pass 0.44 mm under
it; from 275 to 553 they start 1.06 mm over the floor."""

from dataclasses import replace

import FreeCAD as App
import pytest
from scenarios import PAPER
from waferscan.cad import roles
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import DocumentScene
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import clearance as core


def build_cell(doc):
    """tests/cad/test_own_cell.py's cell: a FOUP (App::Part, its corner at (-10, 30, -5)) of a
    base and two wafers, and a sensor, tagged."""
    foup = doc.addObject("App::Part", "FOUP")
    foup.Placement.Base = App.Vector(-10, 30, -5)
    base = doc.addObject("Part::Box", "Base")
    base.Length, base.Width, base.Height = 340, 360, 5
    foup.addObject(base)
    for name, z in (("W1", 10.0), ("W3", 30.0)):
        wafer = doc.addObject("Part::Cylinder", name)
        wafer.Radius, wafer.Height = 150, 0.775
        wafer.Placement.Base = App.Vector(170, 170, z + 5)
        foup.addObject(wafer)
        doc.recompute()
        roles.tag_wafer(wafer)
    sensor = doc.addObject("Part::Box", "Sensor")
    sensor.Length, sensor.Width, sensor.Height = 160, 4, 4
    sensor.Placement.Base = App.Vector(80, 64.6, -2)
    doc.recompute()
    roles.tag_carrier(foup, slot_count=5, pitch=10.0, slot_origin=foup.Placement.inverse()
                      .multiply(App.Placement(App.Vector(160, 200, 10), App.Rotation())))
    inverse = sensor.Placement.inverse()
    roles.tag_scanner(sensor, tuple(inverse.multVec(App.Vector(70, 66.6, 0))),
                      tuple(inverse.multVec(App.Vector(250, 66.6, 0))))
    doc.recompute()


def _checked(doc):
    return scan_document(doc).clearance


def test_the_paper_carrier_is_read_as_55_boxes_and_clears_the_paper_stroke():
    doc = build_document(read_scenario(PAPER), "CarrierPaper")
    try:
        report = _checked(doc)
        assert report.carrier == "checked: 55 solids of LP1"
        (least,) = report.closest  # the wafers' rims are nearer than the roof
        assert least.distance == pytest.approx(0.6504564, abs=1e-6)
        assert least.obstacle.startswith("LP1_W") and not report.contacts
    finally:
        App.closeDocument(doc.Name)
    layout = read_scenario(PAPER)
    doc = build_document(replace(layout, wafers=()), "CarrierPaperEmpty")
    try:
        (least,) = _checked(doc).closest
        assert least.distance == pytest.approx(4.94, abs=1e-6) and least.exact
        assert least.obstacle == "LP1 roof" and least.position == pytest.approx(550.0)
    finally:
        App.closeDocument(doc.Name)


def test_a_stroke_on_into_the_roof_is_a_contact():
    layout = read_scenario(PAPER)
    layout = replace(layout, wafers=(), scan=replace(layout.scan, final_z=560.0))
    doc = build_document(layout, "CarrierRoof")
    try:
        report = _checked(doc)
        (least,) = report.closest
        assert least.obstacle == "LP1 roof" and least.part.startswith("tine_")
        slack = core.CONTACT_RELATIVE * (0.5 + 4.0)
        assert -4.0 - 1e-6 <= least.distance <= -4.0 + slack
        assert report.contacts == (least,)
    finally:
        App.closeDocument(doc.Name)


def test_a_stroke_inside_the_opening_is_1_06_mm_over_the_floor():
    # Hand: from 275 to 553 the tines start 275 - 273.94 = 1.06 mm over the floor and end
    # 558.94 - 557 = 1.94 mm under the roof.
    layout = read_scenario(PAPER)
    layout = replace(layout, wafers=(), scan=replace(layout.scan, start_z=275.0, final_z=553.0))
    doc = build_document(layout, "CarrierOpening")
    try:
        report = _checked(doc)
        least = report.least
        assert least.distance == pytest.approx(1.06, abs=1e-6) and least.exact
        assert least.obstacle == "LP1 floor" and least.position == pytest.approx(275.0)
        assert not report.contacts
    finally:
        App.closeDocument(doc.Name)


def test_an_own_carrier_is_its_untagged_solids_named_by_label():
    # Its wafers are tagged: obstacles as wafers, not as the carrier's solids.
    # The FOUP's base: X -10..330, Y 30..390, Z -5..0. The sensor's heads (radius 3) at
    # (70, 66.6) and (250, 66.6), over the base, start the stroke at Z = 0 (the cell has no
    # scan settings: the default range), centred on the base's top: 3.0 mm deep in it.
    doc = App.newDocument("CarrierOwnCell")
    try:
        build_cell(doc)
        report = _checked(doc)
        assert report.body == "scanner" and report.carrier == "checked: 1 solid of FOUP"
        (least,) = report.closest
        assert scan_document(doc, clearance=False).layout.scan.start_z == 0.0
        assert least.obstacle == "FOUP Base" and least.part in ("emitter head", "receiver head")
        slack = core.CONTACT_RELATIVE * (1.0 + 3.0)
        assert -3.0 - 1e-6 <= least.distance <= -3.0 + slack and report.contacts == (least,)
    finally:
        App.closeDocument(doc.Name)


def test_a_curved_solid_of_six_faces_and_eight_corners_is_measured_by_its_faces():
    # An extrusion whose top edge is an arc through (50, 20): 6 faces and 8 corners, but not a
    # box; the hull of its corners ends at y = 10, the solid at y = 20. A ball of 0.5 mm at
    # (50, 18, 25) lies inside it: 2 mm under the arc (its tessellation within 0.1 mm).
    import numpy as np
    import Part

    from waferscan.cad.document_scan import _carrier_solids
    from waferscan.robot.clearance import carrier_obstacle

    doc = App.newDocument("CarrierCurved")
    try:
        V = App.Vector
        edges = [Part.LineSegment(V(0, 0, 0), V(100, 0, 0)).toShape(),
                 Part.LineSegment(V(100, 0, 0), V(100, 10, 0)).toShape(),
                 Part.Arc(V(100, 10, 0), V(50, 20, 0), V(0, 10, 0)).toShape(),
                 Part.LineSegment(V(0, 10, 0), V(0, 0, 0)).toShape()]
        solid = Part.Face(Part.Wire(edges)).extrude(V(0, 0, 50))
        assert (len(solid.Faces), len(solid.Vertexes)) == (6, 8)
        wall = doc.addObject("Part::Feature", "Wall")
        wall.Shape = solid
        doc.recompute()
        roles.tag_carrier(wall, slot_count=2, pitch=10.0,
                          slot_origin=App.Placement(V(50, 5, 10), App.Rotation()))
        doc.recompute()
        from types import SimpleNamespace

        from waferscan.cad.reader import carrier_from

        scene = DocumentScene.of(doc)  # a carrier alone: no scanner, so no layout to read
        layout = SimpleNamespace(carrier=carrier_from(scene.carriers[0]).name)
        ((vertices, triangles, name),) = _carrier_solids(scene, layout)
        assert triangles is not None and name == "Wall"  # tessellated, not its corners
        import coal

        geometry, rotation, translation, inside = carrier_obstacle(vertices, triangles)
        request, result = coal.DistanceRequest(), coal.DistanceResult()
        distance = coal.distance(coal.Sphere(0.5),
                                 coal.Transform3s(np.eye(3), np.array([50.0, 18.0, 25.0])),
                                 geometry, coal.Transform3s(rotation, translation), request,
                                 result)
        if inside is not None:  # a mesh: its inside test gives the sign
            distance = -distance if inside(np.array([50.0, 18.0, 25.0])) else distance
        assert distance < 0.0
    finally:
        App.closeDocument(doc.Name)
