"""SPEC §15: the carrier's solids in the clearance check, given to the robot layer as plain
arrays (vertices, triangles, name), against hand computations. No FreeCAD.

The paper's carrier (cad/features.carrier_solids, rebuilt here by hand in the world): its frame
at slot 1's seat (0, 400, 293.94), walls X in [-160, -156] and [156, 160], Y in [245, 560], Z in
[269.94, 558.94]; floor Z in [269.94, 273.94] and roof Z in [558.94, 562.94], both X in
[-160, 160], Y in [245, 564] (the opening two pitches under slot 1's seat to 2.5 over the top
slot's, so that the paper's stroke, 280 to 550, its tines 4 mm tall, clears them); ledges X in [-156, -146.25] and [146.25, 156], Y in [317.5, 482.5],
1.5 mm under each seat. The bundled robot's tines (tests/robot/test_clearance.py): X in [-90, -70]
and [70, 90], Y in [86.6, 266.6], Z from the beam to the beam + 4."""

import math
from dataclasses import replace
from pathlib import Path

import coal
import numpy as np
import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import Beam, RobotSpec
from waferscan.core.scan import clearance as core
from waferscan.robot.clearance import RobotBody, ScannerBody, carrier_obstacle, clearance_for

ROOT = Path(__file__).resolve().parents[2]
PAPER = read_scenario(ROOT / "resources" / "examples" / "paper.toml")
EMPTY = replace(PAPER, wafers=())  # the carrier alone
FACES = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def box(low, size, name, rotation=np.eye(3)):
    """A box as a closed mesh: 8 vertices, 12 triangles (outward, as a tessellation gives)."""
    low, size = np.asarray(low, float), np.asarray(size, float)
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    vertices = (low + corners * size) @ np.asarray(rotation).T
    triangles = [t for a, b, c, d in FACES for t in ((a, b, c), (a, c, d))]
    return vertices, np.array(triangles), name


def paper_carrier():
    """The paper's LP1 as features.carrier_solids draws it, in the world."""
    c = PAPER.scanned_carrier
    r, wall = c.wafer_diameter / 2.0, 4.0
    inner, front, back = r + 6.0, -r - 5.0, r + 10.0
    bottom, top = -2.0 * c.pitch - wall, (c.slot_count + 1.5) * c.pitch
    o = np.array([c.center[0], c.center[1], c.first_slot_z])
    solids = [
        box(o + [-inner - wall, front, bottom], [wall, back - front, top - bottom], "LP1 wall_left"),
        box(o + [inner, front, bottom], [wall, back - front, top - bottom], "LP1 wall_right"),
        box(o + [-inner - wall, back, bottom], [2 * (inner + wall), wall, top - bottom],
            "LP1 wall_back"),
        box(o + [-inner - wall, front, bottom], [2 * (inner + wall), back - front + wall, wall],
            "LP1 floor"),
        box(o + [-inner - wall, front, top], [2 * (inner + wall), back - front + wall, wall],
            "LP1 roof")]
    depth, thickness, width = 1.1 * r, 1.5, inner - c.support_span / 2.0
    for k in range(c.slot_count):
        for x, side in ((-inner, "left"), (c.support_span / 2.0, "right")):
            solids.append(box(o + [x, -depth / 2.0, k * c.pitch - thickness],
                              [width, depth, thickness], f"LP1 slot {k + 1} ledge_{side}"))
    return tuple(solids)


CARRIER = paper_carrier()


def _named(*names):
    return tuple(s for s in CARRIER if s[2] in names)


def _stroke(layout, start, final):
    return replace(layout, scan=replace(layout.scan, start_z=start, final_z=final))


def test_the_hand_built_carrier_is_the_drawn_one():
    bounds = {name: (v.min(axis=0), v.max(axis=0)) for v, _, name in CARRIER}
    assert len(CARRIER) == 55
    np.testing.assert_allclose(bounds["LP1 floor"][0], [-160, 245, 269.94])
    np.testing.assert_allclose(bounds["LP1 roof"][1], [160, 564, 562.94])
    np.testing.assert_allclose(bounds["LP1 wall_right"][0], [156, 245, 269.94])
    np.testing.assert_allclose(bounds["LP1 slot 1 ledge_right"][0], [146.25, 317.5, 292.44])


