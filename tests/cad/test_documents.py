"""Layouts as FreeCAD documents: scenario -> document -> layout round trips, scans through the
document, edits that change the next scan, App::Part nesting and App::Link, tagging solids of
any origin, save and reload."""

import math
import random

import FreeCAD as App
import Part
import pytest
from random_layouts import random_layout
from scenarios import PAPER_CODE

from waferscan.addon import paper_scenario
from waferscan.cad import roles
from waferscan.cad.builder import build_document
from waferscan.cad.disc import NotADisc, disc_of
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import read_layout
from waferscan.core.errors import InputError
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

PAPER = read_scenario(paper_scenario())


def assert_same_layout(read, original):
    assert [w.name for w in read.wafers] == [w.name for w in original.wafers]
    for a, b in zip(read.wafers, original.wafers):
        assert a.center == pytest.approx(b.center, abs=1e-9)
        assert a.normal == pytest.approx(b.normal, abs=1e-12)
        assert a.diameter == pytest.approx(b.diameter, abs=1e-9)
        assert a.thickness == pytest.approx(b.thickness, abs=1e-12)
    assert read.beam.emitter == pytest.approx(original.beam.emitter, abs=1e-9)
    assert read.beam.direction == pytest.approx(original.beam.direction, abs=1e-12)
    assert read.beam.length == pytest.approx(original.beam.length, abs=1e-9)
    assert read.lift_axis == pytest.approx(original.lift_axis, abs=1e-12)
    for a, b in zip(read.carriers, original.carriers):
        assert (a.name, a.slot_count) == (b.name, b.slot_count)
        assert (a.pitch, a.first_slot_z, a.wafer_diameter, a.wafer_thickness, a.support_span) == \
            pytest.approx((b.pitch, b.first_slot_z, b.wafer_diameter, b.wafer_thickness,
                           b.support_span), abs=1e-9)
        assert a.center + a.front == pytest.approx(b.center + b.front, abs=1e-9)
    assert read.scan == original.scan
    assert read.carrier == original.carrier


def runs(result):
    return [(r.z_in, r.z_out, r.wafers) for r in result.runs]


def test_paper_round_trip(paper_doc):
    read = read_layout(paper_doc)
    assert_same_layout(read, PAPER)
    assert runs(scan_layout(read)) == runs(scan_layout(PAPER))


def test_random_scenarios_round_trip_and_scan_identically():
    for seed in range(25):
        layout = random_layout(random.Random(seed))
        doc = build_document(layout, f"Random{seed}")
        try:
            read = read_layout(doc)
            assert_same_layout(read, layout)
            assert scan_layout(read).slot_map == scan_layout(layout).slot_map
            assert runs(scan_layout(read)) == runs(scan_layout(layout))
        finally:
            App.closeDocument(doc.Name)


@pytest.mark.parametrize("engine", ["document", "brep", "loop", "vector"])
def test_document_engines_equal_analytic(paper_doc, engine):
    reference = scan_document(paper_doc, "analytic")
    result = scan_document(paper_doc, engine)
    assert result.code == reference.code == "1101221001220001010000010"
    assert runs(result) == runs(reference)
    assert result.wafers == reference.wafers


def test_document_engine_on_random_layouts():
    for seed in (1, 2, 5, 8):
        layout = random_layout(random.Random(seed), max_steps=400)
        doc = build_document(layout, f"Doc{seed}")
        try:
            assert runs(scan_document(doc, "document")) == runs(scan_document(doc, "analytic"))
        finally:
            App.closeDocument(doc.Name)


def test_document_engine_leaves_the_scanner_where_it_was(paper_doc):
    scanner = paper_doc.getObjectsByLabel("Scanner")[0]
    before = App.Placement(scanner.Placement)
    scan_document(paper_doc, "document")
    assert scanner.Placement.toMatrix() == before.toMatrix()


def wafer(doc, label):
    return doc.getObjectsByLabel(label)[0]


