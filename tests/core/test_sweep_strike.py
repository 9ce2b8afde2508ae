"""The fork's tines during the sweep (SPEC §13, honest results §3): the wrist-angle ranges over
which a tine (an end of the beam) is inside a wafer, where a real fork would strike it, against a
hand computation for the bundled robot, a brute-force scan of angles, and the warnings and JSON
that say so. The core's closed forms alone turn the whole ±sweep (``scan_layout`` without the
robot's limits): the example is taken at the paper's depth, 26.6 mm (scenarios.slow_jab_deep).
Through the robot, the sweep stops before a tine comes within clearance_min (SPEC §13 amended):
the command line's channels then say that instead."""

import json
import math
from dataclasses import replace
import pytest
from commands import waferscan
from scenarios import SLOW_JAB as EXAMPLE
from scenarios import slow_jab_deep

from waferscan.core.files.report import result_dict
from waferscan.core.model import Beam, Carrier, Layout, MappingTolerances, ScanParameters, Wafer
from waferscan.core.scan import slow_scan
from waferscan.core.scan.layout_scan import scan_layout

EXAMPLE_LAYOUT = slow_jab_deep()

R, T = 150.0, 0.7
SEAT = 300.0
CENTER = (0.0, 400.0)
BEAM_Y = 240.0  # the start pose's beam, 10 mm in front of a seated wafer's front edge
RADIUS = 260.0  # the bundled robot: the wrist 260 mm behind the beam's midpoint
HALF = 80.0     # its 160 mm beam: the tines at x = -80 (emitter) and +80 (receiver)
Z = SEAT + T / 2


def layout(wafers, jab=26.6, sweep=40.0, direction=(1.0, 0.0, 0.0)):
    carrier = Carrier("C", 1, 10.0, SEAT, CENTER, 2 * R, T, front=(0.0, -1.0))
    params = ScanParameters(start_z=SEAT - 5.0, final_z=SEAT + 10.0, z_step=0.05, mode="slow",
                            jab=jab, sweep=sweep)
    return Layout(carriers=(carrier,), wafers=tuple(wafers),
                  beam=Beam((-HALF, BEAM_Y, SEAT - 5.0), direction, 2 * HALF), scan=params,
                  mapping=MappingTolerances(), carrier="C")


def wafer(dx=0.0, dy=0.0, normal=(0.0, 0.0, 1.0)):
    return Wafer("W", (CENTER[0] + dx, CENTER[1] + dy, SEAT), normal, 2 * R, T)


def hand_strike(jab, dx=0.0, dy=0.0):
    """By hand (law of cosines): each tine is sqrt(80² + 260²) from the wrist, the wafer's centre
    D from it; the tine is on the rim where the angle between them is acos((T² + D² - r²) /
    (2 T D)). The emitter's tine (x = -80) starts 17.10° left of the heading and is turned
    clockwise (negative angles) onto the centre's bearing; the receiver's mirrors it."""
    wrist = (0.0, BEAM_Y + jab - RADIUS)
    tine = math.hypot(HALF, RADIUS)
    cx, cy = CENTER[0] + dx - wrist[0], CENTER[1] + dy - wrist[1]
    d = math.hypot(cx, cy)
    r = R + 1e-9  # touching counts (the engines' tolerance)
    spread = math.degrees(math.acos((tine * tine + d * d - r * r) / (2 * tine * d)))
    bearing = math.degrees(math.atan2(cx, cy))  # of the centre, clockwise from the heading
    start = math.degrees(math.atan2(HALF, RADIUS))  # of each tine, from the heading
    left = (-(start + spread) - bearing, -(start - spread) - bearing)
    right = (start - spread - bearing, start + spread - bearing)
    return (left, right)


def brute_force(lay, advance, amplitude, step=0.001):
    """Every angle on a fine grid at which a tine, turned about the wrist by this test's own
    arithmetic, is within the wafer's rim and thickness (level wafers: a disc and a band)."""
    wx, wy = 0.0, BEAM_Y + advance - RADIUS
    inside = []
    n = int(round(2 * amplitude / step))
    for i in range(n + 1):
        a = -amplitude + i * step
        c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
        hit = False
        for x in (-HALF, HALF):
            dx, dy = x - wx, BEAM_Y + advance - wy
            px, py = wx + c * dx - s * dy, wy + s * dx + c * dy
            for w in lay.wafers:
                if (math.hypot(px - w.center[0], py - w.center[1]) <= w.radius
                        and w.center[2] <= Z <= w.center[2] + w.thickness):
                    hit = True
        inside.append((a, hit))
    return inside