@pytest.mark.parametrize("size", [(4, 5, 6), (4, 415, 290), (2, 3, 60), (1, 1, 10)])
def test_boxes_are_coal_boxes_and_other_meshes_are_not(size):
    # (4, 415, 290): a FOUP's wall, whose face diagonal (290.03) is shorter than its long side:
    # a corner's nearest corners are then not along its edges.
    for vertices, triangles, _ in (box([1, 2, 3], size, "b"),
                                   box([1, 2, 3], size, "turned",
                                       coal.Quaternion(0.9, 0.1, 0.3, 0.2).normalized()
                                       .toRotationMatrix())):
        for given in (triangles, triangles[:, ::-1], None):  # inwards, or its corners only
            geometry, rotation, centre, inside = carrier_obstacle(vertices, given)
            assert isinstance(geometry, coal.Box) and inside is None
            np.testing.assert_allclose(sorted(2.0 * geometry.halfSide), sorted(size), atol=1e-9)
            np.testing.assert_allclose(centre, vertices.mean(axis=0), atol=1e-9)
    wedge = np.array([[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 5], [10, 0, 5], [0, 10, 5]],
                     float)
    triangles = np.array([(0, 2, 1), (3, 4, 5), (0, 1, 4), (0, 4, 3), (1, 2, 5), (1, 5, 4),
                          (2, 0, 3), (2, 3, 5)])
    assert not isinstance(carrier_obstacle(wedge, triangles)[0], (coal.Box, coal.BVHModelOBBRSS))
    assert carrier_obstacle(wedge, triangles)[3] is None  # a convex: coal's distance is signed
    vertices, triangles, _ = _l_prism(0.0)
    assert isinstance(carrier_obstacle(vertices, triangles)[0], coal.BVHModelOBBRSS)


def test_the_paper_stroke_clears_the_carriers_floor_and_roof():
    # Hand: the stroke takes the tines' 4 mm from Z = 280 to 554: 280 - 273.94 = 6.06 mm over
    # the floor at its start, 558.94 - 554 = 4.94 mm under the roof at its end (they lie under
    # both, 20 mm in X and 266.6 - 245 = 21.6 mm in Y). The walls are 156 - 90 = 66 mm and the
    # ledges hypot(146.25 - 90, 317.5 - 266.6) = 75.86 mm away. With the wafers, the least is
    # the tines' inner tip corners' 0.650 mm to the rims.
    report = clearance_for(EMPTY, carrier=CARRIER)
    assert report.carrier == "checked: 55 solids of LP1"
    (least,) = report.closest
    assert least.exact and least.obstacle == "LP1 roof" and least.part.startswith("tine_")
    assert least.distance == pytest.approx(4.94, abs=1e-6)
    assert least.position == pytest.approx(550.0, abs=1e-6)
    body = RobotBody(PAPER, carrier=CARRIER)
    motion = least.motion
    assert body.nearest(motion, 280.0)[0] == pytest.approx(6.06, abs=1e-6)
    assert body.nearest(motion, 280.0)[2] == "LP1 floor"
    with_wafers = clearance_for(PAPER, carrier=CARRIER)
    assert with_wafers.least.distance == pytest.approx(math.hypot(70.0, 133.4) - 150.0, abs=1e-6)
    assert with_wafers.least.obstacle.startswith("LP1_W") and not with_wafers.contacts
    walls = clearance_for(EMPTY, carrier=_named("LP1 wall_left", "LP1 wall_right"))
    assert walls.least.distance == pytest.approx(66.0, abs=1e-6) and walls.least.exact
    ledges = clearance_for(EMPTY, carrier=tuple(s for s in CARRIER if "ledge" in s[2]))
    assert ledges.least.distance == pytest.approx(math.hypot(56.25, 50.9), abs=1e-6)


def test_a_stroke_through_the_roof_is_a_contact_as_deep_as_the_tines():
    # Hand: a stroke on to 560 puts the tines' 4 mm (from 559.94 on) inside the roof's
    # (558.94 to 562.94) at its end: 4.0 mm deep.
    layout = _stroke(EMPTY, 280.0, 560.0)
    report = clearance_for(layout, carrier=CARRIER)
    (least,) = report.closest
    assert least.obstacle == "LP1 roof" and least.part.startswith("tine_")
    clearance_min = layout.mapping.clearance_min
    assert -4.0 - 1e-6 <= least.distance <= -4.0 + core.CONTACT_RELATIVE * (clearance_min + 4.0)
    assert report.contacts == (least,)
    body = RobotBody(layout, carrier=CARRIER)
    assert body.nearest(least.motion, least.position)[0] == pytest.approx(least.distance,
                                                                          abs=1e-6)
    assert body.nearest(least.motion, 558.94)[:3] == (pytest.approx(-4.0, abs=1e-6),
                                                       body.nearest(least.motion, 558.94)[1],
                                                       "LP1 roof")


def test_a_stroke_inside_the_opening_clears_the_roof_exactly_in_one_piece():
    # Hand: from 274.5 to 554.5 the tines' top reaches 558.5, 0.44 mm under the roof (558.94);
    # at the start their bottom is 274.5 - 273.94 = 0.56 mm over the floor's top. The least is
    # the roof's 0.44 mm, at the stroke's end.
    inside = _stroke(EMPTY, 274.5, 554.5)
    body = RobotBody(inside, carrier=CARRIER)
    (motion,) = core.scan_motions(inside)
    swept = body.swept(motion)
    assert swept is not None  # the exact translation, not the Lipschitz search
    assert swept.distance == pytest.approx(0.44, abs=1e-6) and swept.obstacle == "LP1 roof"
    assert swept.position == pytest.approx(554.5, abs=1e-6)
    assert body.nearest(motion, swept.position)[0] == pytest.approx(0.44, abs=1e-6)
    assert body.nearest(motion, 274.5)[:3] == (pytest.approx(0.56, abs=1e-6),
                                                body.nearest(motion, 274.5)[1], "LP1 floor")
    down = replace(motion, start=554.5, end=274.5)
    assert body.swept(down).distance == pytest.approx(0.44, abs=1e-6)


