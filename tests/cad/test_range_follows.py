"""A ScanSettings object whose range follows the carrier (RangeFromCarrier, what the GUI's first
Run scan adds) is read headless with the carrier's slots' range, whatever StartZ and FinalZ
hold, until the user sets one of them (issue 27 item 9); the command line reads the same."""

import FreeCAD as App
import pytest

from waferscan.cad import roles
from waferscan.cad.features import following_carrier, make_settings
from waferscan.cad.reader import read_layout
from waferscan.core.model import MappingTolerances, ScanParameters


@pytest.fixture
def cell():
    doc = App.newDocument("Follows")
    plate = doc.addObject("Part::Box", "Plate")
    plate.Length, plate.Width, plate.Height = 340, 360, 5
    plate.Placement.Base = App.Vector(-170, 20, -5)
    for slot in (1, 2):
        wafer = doc.addObject("Part::Cylinder", f"W{slot}")
        wafer.Radius, wafer.Height = 150, 0.7
        wafer.Placement.Base = App.Vector(0, 200, 10 * slot)
    bar = doc.addObject("Part::Box", "Sensor")
    bar.Length, bar.Width, bar.Height = 160, 4, 4
    bar.Placement.Base = App.Vector(-80, 64.6, 0)
    doc.recompute()
    for slot in (1, 2):
        roles.tag_wafer(doc.getObject(f"W{slot}"))
    roles.tag_carrier(plate, slot_origin=App.Placement(App.Vector(170, 180, 15), App.Rotation()))
    roles.tag_scanner(bar, emitter=(0, 2, 2), receiver=(160, 2, 2))
    settings = make_settings(doc, ScanParameters(start_z=5.0, final_z=255.0),
                             MappingTolerances(), None, range_from_carrier=True)
    doc.recompute()
    name = doc.Name
    yield doc, plate, settings
    if name in App.listDocuments():
        App.closeDocument(name)


def scanned_range(doc):
    scan = read_layout(doc).scan
    return [scan.start_z, scan.final_z]


def test_the_range_follows_slot_count_pitch_and_origin(cell):
    doc, plate, settings = cell
    assert settings.RangeFromCarrier is True
    assert scanned_range(doc) == pytest.approx([5.0, 255.0])  # 25 slots by default
    plate.SlotCount = 5
    assert scanned_range(doc) == pytest.approx([5.0, 55.0])
    plate.Pitch = 6.0
    plate.SlotOrigin = App.Placement(App.Vector(170, 180, 25), App.Rotation())  # seat at Z 20
    assert scanned_range(doc) == pytest.approx([17.0, 47.0])
    plate.Placement.Base = App.Vector(-170, 20, 5)  # the carrier raised 10 mm
    assert scanned_range(doc) == pytest.approx([27.0, 57.0])


def test_writing_the_followed_range_keeps_following(cell):
    doc, plate, settings = cell
    with following_carrier():
        settings.FinalZ = 55.0
    assert settings.RangeFromCarrier is True


def test_a_range_the_user_sets_is_kept(cell):
    doc, plate, settings = cell
    settings.FinalZ = 40.0
    assert settings.RangeFromCarrier is False
    plate.SlotCount = 5
    assert scanned_range(doc) == pytest.approx([5.0, 40.0])


def test_a_document_saved_following_opens_following(cell, tmp_path):
    doc, plate, settings = cell
    path = str(tmp_path / "follows.FCStd")
    doc.saveAs(path)
    App.closeDocument(doc.Name)
    again = App.openDocument(path)
    try:
        restored = [o for o in again.Objects if roles.role_of(o) == roles.SETTINGS][0]
        assert restored.RangeFromCarrier is True
        again.getObject("Plate").SlotCount = 3
        assert scanned_range(again) == pytest.approx([5.0, 35.0])
    finally:
        App.closeDocument(again.Name)
