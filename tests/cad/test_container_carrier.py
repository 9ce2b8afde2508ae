"""Slots derived from a carrier made of many solids (issue 27's walkthrough): the paper's FOUP
split into its 55 walls and ledges, as a STEP file imported with "merge compound" on and split
gives them, gathered in a container (Make carrier from solids' App::Part, a turned App::Part
in a turned App::Part, an App::Link to a part placed elsewhere, a LinkGroup, one compound) and
tagged as the carrier: its ledges are read across all its solids, placed globally, and give the
paper's 25 slots, not the 24 the wafers alone would."""

import dataclasses

import FreeCAD as App
import Part
import pytest

from waferscan.cad import roles
from waferscan.cad.carrier_geometry import instance_of, propose_slots

PAPER_SEAT = (0.0, 400.0, 293.94)


@pytest.fixture
def paper_solids(paper_layout_read, built):
    """The robot-less paper document with its carrier hidden and untagged; its 55 solids,
    global."""
    doc = built(dataclasses.replace(paper_layout_read, robot=None), "ContainerCarrier")
    lp1 = doc.getObject("LP1")
    solids = instance_of(lp1).shape().Solids
    roles.untag(lp1)
    lp1.Visibility = False
    assert len(solids) == 55
    return doc, solids


def features_in(doc, solids, frame=App.Placement()):
    """A Part::Feature per solid, its shape in ``frame`` (the container's global placement)."""
    made = []
    for number, solid in enumerate(solids):
        local = solid.copy()
        local.transformShape(frame.inverse().toMatrix(), True)
        obj = doc.addObject("Part::Feature", f"Solid{number:03d}")
        obj.Shape = local
        made.append(obj)
    return made


def part_of_solids(doc, solids):
    part = doc.addObject("App::Part", "Carrier")  # as Make carrier from solids makes it
    for obj in features_in(doc, solids):
        part.addObject(obj)
    return part


def turned_parts(doc, solids):
    outer = doc.addObject("App::Part", "Cell")
    inner = doc.addObject("App::Part", "Foup")
    outer.addObject(inner)
    outer.Placement = App.Placement(App.Vector(50, -20, 10), App.Rotation(App.Vector(0, 0, 1), 30))
    inner.Placement = App.Placement(App.Vector(-5, 8, -10), App.Rotation(App.Vector(0, 0, 1), -30))
    for obj in features_in(doc, solids, outer.Placement.multiply(inner.Placement)):
        inner.addObject(obj)
    return outer


def link_to_part(doc, solids):
    seat = App.Placement(App.Vector(*PAPER_SEAT), App.Rotation())
    source = doc.addObject("App::Part", "FoupSource")
    for obj in features_in(doc, solids, seat):
        source.addObject(obj)
    source.Placement = App.Placement(App.Vector(2000, 0, 0), App.Rotation())
    source.Visibility = False  # only the link is shown, where the wafers are
    link = doc.addObject("App::Link", "FoupLink")
    link.LinkedObject = source
    link.Placement = seat
    return link


def link_group(doc, solids):
    group = doc.addObject("App::LinkGroup", "FoupGroup")
    group.ElementList = features_in(doc, solids)
    return group


def compound(doc, solids):
    obj = doc.addObject("Part::Feature", "FoupCompound")
    obj.Shape = Part.makeCompound(solids)
    return obj


@pytest.mark.parametrize("make", [part_of_solids, turned_parts, link_to_part, link_group,
                                  compound])
def test_a_carrier_of_many_solids_gives_its_ledges(paper_solids, make):
    doc, solids = paper_solids
    carrier = make(doc, solids)
    doc.recompute()
    roles.tag_carrier(carrier)
    proposal = propose_slots(carrier)
    assert "25 support levels" in proposal.how, proposal.how
    assert proposal.slot_count == 25
    assert proposal.pitch == pytest.approx(10.0, abs=1e-6)
    assert proposal.seat == pytest.approx(PAPER_SEAT, abs=1e-6)


def test_a_hidden_solid_in_the_carrier_is_not_read(paper_solids):
    # A solid the user hid is not in the 3D view, and not read: here the top slot's two
    # ledges copied half a pitch higher, which read would halve the pitch.
    doc, solids = paper_solids
    part = part_of_solids(doc, solids)
    top = max(s.BoundBox.ZMax for s in solids if s.BoundBox.ZLength < 2.0)
    ledges = [s.copy() for s in solids if s.BoundBox.ZLength < 2.0 and s.BoundBox.ZMax == top]
    assert len(ledges) == 2
    for ledge in ledges:
        ledge.translate(App.Vector(0, 0, 5))
    blocks = Part.makeCompound(ledges)
    hidden = doc.addObject("Part::Feature", "Hidden")
    hidden.Shape = blocks
    part.addObject(hidden)
    hidden.Visibility = False
    doc.recompute()
    roles.tag_carrier(part)
    assert propose_slots(part).slot_count == 25
