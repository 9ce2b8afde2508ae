"""``placements_at(z)`` of both movers (the robot's lift joint, a scanner no robot carries): the
placements ``move_to(z)`` sets, without setting them (the GUI's animation draws them in the 3D
view only)."""

from dataclasses import replace

import FreeCAD as App
import pytest

from waferscan.addon import paper_scenario
from waferscan.cad.builder import build_document
from waferscan.cad.reader import DocumentScene, read_layout
from waferscan.cad.stepping import mover_for
from waferscan.core.files.scenario import read_scenario

PAPER = read_scenario(paper_scenario())


def same(a, b):
    """The same placement, bit for bit."""
    return tuple(a.Base) == tuple(b.Base) and a.Rotation.Q == b.Rotation.Q


@pytest.mark.parametrize("robot", [True, False], ids=["robot", "scanner"])
def test_placements_at_are_what_move_to_sets(robot):
    layout = PAPER if robot else replace(PAPER, robot=None)
    doc = build_document(layout, "PlacementsAt")
    try:
        scene = DocumentScene.of(doc)
        mover = mover_for(scene, read_layout(doc, scene))
        start = {o.Name: App.Placement(o.Placement) for o in doc.Objects
                 if hasattr(o, "Placement")}
        for z in (layout.scan.start_z + 12.5, layout.scan.final_z):
            planned = mover.placements_at(z)
            assert len(planned) == (6 if robot else 1)
            # Nothing moved yet.
            assert all(same(o.Placement, start[o.Name]) for o, _ in planned)
            mover.move_to(z)
            for obj, placement in planned:
                assert same(obj.Placement, placement), obj.Name
            mover.restore()
        # The scanner lifted by the travel: its emitter at z.
        scanner = planned[-1][0]
        lifted = planned[-1][1].Base.z - start[scanner.Name].Base.z
        assert lifted == pytest.approx(layout.scan.final_z - layout.scan.start_z, abs=1e-9)
    finally:
        App.closeDocument(doc.Name)
