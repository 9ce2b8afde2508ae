"""SPEC §13 amended: a slow scan's sweep turns only as far as the fork stays clearance_min from
every wafer; it reports the angles it reached; a sweep that cannot turn at all is bad input.

Hand geometry (tests/robot/test_clearance.py): the bundled robot's tines are boxes whose inner
tip corners lie 70 mm either side of the fork's centre line, at the beam. In slow_jab.toml the
beam starts at Y = 240 and the jab advances it along +Y; the wrist's vertical axis is 260 mm
behind the beam's midpoint, on the carrier's centre line X = 0, and a seated wafer's centre is
(0, 400), radius 150. Turning the wrist by +phi (counter-clockwise seen from above) takes the
right tine's inner tip corner, (70, 260) from the wrist, to (70 cos phi - 260 sin phi,
70 sin phi + 260 cos phi): towards the wafer's rim. Turning by -phi takes the left one there,
by symmetry."""

import math
from dataclasses import replace

import pytest
from scenarios import SLOW_JAB

from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import Wafer
from waferscan.core.scan import clearance as core
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.robot.clearance import RobotBody, clearance_for

SLOW = read_scenario(SLOW_JAB)
SEAT = SLOW.scanned_carrier.seat_z


def _corner_gap(phi_deg, depth):
    """The inner tip corner's distance from a seated wafer's rim, turned by phi (hand)."""
    phi = math.radians(phi_deg)
    x = 70.0 * math.cos(phi) - 260.0 * math.sin(phi)
    y = (240.0 + depth - 260.0) + 70.0 * math.sin(phi) + 260.0 * math.cos(phi)
    return math.hypot(x, y - 400.0) - 150.0


def _angle_at_gap(gap, depth):
    """The turn (deg, > 0) at which the corner comes within ``gap`` of the rim: bisection on
    the hand formula (it falls monotonically over the first degrees)."""
    lo, hi = 0.0, 10.0
    assert _corner_gap(lo, depth) > gap > _corner_gap(hi, depth)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _corner_gap(mid, depth) > gap else (lo, mid)
    return lo


def _one_wafer(depth, clearance_min, wafer=None, sweep=40.0):
    wafer = wafer or Wafer("w1", (0.0, 400.0, SEAT(1)), (0.0, 0.0, 1.0), 300.0, 0.7)
    layout = replace(SLOW, wafers=(wafer,)).with_scan(jab=depth, sweep=sweep)
    return replace(layout, mapping=replace(layout.mapping, clearance_min=clearance_min))


def test_the_sweep_stops_where_a_tine_corner_comes_within_clearance_min():
    layout = _one_wafer(20.0, 1.0)
    body = RobotBody(layout)
    z = SEAT(1) + 0.35
    low, high = core.sweep_reach(body, 1, z, 20.0, 40.0, 1.0)
    # Hand: sqrt(70² + 140²) - 150 = 6.525 mm from the rim before the turn; 1 mm at +/-1.8495 deg.
    assert _corner_gap(0.0, 20.0) == pytest.approx(6.525, abs=1e-3)
    limit = _angle_at_gap(1.0, 20.0)
    assert limit == pytest.approx(1.8495, abs=1e-4)
    # It stops short of the limit, never beyond, and within 1 µm of clearance there.
    for reached, tine in ((high, "tine_right"), (-low, "tine_left")):
        assert limit - 1e-3 < reached <= limit
        assert 1.0 <= _corner_gap(reached, 20.0) < 1.0 + core.TOLERANCE
    motion = core.Motion(core.SWEEP, "slot 1 sweep", 1, low, high, z, 20.0)
    distance, part, obstacle, _ = body.nearest(motion, high)
    assert part == "tine_right" and obstacle == "w1"
    assert distance == pytest.approx(_corner_gap(high, 20.0), abs=1e-5)  # the jab by IK


def test_the_scan_reports_the_angles_reached_and_its_sweep_never_comes_closer():
    layout = _one_wafer(20.0, 1.0)
    body = RobotBody(layout)
    result = scan_layout(layout, turn_limits=core.turn_limits(body, 1.0))
    probe = result.pockets[0]
    limit = _angle_at_gap(1.0, 20.0)
    assert probe.reached[0] == pytest.approx(-limit, abs=1e-3)
    assert probe.reached[1] == pytest.approx(limit, abs=1e-3)
    # The beam crosses the wafer all the way (its ends are the tines, outside the rim): the
    # sweep is blocked at both angles reached, and no strike is left to report.
    assert probe.sweep == pytest.approx(probe.reached, abs=1e-9)
    assert probe.strike == () and probe.shift is None
    assert any("the sweep stopped where the fork comes within clearance_min" in w
               for w in result.warnings)
    # Checked along the motion it made: no contact, the least at clearance_min.
    report = clearance_for(layout, body, result.pockets)
    sweep = [c for c in report.closest if c.motion.kind == core.SWEEP][0]
    assert (sweep.motion.start, sweep.motion.end) == probe.reached
    assert 1.0 <= sweep.distance < 1.0 + core.TOLERANCE and not report.contacts
    # Without the limits (the core alone), the whole +/-40 deg is turned through the wafer.
    free = scan_layout(layout).pockets[0]
    assert free.reached == (-40.0, 40.0) and free.strike