def test_moving_a_wafer_changes_the_next_scan(paper_doc):
    w = wafer(paper_doc, "LP1_W01")
    w.Placement.Base = w.Placement.Base + App.Vector(0, 0, 3.0)  # 3 mm above its seat
    paper_doc.recompute()
    result = scan_document(paper_doc, "document")
    assert result.code[0] == "5"
    first = result.runs[0]
    assert (first.z_in, first.z_out) == pytest.approx((296.95, 297.60))


def test_tilting_a_wafer_changes_the_next_scan(paper_doc):
    w = wafer(paper_doc, "LP1_W10")  # slot 24
    w.Placement.Rotation = App.Rotation(App.Vector(0, 1, 0), -math.degrees(math.atan(10 / 292.5)))
    w.Placement.Base = w.Placement.Base + App.Vector(0, 0, 5.0)
    paper_doc.recompute()
    result = scan_document(paper_doc, "document")
    assert result.code == "1101221001220001010000022"


def test_deleting_a_wafer_changes_the_next_scan(paper_doc):
    paper_doc.removeObject(wafer(paper_doc, "LP1_W02").Name)
    result = scan_document(paper_doc, "document")
    assert result.code == "1001221001220001010000010"


def test_hiding_a_wafer_takes_it_out_of_the_scene(paper_doc):
    wafer(paper_doc, "LP1_W02").Visibility = False
    assert scan_document(paper_doc).code == "1001221001220001010000010"


def test_moving_the_carrier_assembly_moves_its_slots_and_wafers(paper_doc):
    assembly = paper_doc.getObjectsByLabel("LP1 assembly")[0]
    assembly.Placement.Base = assembly.Placement.Base + App.Vector(0, 0, 10.0)
    read = read_layout(paper_doc)
    assert read.scanned_carrier.first_slot_z == pytest.approx(303.94)
    assert scan_document(paper_doc).code == PAPER_CODE


def test_nested_parts_and_links(paper_doc):
    """The carrier assembly inside another App::Part, and extra wafers as App::Links to a hidden
    original: all read through their global placements."""
    outer = paper_doc.addObject("App::Part", "Outer")
    outer.Placement = App.Placement(App.Vector(0, 0, 20.0), App.Rotation())
    assembly = paper_doc.getObjectsByLabel("LP1 assembly")[0]
    outer.addObject(assembly)
    paper_doc.recompute()
    read = read_layout(paper_doc)
    assert read.scanned_carrier.first_slot_z == pytest.approx(313.94)
    assert read.wafers[0].center == pytest.approx((0.0, 400.0, 313.94))
    # Shift the scanned Z window with the carrier; the code stays the paper's.
    settings = paper_doc.getObjectsByLabel("ScanSettings")[0]
    settings.StartZ, settings.FinalZ = 300.0, 570.0
    assert scan_document(paper_doc, "document").code == PAPER_CODE

    original = wafer(paper_doc, "LP1_W01")
    template = paper_doc.copyObject(original)
    template.Label = "template"
    template.Visibility = False  # the hidden original of the links is not in the scene
    link = paper_doc.addObject("App::Link", "Extra")
    link.Label = "extra"
    link.LinkedObject = template
    link.Placement = App.Placement(App.Vector(0, 400, 363.94 + 20.0), App.Rotation())  # slot 8
    paper_doc.recompute()
    read = read_layout(paper_doc)
    assert "template" not in [w.name for w in read.wafers]
    extra = next(w for w in read.wafers if w.name == "extra")
    assert extra.center == pytest.approx((0.0, 400.0, 383.94))
    assert scan_document(paper_doc, "document").code == "1101221101220001010000010"