def within(angle, spans, margin=0.0):
    return any(lo + margin <= angle <= hi - margin for lo, hi in spans)


def test_the_bundled_robots_tine_enters_a_seated_wafer_at_1_618_degrees():
    strike = slow_scan.sweep_strikes(layout([wafer()]), Z, 26.6, 40.0)
    hand = hand_strike(26.6)
    assert [c for span in strike for c in span] == pytest.approx(
        [c for span in hand for c in span], abs=1e-9)
    # The documented figures (docs/tutorials/slow-scanning.md): -32.588 .. -1.618 and +1.618 ..
    # +32.588 degrees.
    assert [round(c, 3) for span in strike for c in span] == [-32.588, -1.618, 1.618, 32.588]


@pytest.mark.parametrize("dx, dy", [(3.0, 0.0), (0.0, -5.0), (-20.0, 4.0)])
def test_a_shifted_wafer_matches_the_hand_computation(dx, dy):
    strike = slow_scan.sweep_strikes(layout([wafer(dx, dy)]), Z, 26.6, 40.0)
    assert [c for span in strike for c in span] == pytest.approx(
        [c for span in hand_strike(26.6, dx, dy) for c in span], abs=1e-9)


@pytest.mark.parametrize("dx, dy, jab", [(0.0, 0.0, 26.6), (3.0, 0.0, 26.6), (0.0, -5.0, 20.0),
                                         (40.0, 2.0, 15.0)])
def test_the_ranges_agree_with_a_brute_force_scan_of_angles(dx, dy, jab):
    lay = layout([wafer(dx, dy)], jab=jab)
    strike = slow_scan.sweep_strikes(lay, Z, jab, 40.0)
    grid = brute_force(lay, jab, 40.0)
    assert any(hit for _, hit in grid)
    for angle, hit in grid:
        near_edge = any(abs(angle - e) < 1e-6 for span in strike for e in span)
        if not near_edge:
            assert within(angle, strike) == hit, angle


def test_bracket_and_bisect_agrees_with_the_closed_form_to_its_tolerance():
    for lay in (layout([wafer(3.0)]), layout([wafer(-40.0, -7.0)], jab=20.0)):
        jab = lay.scan.jab
        exact = slow_scan.sweep_strikes(lay, Z, jab, 40.0)
        bisected = slow_scan.sweep_strikes(lay, Z, jab, 40.0, exact=False)
        assert len(exact) == len(bisected) == 2
        assert [c for s in bisected for c in s] == pytest.approx(
            [c for s in exact for c in s], abs=2 * slow_scan.SWEEP_TOLERANCE_DEG)


def test_a_tilted_wafers_strike_edges_are_bisected_to_the_tolerance():
    tilt = math.radians(0.05)
    tilted = wafer(normal=(math.sin(tilt), 0.0, math.cos(tilt)))
    lay = layout([tilted])
    strike = slow_scan.sweep_strikes(lay, Z, 26.6, 40.0)
    assert strike
    for lo, hi in strike:
        for edge, into in ((lo, 1), (hi, -1)):
            # Just inside the range a tine is in the wafer (the exact test), just outside none is.
            def any_tine_in(angle):
                return any(slow_scan.tine_inside(p, (1.0, 0.0, 0.0), tilted, 1e-9)
                           for p in slow_scan.tine_points(lay, Z, 26.6, angle))
            if abs(abs(edge) - 40.0) > 1e-12:
                assert any_tine_in(edge + into * 1e-7)
                assert not any_tine_in(edge - into * 1e-7)
    # Tilted 0.05°, the faces move at most 150·tan 0.05° = 0.13 mm at the rim, less than the
    # 0.35 mm between the tines' height and a face: both tines strike, as for a level wafer,
    # and close to its ranges (the rim moves up to 0.13·sin 0.05° mm in plan).
    assert len(strike) == 2
    level = slow_scan.sweep_strikes(layout([wafer()]), Z, 26.6, 40.0)
    assert [c for s in strike for c in s] == pytest.approx([c for s in level for c in s],
                                                           abs=0.01)