def test_an_empty_pocket_turns_the_whole_sweep():
    layout = _one_wafer(20.0, 1.0)
    body = RobotBody(layout)
    assert core.sweep_reach(body, 10, SEAT(10) + 0.35, 20.0, 40.0, 1.0) == (-40.0, 40.0)


def test_a_wafer_shifted_right_stops_the_right_turn_sooner():
    # Shifted 3 mm to the right, the wafer comes to the right tine (turning +) sooner and to the
    # left one (turning -) later than a seated one's.
    shifted = Wafer("w1", (3.0, 400.0, SEAT(1)), (0.0, 0.0, 1.0), 300.0, 0.7)
    layout = _one_wafer(20.0, 1.0, shifted)
    low, high = core.sweep_reach(RobotBody(layout), 1, SEAT(1) + 0.35, 20.0, 40.0, 1.0)
    limit = _angle_at_gap(1.0, 20.0)
    assert high < limit - 0.2 and -low > limit + 0.2


def test_a_sweep_that_cannot_turn_names_the_pocket_and_where_a_tine_would_meet_the_wafer():
    # The paper's depth (26.6 mm: the corner 0.650 mm from the rim) under clearance_min 1 mm.
    layout = _one_wafer(26.6, 1.0)
    body = RobotBody(layout)
    with pytest.raises(core.SweepBlocked) as raised:
        core.sweep_reach(body, 1, SEAT(1) + 0.35, 26.6, 40.0, 1.0)
    exc = raised.value
    assert exc.slot == 1 and exc.closest[0] == pytest.approx(_corner_gap(0.0, 26.6), abs=1e-5)
    touch = _angle_at_gap(0.0, 26.6)
    assert exc.meets[0] == pytest.approx(-touch, abs=2e-3)
    assert exc.meets[1] == pytest.approx(touch, abs=2e-3)
    assert str(exc) == (f"sweep: cannot turn at slot 1: before it turns, {exc.closest[1]} is "
                        f"0.650 mm from w1, under clearance_min 1 mm; turning, the fork would "
                        f"touch at {exc.meets[0]:+.3f} deg or {exc.meets[1]:+.3f} deg")
    # Under 0.5 mm it can turn, a little: to where the corner is 0.5 mm from the rim.
    low, high = core.sweep_reach(body, 1, SEAT(1) + 0.35, 26.6, 40.0, 0.5)
    assert high == pytest.approx(_angle_at_gap(0.5, 26.6), abs=1e-3) and high < 0.1


def test_reach_along_is_conservative_on_a_fine_scan_of_the_turn():
    # Every angle up to the one reached keeps clearance_min, checked on a fine grid.
    layout = _one_wafer(20.0, 3.0)
    body = RobotBody(layout)
    z = SEAT(1) + 0.35
    motion = core.Motion(core.SWEEP, "slot 1 sweep", 1, 0.0, 40.0, z, 20.0)
    reached, near = core.reach_along(body, motion, 3.0)
    assert 3.0 <= near[0] < 3.0 + core.TOLERANCE
    assert min(body.nearest(motion, reached * k / 400.0)[0] for k in range(401)) >= 3.0
    assert reached == pytest.approx(_angle_at_gap(3.0, 20.0), abs=1e-3)


def _seated(layout):
    from waferscan.core.scan.slow_scan import seated_wafer

    carrier = layout.scanned_carrier
    return replace(layout, wafers=tuple(seated_wafer(carrier, s)
                                        for s in range(1, carrier.slot_count + 1)))


def test_a_wafer_that_blocks_the_turn_is_a_contact_a_recipe_that_does_is_bad_input():
    # slow_jab.toml at a 22 mm jab: a seated wafer leaves the tines' corners
    # sqrt(70² + 138²) - 150 = 4.74 mm away, but slot 8's wafer, pushed 5 mm out, 0.296 mm:
    # its pocket's sweep cannot turn under 1 mm. What is in the pocket is to blame, not the
    # recipe: the sweep turns (0, 0), the jab's contact says why, and the scan is made.
    layout = SLOW.with_scan(jab=22.0)
    body = RobotBody(layout)
    limits = core.turn_limits(body, 1.0, seated=lambda: RobotBody(_seated(layout)))
    result = scan_layout(layout, turn_limits=limits)
    slot8 = next(p for p in result.pockets if p.slot == 8)
    assert slot8.reached == (0.0, 0.0) and slot8.shift is None
    assert next(p for p in result.pockets if p.slot == 1).reached[1] > 1.0
    assert any(w.startswith("slot 8: the sweep could not turn: before it turns the fork is "
                            "already within clearance_min (1 mm)") for w in result.warnings)
    report = clearance_for(layout, body, result.pockets)
    jab8 = next(c for c in report.closest if c.motion.kind == core.JAB and c.motion.slot == 8)
    assert jab8 in report.contacts and jab8.distance == pytest.approx(0.296, abs=1e-3)
    assert result.slot_map.code[7] == "6"  # still read: protruding
    # At 26.6 mm a seated wafer blocks the turn too (0.650 mm): the recipe is bad input.
    deep = SLOW.with_scan(jab=26.6)
    limits = core.turn_limits(RobotBody(deep), 1.0, seated=lambda: RobotBody(_seated(deep)))
    with pytest.raises(core.SweepBlocked, match="cannot turn at slot 1"):
        scan_layout(deep, turn_limits=limits)
