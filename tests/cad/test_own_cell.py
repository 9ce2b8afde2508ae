"""An engineer's own cell read headless: a STEP file imported with "Use LinkGroup" on (each solid
listed under the document and again inside its link groups) is read once per solid, as the tree
and the 3D view show it; a compound of solids (STEP import with "merge compound" on) split into
its solids, each placed where it was."""

import FreeCAD as App
import Import
import Part
import pytest

from waferscan.cad import roles
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import DocumentScene

SEATS = {"W1": 10.0, "W3": 30.0}  # slots 1 and 3 of 5: slot 1's seat at Z 10, pitch 10


def build_cell(doc):
    """A FOUP (App::Part, its corner at (-10, 30, -5)) with a base and two wafers, and a sensor,
    in an App::Part cell."""
    cell = doc.addObject("App::Part", "MyCell")
    foup = doc.addObject("App::Part", "FOUP")
    cell.addObject(foup)
    foup.Placement.Base = App.Vector(-10, 30, -5)
    base = doc.addObject("Part::Box", "Base")
    base.Length, base.Width, base.Height = 340, 360, 5
    foup.addObject(base)
    for name, z in SEATS.items():
        wafer = doc.addObject("Part::Cylinder", name)
        wafer.Radius, wafer.Height = 150, 0.775
        wafer.Placement.Base = App.Vector(170, 170, z + 5)
        foup.addObject(wafer)
    sensor = doc.addObject("Part::Box", "Sensor")
    sensor.Length, sensor.Width, sensor.Height = 160, 4, 4
    sensor.Placement.Base = App.Vector(80, 64.6, -2)
    cell.addObject(sensor)
    doc.recompute()
    return cell


def tag(carrier, wafers, sensor, carrier_frame, sensor_frame):
    for wafer in wafers:
        roles.tag_wafer(wafer)
    roles.tag_carrier(carrier, slot_count=5, pitch=10.0, slot_origin=carrier_frame.inverse()
                      .multiply(App.Placement(App.Vector(160, 200, 10), App.Rotation())))
    inverse = sensor_frame.inverse()
    roles.tag_scanner(sensor, tuple(inverse.multVec(App.Vector(70, 66.6, 0))),
                      tuple(inverse.multVec(App.Vector(250, 66.6, 0))))


@pytest.fixture
def step_file(tmp_path):
    doc = App.newDocument("OwnCellSource")
    try:
        cell = build_cell(doc)
        path = tmp_path / "cell.step"
        Import.export([cell], str(path))
    finally:
        App.closeDocument(doc.Name)
    return path


def test_a_link_group_import_is_read_once_per_solid(step_file):
    doc = App.newDocument("LinkGroupCell")
    try:
        Import.insert(str(step_file), doc.Name, merge=False, useLinkGroup=True)
        by_label = {o.Label: o for o in doc.Objects}
        assert by_label["FOUP"].TypeId == "App::LinkGroup"
        # The solids are listed under the document too: a naive walk met W1 three times.
        assert by_label["W1"].getParentGroup() is None
        cell, foup = by_label["MyCell"], by_label["FOUP"]
        foup_frame = cell.getSubObject(f"{foup.Name}.", retType=3)
        sensor = by_label["Sensor"]
        tag(foup, [by_label["W1"], by_label["W3"]], sensor, foup_frame,
            cell.getSubObject(f"{sensor.Name}.", retType=3))
        doc.recompute()
        scene = DocumentScene.of(doc)
        assert [i.path for i in scene.wafers] == ["MyCell/FOUP/W1", "MyCell/FOUP/W3"]
        assert [i.path for i in scene.carriers] == ["MyCell/FOUP"]
        assert [i.path for i in scene.scanners] == ["MyCell/Sensor"]
        result = scan_document(doc, "analytic")
        assert result.code == "10100"
        assert sorted(round(w.center[2], 9) for w in result.layout.wafers) == [10.0, 30.0]
    finally:
        App.closeDocument(doc.Name)


def test_a_compound_split_into_its_solids_keeps_them_in_place():
    doc = App.newDocument("MergedCell")
    try:
        solids = [Part.makeBox(340, 360, 5, App.Vector(-10, 30, -5)),
                  Part.makeCylinder(150, 0.775, App.Vector(160, 200, 10)),
                  Part.makeCylinder(150, 0.775, App.Vector(160, 200, 30))]
        compound = doc.addObject("Part::Feature", "Merged")
        compound.Shape = Part.makeCompound(solids)
        compound.Placement.Base = App.Vector(0, 0, 100)  # the whole file moved up
        assert roles.is_compound_of_solids(compound)
        parts = roles.split_compound(compound)
        doc.recompute()
        assert [p.Name for p in parts] == ["Merged_S001", "Merged_S002", "Merged_S003"]
        assert compound.Visibility is False
        for part, solid in zip(parts, solids):
            moved = solid.copy()
            moved.translate(App.Vector(0, 0, 100))
            assert part.Shape.BoundBox.isInside(moved.BoundBox.Center)
            assert part.Shape.Volume == pytest.approx(solid.Volume, rel=1e-12)
            assert abs(part.Shape.BoundBox.ZMin - moved.BoundBox.ZMin) < 1e-9
        assert not roles.is_compound_of_solids(parts[1])
        roles.tag_wafer(parts[1])  # one solid: a disc now
    finally:
        App.closeDocument(doc.Name)