def test_a_tine_above_or_below_the_wafers_thickness_does_not_strike_it():
    # The receiver's tine 1 mm above the pocket's height (the beam tilted up), the wafer 0.7 mm
    # thick around it: only the emitter's tine, at the pocket's height, strikes.
    rise = 1.0 / (2 * HALF)
    tilted = layout([wafer()], direction=(math.sqrt(1 - rise * rise), 0.0, rise))
    strike = slow_scan.sweep_strikes(tilted, Z, 26.6, 40.0)
    assert len(strike) == 1 and strike[0][1] < 0.0


def test_an_empty_pocket_has_no_strike():
    assert slow_scan.sweep_strikes(layout([]), Z, 26.6, 40.0) == ()


def test_with_the_bundled_robot_a_sweep_that_finds_its_edges_always_strikes():
    """Why no sweep setting avoids the strike and still finds both edges: for jabs across the
    whole reach, the sweep's edges are where a tine leaves the rim."""
    for jab in (10.5, 12.0, 16.0, 20.0, 26.6, 30.0, 33.0):
        lay = layout([wafer()], jab=jab, sweep=90.0)
        pair = slow_scan.sweep_pair(lay, Z, jab, 90.0)
        strike = slow_scan.sweep_strikes(lay, Z, jab, 90.0)
        assert pair is not None and abs(pair[0]) < 90.0
        assert strike[0][0] == pytest.approx(pair[0], abs=1e-9)
        assert strike[-1][1] == pytest.approx(pair[1], abs=1e-9)


def test_a_sweep_smaller_than_the_tines_entry_angle_does_not_strike():
    # 1.6° is short of a seated wafer's 1.618°, not of the wafers nearer the fork: slot 3's
    # (3 mm to the right) is met at +1.184°, slot 8's (5 mm out) at ±0.360°.
    lay = replace(EXAMPLE_LAYOUT, scan=replace(EXAMPLE_LAYOUT.scan, sweep=1.6))
    struck = {p.slot: p.strike for p in scan_layout(lay).pockets if p.strike}
    assert sorted(struck) == [3, 8]
    assert len(struck[3]) == 1
    assert list(struck[3][0]) == pytest.approx([hand_strike(26.6, 3.0)[1][0], 1.6], abs=1e-9)
    lay = replace(EXAMPLE_LAYOUT, scan=replace(EXAMPLE_LAYOUT.scan, sweep=0.3))
    result = scan_layout(lay)
    assert all(p.strike == () for p in result.pockets)
    assert not any("tine" in w for w in result.warnings)
    # Honest still: such a sweep is blocked at its ends, so it judges no position.
    assert any("still blocked at its end" in w for w in result.warnings)
    assert all(s["sweep_strike"] is None for s in result_dict(result)["slots"])


EXAMPLE_RESULT = scan_layout(EXAMPLE_LAYOUT)


def test_the_example_warns_once_for_the_seated_pockets_and_once_for_each_other():
    lines = [w for w in EXAMPLE_RESULT.warnings if "tine" in w]
    assert lines == [
        "slots 1, 2, 4, 7, 10, 16, 18, 24: the sweep turns a tine (an end of the beam) into the "
        "wafer from -32.588 to -1.618 deg and from +1.618 to +32.588 deg (a real fork would "
        "strike it)",
        "slot 3: the sweep turns a tine (an end of the beam) into the wafer from -33.022 to "
        "-2.058 deg and from +1.184 to +32.148 deg (a real fork would strike it)",
        "slot 8: the sweep turns a tine (an end of the beam) into the wafer from -33.845 to "
        "-0.360 deg and from +0.360 to +33.845 deg (a real fork would strike it)"]
    # Slot 3 by hand: the wafer 3 mm to the right.
    jab = EXAMPLE_LAYOUT.scan.jab
    slot3 = next(p for p in EXAMPLE_RESULT.pockets if p.slot == 3)
    assert [c for s in slot3.strike for c in s] == pytest.approx(
        [c for s in hand_strike(jab, 3.0) for c in s], abs=1e-9)