def _moved(dx, layout=EMPTY):
    """The sensor and the robot moved dx mm along X: the robot taught on the moved beam."""
    beam = layout.beam
    return replace(layout, beam=Beam((beam.emitter[0] + dx,) + tuple(beam.emitter[1:]),
                                     beam.direction, beam.length),
                   robot=RobotSpec(base=(dx, -300.0, 0.0)))


@pytest.mark.parametrize("dx, expected", [(65.0, 1.0), (67.0, -1.0)])
def test_a_fork_taught_too_far_right_meets_the_right_wall(dx, expected):
    # Hand: moved dx along X, tine_right covers X in [70 + dx, 90 + dx]; the right wall starts
    # at X = 156, so the gap is 156 - 90 - dx: 1.0 mm for dx = 65, an overlap of 1.0 mm (the
    # tine 21.6 mm into the wall in Y, all its 4 mm in Z) for dx = 67. The stroke stays 11.06
    # mm over the floor and 16.94 mm under the roof.
    layout = _stroke(_moved(dx), 285.0, 538.0)
    report = clearance_for(layout, carrier=CARRIER)
    least = report.least
    assert (least.part, least.obstacle) == ("tine_right", "LP1 wall_right")
    if expected > 0:
        assert least.distance == pytest.approx(expected, abs=1e-6) and not report.contacts
    else:
        assert report.contacts == (least,)
        slack = core.CONTACT_RELATIVE * (layout.mapping.clearance_min - expected)
        assert expected - 1e-6 <= least.distance <= expected + slack
        body = RobotBody(layout, carrier=CARRIER)
        assert body.nearest(least.motion, 400.0)[:3] == (pytest.approx(-1.0, abs=1e-6),
                                                         "tine_right", "LP1 wall_right")
        assert "between tine_right and LP1 wall_right, fast stroke up" in report.warnings()[0]


def _l_prism(z0):
    """A non-convex L-shaped prism about the emitter head at scan position z0: the L
    (-100, 250) (0, 250) (0, 260) (-60, 260) (-60, 290) (-100, 290), Z in [z0 - 10, z0 + 10]."""
    outline = [(-100, 250), (0, 250), (0, 260), (-60, 260), (-60, 290), (-100, 290)]
    n = len(outline)
    vertices = np.array([(x, y, z) for z in (z0 - 10.0, z0 + 10.0) for x, y in outline], float)
    triangles = []
    for i in range(n):  # the sides, outwards (the outline runs anticlockwise)
        j = (i + 1) % n
        triangles += [(i, j, n + j), (i, n + j, n + i)]
    for i in (4, 5, 0, 1, 2):  # the caps, a fan from the reflex corner (-60, 260)
        j = (i + 1) % n
        if 3 not in (i, j):
            triangles += [(3, j, i), (n + 3, n + i, n + j)]
    return vertices, np.array(triangles), "LP1 L"


def test_a_part_inside_a_non_convex_solid_overlaps_it():
    # Hand: the emitter head (radius 3) at (-80, 266.6, z0) lies inside the L's upright arm,
    # 10 mm from its top and bottom, 16.6 from Y = 250 and 20 from X = -100 and -60: the sphere
    # is 10 - 3 = 7 mm inside. 20 mm above, it is 20 - 10 - 3 = 7 mm clear.
    layout = replace(EMPTY, robot=None)
    z0 = 400.0
    body = ScannerBody(layout, carrier=(_l_prism(z0),))
    (motion,) = core.scan_motions(layout)
    assert body.nearest(motion, z0)[:3] == (pytest.approx(-7.0, abs=1e-6), "emitter head",
                                            "LP1 L")
    assert body.nearest(motion, z0 + 20.0)[0] == pytest.approx(7.0, abs=1e-6)
    least = core.least_along(body, motion, layout.mapping.clearance_min)
    assert least.distance < 0.0 and least.obstacle == "LP1 L"


def test_a_body_made_without_the_carrier_takes_it_later_once():
    body = RobotBody(PAPER)
    (motion,) = core.scan_motions(PAPER)
    assert body.nearest(motion, 280.0)[2].startswith("LP1_W")
    assert body.add_carrier(CARRIER) is body
    items = body.obstacles.items
    body.add_carrier(CARRIER)  # the same solids: nothing made again
    assert body.obstacles.items is items and body.obstacles.carrier_count == 55
    assert body.nearest(motion, 270.0)[2] == "LP1 floor"
    assert clearance_for(PAPER).carrier == core.CARRIER_NOT_CHECKED