def test_tag_solids_of_any_origin():
    doc = App.newDocument("Tagging")
    try:
        cylinder = doc.addObject("Part::Cylinder", "Cyl")
        cylinder.Radius, cylinder.Height = 100.0, 0.725
        cylinder.Placement = App.Placement(App.Vector(1, 2, 3), App.Rotation(App.Vector(1, 0, 0), 30))
        body = doc.addObject("PartDesign::Body", "Body")
        pd = doc.addObject("PartDesign::AdditiveCylinder", "PdCylinder")
        body.addObject(pd)
        pd.Radius, pd.Height = 150.0, 0.775
        body.Placement = App.Placement(App.Vector(0, 0, 50), App.Rotation())
        box = doc.addObject("Part::Box", "Box")
        doc.recompute()
        Part.export([cylinder], "/tmp/waferscan-wafer.step")
        imported = doc.addObject("Part::Feature", "Imported")
        imported.Shape = Part.read("/tmp/waferscan-wafer.step")
        doc.recompute()
        for obj in (cylinder, body, imported):
            roles.tag_wafer(obj)
            assert roles.role_of(obj) == roles.WAFER
        center, normal, diameter, thickness = disc_of(imported.Shape)
        assert center == pytest.approx((1, 2, 3), abs=1e-7)
        assert normal == pytest.approx((0, -0.5, math.sqrt(3) / 2), abs=1e-9)
        assert (diameter, thickness) == pytest.approx((200.0, 0.725), abs=1e-9)
        assert disc_of(body.Shape)[0] == pytest.approx((0, 0, 50), abs=1e-9)
        with pytest.raises(NotADisc, match="Box is not a wafer"):
            roles.tag_wafer(box)
        # A box tagged by hand is refused by the reader with a clear message.
        roles.set_role(box, roles.WAFER)
        scanner = doc.addObject("Part::Feature", "Beam")
        roles.tag_scanner(scanner)
        carrier = doc.addObject("Part::Feature", "Foup")
        roles.tag_carrier(carrier)
        with pytest.raises(InputError, match="Tagging: Box is tagged as a wafer but has no cylindrical rim"):
            read_layout(doc)
    finally:
        App.closeDocument(doc.Name)


def test_save_and_reload_keep_roles_proxies_and_results(paper_doc, tmp_path):
    path = str(tmp_path / "paper.FCStd")
    paper_doc.saveAs(path)
    before = scan_document(paper_doc, "document")
    App.closeDocument(paper_doc.Name)
    reopened = App.openDocument(path)
    try:
        carrier = reopened.getObjectsByLabel("LP1")[0]
        assert type(carrier.Proxy).__name__ == "CarrierBody"
        assert roles.role_of(carrier) == roles.CARRIER
        carrier.SlotCount = 13  # the proxy rebuilds the body after reload
        reopened.recompute()
        # the roof over the top slot: 1.5 pitches above its seat (features.carrier_solids)
        assert carrier.Shape.BoundBox.ZMax == pytest.approx((13 + 1.5) * 10.0 + 4.0, abs=1e-6)
        carrier.SlotCount = 25
        reopened.recompute()
        after = scan_document(reopened, "document")
        assert runs(after) == runs(before)
        assert_same_layout(read_layout(reopened), PAPER)
    finally:
        App.closeDocument(reopened.Name)


@pytest.mark.parametrize("prop, value, message", [
    ("FinalZ", 100.0, "ScanSettings: final_z (100) is below start_z (280)"),
    ("ScanSpeed", 0.0, "ScanSettings.ScanSpeed: must be greater than 0"),
    ("SensorResponseMs", -1.0, "ScanSettings.SensorResponseMs: must not be negative"),
    ("ZStep", 1e-9, "ScanSettings: z_step 1e-09 over 270 mm makes"),
])
def test_scan_settings_typed_in_the_property_editor_are_checked(paper_doc, prop, value, message):
    settings = paper_doc.getObjectsByLabel("ScanSettings")[0]
    setattr(settings, prop, value)
    with pytest.raises(InputError) as caught:
        scan_document(paper_doc, "analytic")
    assert message in str(caught.value)
    assert str(caught.value).startswith(f"{paper_doc.Name}: ")