def test_json_gives_each_slot_its_strike_ranges_or_null():
    data = json.loads(json.dumps(result_dict(EXAMPLE_RESULT)))
    by_slot = {s["slot"]: s["sweep_strike"] for s in data["slots"]}
    assert len(by_slot[1]) == 2 and all(len(span) == 2 for span in by_slot[1])
    assert [c for span in by_slot[1] for c in span] == pytest.approx(
        [c for span in hand_strike(26.6) for c in span], abs=1e-9)
    assert by_slot[13] is None  # an empty pocket
    loaded = {p.slot for p in EXAMPLE_RESULT.pockets if p.sweep is not None}
    assert {s for s, v in by_slot.items() if v is not None} == loaded


def test_through_the_robot_no_sweep_strikes_and_every_channel_says_where_each_stopped(tmp_path):
    # slow_jab.toml as it is (a 20 mm jab) through the command line: the robot's clearance stops
    # each sweep (SPEC §13 amended) before a tine reaches a wafer, so nothing strikes, and
    # JSON, stderr and results.txt agree on where the sweeps stopped.
    out = tmp_path / "results.txt"
    run = waferscan("scan", EXAMPLE, "--json", "--out", out)
    assert run.returncode == 0, run.stderr
    data = json.loads(run.stdout)
    assert all(s["sweep_strike"] is None for s in data["slots"])
    assert not any("a tine" in w for w in data["warnings"])
    stopped = [w for w in data["warnings"] if "the sweep stopped where" in w]
    assert len(stopped) == 3  # the seated pockets together, slot 3 and slot 8
    assert [line for line in run.stderr.splitlines() if "the sweep stopped where" in line] == [
        f"waferscan: warning: {w}" for w in stopped]
    lines = out.read_text(encoding="utf-8").splitlines()
    assert "status = ok" in lines
    assert not [line for line in lines if line.startswith("collision = ")]
    assert [line for line in lines if line.startswith("warning = ") and "sweep stopped" in line]


@pytest.mark.parametrize("slot, center", [(1, (0.0, 0.0)), (3, (3.0, 0.0)), (8, (0.0, -5.0))])
def test_the_plan_draws_each_tines_path_inside_the_wafer(slot, center):
    from waferscan.core.scan import pocket_plan as plans

    plan = plans.pocket_plan(EXAMPLE_RESULT, slot)
    probe = next(p for p in EXAMPLE_RESULT.pockets if p.slot == slot)
    # slow_jab.toml from above, the carrier's centre at the origin: the wrist 260 mm behind the
    # deepest beam (v = 240 + 26.6 - 400); each tine sqrt(80² + 260²) mm from it.
    wrist = (0.0, 240.0 + 26.6 - 400.0 - 260.0)
    assert [a.tine for a in plan.strikes] == ["emitter", "receiver"]
    assert [a.angles for a in plan.strikes] == list(probe.strike)
    for arc in plan.strikes:
        assert all(math.dist(p, wrist) == pytest.approx(math.hypot(80.0, 260.0), abs=1e-9)
                   for p in arc.points)
        assert all(math.dist(p, center) <= 150.0 + 1e-6 for p in arc.points)
        # It starts and ends on the rim, where the tine enters and leaves the wafer.
        assert math.dist(arc.points[0], center) == pytest.approx(150.0, abs=1e-6)
        assert math.dist(arc.points[-1], center) == pytest.approx(150.0, abs=1e-6)
        steps = [math.dist(a, b) for a, b in zip(arc.points, arc.points[1:])]
        assert max(steps) <= math.radians(plans.STRIKE_ARC_STEP_DEG) * 272.03
    assert plan.strikes[0].label == (f"emitter tine in the wafer {probe.strike[0][0]:+.3f}° to "
                                     f"{probe.strike[0][1]:+.3f}°")


def test_a_pocket_without_a_wafer_draws_no_strike():
    from waferscan.core.scan import pocket_plan as plans

    assert plans.pocket_plan(EXAMPLE_RESULT, 13).strikes == ()
