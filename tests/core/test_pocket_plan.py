"""A pocket seen from above (core/scan/pocket_plan.py): the beams and the points where they met the
wafer, in the carrier's own plan coordinates, against a hand computation on slow_jab.toml."""

import math
from dataclasses import replace
import pytest
from scenarios import SLOW_JAB as EXAMPLE

from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import Beam
from waferscan.core.scan import pocket_plan as plans
from waferscan.core.scan.layout_scan import scan_layout

LAYOUT = read_scenario(EXAMPLE)
RESULT = scan_layout(LAYOUT)
# slow_jab.toml from above, the carrier's centre (0, 400) at the origin, v into the carrier:
START_V = 240.0 - 400.0          # the start pose's beam
DEEPEST_V = START_V + 20.0       # after the jab
WRIST = (0.0, DEEPEST_V - 260.0)  # sweep_radius behind the beam's midpoint (x = 0)


def flat(points):
    """Nested (u, v) pairs as one list, for pytest.approx."""
    return [c for point in points for c in point]


def turned(point, degrees, about=WRIST):
    a = math.radians(degrees)
    dx, dy = point[0] - about[0], point[1] - about[1]
    return (about[0] + math.cos(a) * dx - math.sin(a) * dy,
            about[1] + math.sin(a) * dx + math.cos(a) * dy)


def test_a_protruding_wafer_is_met_5_mm_early_at_its_front_point():
    plan = plans.pocket_plan(RESULT, 8)
    assert plan.seated.center == pytest.approx((0.0, 0.0)) and plan.seated.radius == 150.0
    (wafer,) = plan.wafers
    assert wafer.center == pytest.approx((0.0, -5.0))  # pushed 5 mm out of the opening
    assert flat(plan.beam(plans.START).ends) == pytest.approx([-80.0, START_V, 80.0, START_V])
    front = plan.beam(plans.FRONT)
    # The rim's front point is at v = -5 - 150 = -155: 5 mm in from the start pose.
    assert flat(front.ends) == pytest.approx([-80.0, -155.0, 80.0, -155.0], abs=1e-6)
    assert front.contact == pytest.approx((0.0, -155.0), abs=1e-6)
    assert front.label == "front 5.000 mm"
    assert flat(plan.beam(plans.DEEPEST).ends) == pytest.approx([-80.0, DEEPEST_V,
                                                                 80.0, DEEPEST_V])
    assert plan.wrist == pytest.approx(WRIST)
    assert plan.title.startswith("slot 8 at Z 364.290 mm: front 5.000 mm (seated 10.000)")


@pytest.mark.parametrize("slot, center", [(8, (0.0, -5.0)), (3, (3.0, 0.0)), (1, (0.0, 0.0))])
def test_the_sweeps_edges_are_the_deepest_beam_turned_about_the_wrist_touching_the_rim(slot,
                                                                                      center):
    plan = plans.pocket_plan(RESULT, slot)
    probe = next(p for p in RESULT.pockets if p.slot == slot)
    for role, angle in ((plans.SWEEP_FIRST, probe.sweep[0]), (plans.SWEEP_LAST, probe.sweep[1])):
        beam = plan.beam(role)
        ends = [turned((-80.0, DEEPEST_V), angle), turned((80.0, DEEPEST_V), angle)]
        assert flat(beam.ends) == pytest.approx(flat(ends), abs=1e-9)
        # At an edge of the sweep one end of the beam (a tine) lies on the wafer's rim: there.
        touching = [e for e in ends if abs(math.dist(e, center) - 150.0) < 1e-6]
        assert len(touching) == 1
        assert beam.contact == pytest.approx(touching[0], abs=1e-9)
        assert beam.label == f"{angle:+.3f}°"


def test_a_wafer_shifted_sideways_is_met_at_its_own_front_point():
    plan = plans.pocket_plan(RESULT, 3)
    assert plan.wafers[0].center == pytest.approx((3.0, 0.0))
    assert plan.beam(plans.FRONT).contact == pytest.approx((3.0, -150.0), abs=1e-6)
    assert "shift +3.000 mm" in plan.title


def test_a_pocket_the_jab_and_sweep_never_blocked_has_no_contacts():
    plan = plans.pocket_plan(RESULT, 13)  # empty
    assert [b.role for b in plan.beams] == [plans.START, plans.DEEPEST]
    assert plan.wafers == ()
    assert plan.title == ("slot 13 at Z 414.290 mm: jab met nothing (seated 10.000); sweep met "
                          "nothing")
    assert plans.pocket_plan(RESULT, 26) is None
    assert plans.pocket_plan(scan_layout(replace(LAYOUT, scan=replace(LAYOUT.scan, jab=0.0,
                                                                      sweep=0.0))), 8) is None


def test_the_slots_judged_by_the_probes_come_first():
    # Slot 3 off position by its sweep (5), slot 8 protruding by its jab (6).
    assert plans.chosen_slots(RESULT) == [3, 8, 1, 2]


def test_the_plan_is_the_carriers_own_whatever_way_it_faces():
    # The whole cell turned 90° counter-clockwise about the carrier's centre: the carrier's
    # plan coordinates do not change.
    def turn(x, y):
        return (-(y - 400.0), x + 400.0)

    carrier = LAYOUT.scanned_carrier
    turned_carrier = replace(carrier, center=turn(*carrier.center), front=(1.0, 0.0))
    beam = LAYOUT.beam
    ex, ey = turn(beam.emitter[0], beam.emitter[1])
    dx, dy = -beam.direction[1], beam.direction[0]
    wafers = tuple(replace(w, center=(*turn(w.center[0], w.center[1]), w.center[2]),
                           normal=(-w.normal[1], w.normal[0], w.normal[2]))
                   for w in LAYOUT.wafers)
    layout = replace(LAYOUT, carriers=(turned_carrier,), wafers=wafers, robot=None,
                     beam=Beam((ex, ey, beam.emitter[2]), (dx, dy, beam.direction[2]),
                               beam.length))
    result = scan_layout(layout)
    for slot in (3, 8):
        a, b = plans.pocket_plan(RESULT, slot), plans.pocket_plan(result, slot)
        for role in (plans.FRONT, plans.SWEEP_FIRST, plans.SWEEP_LAST):
            assert b.beam(role).contact == pytest.approx(a.beam(role).contact, abs=1e-6)
