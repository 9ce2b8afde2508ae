"""Slots derived from a cell's geometry (issue 27 item 8): slot count, pitch and slot 1's seat
read off the carrier's support ledges and the wafers' own seats, in global coordinates, and the
frames a user picks globally written into each object's own frame."""

import dataclasses
import math

import FreeCAD as App
import Part
import pytest

from waferscan.cad import roles
from waferscan.cad.carrier_geometry import (
    common_step, instance_of, propose_slots, set_beam_ends, set_slot_frame)
from waferscan.cad.document_scan import scan_document
from waferscan.cad.features import carrier_solids
from waferscan.cad.reader import read_layout
from waferscan.core.files.report import PAPER_CODE

# The paper's carrier (resources/examples/paper.toml): 25 slots at 10 mm, slot 1 at Z 293.94,
# its wafers centred at (0, 400); wafers 4 and 7 cross-slotted (tilted).
PAPER_SEAT = (0.0, 400.0, 293.94)


def test_the_common_step_of_seats_is_their_pitch():
    assert common_step([10.0, 30.0, 60.0]) == pytest.approx(10.0)
    assert common_step([293.94, 303.94, 333.94, 523.94]) == pytest.approx(10.0)
    assert common_step([0.0, 20.0]) == pytest.approx(20.0)  # two seats: their gap
    assert common_step([0.0, 6.35 * 3 + 0.01, 6.35 * 7 - 0.01]) == pytest.approx(6.35, abs=0.01)
    assert common_step([5.0]) is None


def test_the_paper_carrier_gives_its_slots_from_its_support_ledges(paper_doc):
    proposal = propose_slots(paper_doc.getObject("LP1"))
    assert proposal.slot_count == 25
    assert proposal.pitch == pytest.approx(10.0, abs=1e-6)
    assert proposal.seat == pytest.approx(PAPER_SEAT, abs=1e-6)
    assert "25 support levels" in proposal.how
    assert "8 level wafers" in proposal.how and "2 tilted" in proposal.how
    assert proposal.front == pytest.approx((0.0, -1.0))  # towards the document's beam


def plain_copy(doc, obj, name, placement=App.Placement()):
    """A Part::Feature holding ``obj``'s shape where the 3D view shows it, its own frame at
    ``placement`` (what a STEP import gives: no roles, no WaferScan properties)."""
    shown = instance_of(obj).shape()
    local = shown.copy()
    local.Placement = App.Placement()
    # Baked into the geometry (planes stay planes): the copy's own frame is ``placement``.
    local.transformShape(placement.inverse().multiply(shown.Placement).toMatrix(), True)
    copy = doc.addObject("Part::Feature", name)
    copy.Shape = local
    copy.Placement = placement
    assert copy.Shape.BoundBox.isInside(shown.BoundBox.Center)
    return copy


def test_wafers_alone_give_the_seat_and_pitch_and_the_carrier_height_the_count(paper_doc):
    doc = paper_doc
    # A carrier with no ledges: a plain box as tall as the paper's FOUP.
    box = doc.addObject("Part::Feature", "Box")
    box.Shape = Part.makeBox(340, 330, 547.94 - 279.94, App.Vector(-170, 235, 279.94))
    doc.recompute()
    roles.tag_carrier(box)
    proposal = propose_slots(box)
    assert proposal.pitch == pytest.approx(10.0, abs=1e-6)
    assert proposal.seat == pytest.approx(PAPER_SEAT, abs=1e-6)
    # (547.94 - 293.94) / 10 = 25.4: 25 slots, each with a pitch of room above its seat.
    assert proposal.slot_count == 25
    assert "8 level wafers" in proposal.how and "height" in proposal.how


def test_a_second_carrier_takes_no_slots_from_the_wafers_in_another(paper_doc):
    """Found by the GUI test of "Set up carrier and sensor" with two carriers
    (tests/gui/test_gui_frames_choice.py): an empty box beside the paper's FOUP was offered
    24 slots from the seats of the FOUP's wafers."""
    doc = paper_doc
    spare = doc.addObject("Part::Feature", "Spare")
    spare.Shape = Part.makeBox(320, 320, 300, App.Vector(600, 0, 0))
    doc.recompute()
    roles.tag_carrier(spare)
    proposal = propose_slots(spare)
    assert proposal.slot_count is None and "no wafers" in proposal.how
    # the FOUP's own proposal still reads its wafers
    assert "8 level wafers" in propose_slots(doc.getObject("LP1")).how


def test_without_wafers_or_ledges_nothing_is_proposed():
    doc = App.newDocument("Empty")
    try:
        box = doc.addObject("Part::Box", "Box")
        doc.recompute()
        roles.tag_carrier(box)
        proposal = propose_slots(box)
        assert proposal.slot_count is None and "no wafers" in proposal.how
    finally:
        App.closeDocument(doc.Name)


def test_frames_picked_globally_go_into_rotated_objects_own_frames(paper_layout_read, built):
    # The paper's layout with its sensor lifted along Z (no robot): the new sensor's beam is
    # the one scanned.
    doc = built(dataclasses.replace(paper_layout_read, robot=None), "PaperNoRobot")
    lp1, scanner = doc.getObject("LP1"), doc.getObject("Scanner")
    expected = scan_document(doc, "analytic").code
    assert expected == PAPER_CODE
    # The paper's carrier and sensor as a STEP import would give them, each object's frame
    # turned 90 degrees about Z and moved: no roles, so tagged anew with the defaults.
    turn = App.Placement(App.Vector(100, -50, 20), App.Rotation(App.Vector(0, 0, 1), 90))
    carrier = plain_copy(doc, lp1, "Foup", turn)
    sensor = plain_copy(doc, scanner, "Sensor", turn)
    for old in ("LP1", "Scanner"):
        doc.getObject(old).Visibility = False
    doc.recompute()
    roles.tag_carrier(carrier, slot_count=1, pitch=1.0, wafer_thickness=0.7, support_span=292.5)
    roles.tag_scanner(sensor)
    beam = (App.Vector(-80, 266.6, 280), App.Vector(80, 266.6, 280))  # picked in the panel
    proposal = propose_slots(carrier, beam)
    # The front (out of the opening, towards the robot) faces the beam: -Y, as in the paper.
    assert proposal.front == pytest.approx((0.0, -1.0))
    set_slot_frame(carrier, proposal.slot_count, proposal.pitch, App.Vector(*proposal.seat),
                   proposal.front)
    set_beam_ends(sensor, *beam)
    doc.recompute()
    # In the object's own frame, by hand: own (x, y, z) = (y + 50, 100 - x, z - 20).
    assert tuple(carrier.SlotOrigin.Base) == pytest.approx((450.0, 100.0, 273.94))
    assert tuple(sensor.Emitter) == pytest.approx((316.6, 180.0, 260.0))
    assert tuple(sensor.Receiver) == pytest.approx((316.6, 20.0, 260.0))
    assert carrier.SlotCount == 25 and carrier.Pitch.Value == pytest.approx(10.0)
    doc.getObject("ScanSettings").Carrier = "Foup"
    layout = read_layout(doc)
    assert layout.scanned_carrier.first_slot_z == pytest.approx(293.94)
    assert layout.scanned_carrier.center == pytest.approx((0.0, 400.0))
    assert layout.scanned_carrier.front == pytest.approx((0.0, -1.0))
    assert layout.beam.emitter == pytest.approx((-80.0, 266.6, 280.0))
    assert math.isclose(layout.beam.length, 160.0)
    assert scan_document(doc, "analytic").code == expected
