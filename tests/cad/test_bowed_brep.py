"""Bowed wafers (SPEC §10) against OpenCASCADE: the closed-form edges agree with bisection on a
B-rep solid of revolution; the bow survives scenario -> document -> layout."""

from dataclasses import replace

import FreeCAD as App
import Part
import pytest

from waferscan.addon import paper_scenario
from waferscan.cad.bowed_solid import bowed_wafer_solid
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import read_layout
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

PAPER = read_scenario(paper_scenario())


def brep_edges(layout, wafer, near):
    """First and last scan position where the beam segment meets the B-rep solid, bisected
    from brackets around ``near`` (the closed form's edges) to 1e-9 mm."""
    solid = bowed_wafer_solid(wafer)

    def hit(z):
        e = App.Vector(*layout.emitter_at(z))
        r = e + App.Vector(*layout.beam.direction) * layout.beam.length
        # The part of the beam inside the solid (distToShape misses a segment that dips into a
        # surface of revolution and out again, OCCT's extrema on it).
        return solid.common(Part.LineSegment(e, r).toShape()).Length > 0.0

    def bisect(miss, inside):
        assert hit(inside) and not hit(miss)
        while abs(inside - miss) > 1e-9:
            mid = 0.5 * (miss + inside)
            miss, inside = (miss, mid) if hit(mid) else (mid, inside)
        return inside

    return bisect(near[0] - 0.01, near[0] + 0.01), bisect(near[1] + 0.01, near[1] - 0.01)


@pytest.mark.parametrize("index,bow", [(0, 0.1), (0, -0.08), (3, 0.2)])
def test_closed_form_edges_agree_with_the_brep_solid(index, bow):
    wafer = replace(PAPER.wafers[index], bow=bow)
    layout = replace(PAPER, wafers=(wafer,)).with_scan(z_step=0.0)
    (run,) = scan_layout(layout).runs
    low, high = brep_edges(layout, wafer, (run.z_in, run.z_out))
    assert abs(low - run.z_in) <= 1e-6 and abs(high - run.z_out) <= 1e-6


def test_the_bow_survives_the_document():
    bowed = replace(PAPER, robot=None, wafers=tuple(replace(w, bow=0.05 * (i % 3 - 1))
                                                    for i, w in enumerate(PAPER.wafers)))
    doc = build_document(bowed, "BowTest")
    try:
        read = read_layout(doc)
        assert [w.bow for w in read.wafers] == pytest.approx([w.bow for w in bowed.wafers])
        direct = scan_layout(bowed)
        assert scan_document(doc).runs == direct.runs
        assert scan_document(doc, "document").runs == direct.runs
    finally:
        App.closeDocument(doc.Name)


def test_crosscheck_and_the_brep_engine_confirm_a_bowed_layout():
    from waferscan.cad.crosscheck import crosscheck

    wafers = tuple(replace(w, bow=0.1) for w in PAPER.wafers[:3])
    layout = replace(PAPER, robot=None, wafers=wafers).with_scan(final_z=330.0)
    doc = build_document(layout, "BowCheck")
    try:
        check = crosscheck(doc)
        assert check.ok, check
        assert len(check.wafers) == 3 and check.largest_deviation <= 1e-6
        assert scan_document(doc, "brep").runs == scan_layout(layout).runs
    finally:
        App.closeDocument(doc.Name)
