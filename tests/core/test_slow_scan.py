"""Slow scanning's jab and sweep (SPEC §13) against closed forms worked by hand."""

import math
from dataclasses import replace

import pytest

from waferscan.core.model import Beam, Carrier, Layout, MappingTolerances, ScanParameters, Wafer
from waferscan.core.scan import slow_scan
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.scan.scan_result import slot_plan

R, T = 150.0, 0.7
SEAT = 300.0
CENTER = (0.0, 400.0)
BEAM_Y = 240.0  # the start pose's beam: 10 mm in front of a seated wafer's front edge (250)
RADIUS = 260.0  # the bundled robot: wrist axis 260 mm behind the beam (resources/robots)
HALF = 80.0     # its beam: 160 mm, emitter on the -X side, receiver on the +X side


def layout(wafers, jab=30.0, sweep=40.0, slots=1, **scan):
    carrier = Carrier("C", slots, 10.0, SEAT, CENTER, 2 * R, T, front=(0.0, -1.0))
    start = SEAT - 5.0
    params = ScanParameters(start_z=start, final_z=SEAT + 10.0 * slots, z_step=0.05,
                            mode="slow", jab=jab, sweep=sweep, **scan)
    return Layout(carriers=(carrier,), wafers=tuple(wafers),
                  beam=Beam((-HALF, BEAM_Y, start), (1.0, 0.0, 0.0), 2 * HALF), scan=params,
                  mapping=MappingTolerances(), carrier="C")


def wafer(dx=0.0, dy=0.0, name="W", seat=SEAT):
    return Wafer(name, (CENTER[0] + dx, CENTER[1] + dy, seat), (0.0, 0.0, 1.0), 2 * R, T)


Z = SEAT + T / 2  # the pocket's jab height


def test_heading_points_into_the_carrier():
    assert slow_scan.heading(layout([wafer()])) == pytest.approx((0.0, 1.0, 0.0))
    flipped = layout([wafer()])
    flipped = replace(flipped, beam=Beam((HALF, BEAM_Y, SEAT - 5), (-1.0, 0.0, 0.0), 2 * HALF))
    assert slow_scan.heading(flipped) == pytest.approx((0.0, 1.0, 0.0))


def test_a_wafer_pushed_4_mm_out_is_met_4_mm_earlier():
    seated = slow_scan.jab_front(layout([wafer()]), Z, 30.0)
    pushed = slow_scan.jab_front(layout([wafer(dy=-4.0)]), Z, 30.0)
    # Closed form: the segment spans x = 0, so it first touches the rim's nearest point.
    assert seated == pytest.approx(CENTER[1] - R - BEAM_Y, abs=1e-9)  # 10 mm
    assert pushed == pytest.approx(seated - 4.0, abs=1e-9)


def test_jab_meets_nothing_beyond_its_reach_or_in_an_empty_pocket():
    assert slow_scan.jab_front(layout([wafer()]), Z, 9.0) is None
    assert slow_scan.jab_front(layout([]), Z, 30.0) is None
    # Already blocked at the start pose: front 0.
    assert slow_scan.jab_front(layout([wafer(dy=-20.0)]), Z, 30.0) == 0.0


def test_jab_off_centre_meets_the_rim_where_the_beam_end_touches_it():
    # A wafer shifted 100 mm sideways: the nearest point of the segment's span to the rim is the
    # receiver end at x = 80: rim's y there is cy - sqrt(R^2 - 20^2).
    # Touching counts (rim and beam ends grown by 1e-9 mm): met a few 1e-9 mm earlier.
    front = slow_scan.jab_front(layout([wafer(dx=100.0)]), Z, 40.0)
    assert front == pytest.approx(CENTER[1] - math.sqrt(R * R - 20.0 ** 2) - BEAM_Y, abs=1e-8)


def _endpoint_roots(s, rho, cx, cy):
    """By hand: the beam's end (s, rho) in the wrist's frame turned by phi lies on the rim when
    cos(phi)(s cx + rho cy) + sin(phi)(s cy - rho cx) = (s² + rho² + |c|² - R²)/2."""
    a, b = s * cx + rho * cy, s * cy - rho * cx
    k = 0.5 * (s * s + rho * rho + cx * cx + cy * cy - R * R)
    m = math.hypot(a, b)
    base, spread = math.atan2(b, a), math.acos(k / m)
    return sorted(math.degrees(base + sign * spread) for sign in (-1, 1))


@pytest.mark.parametrize("shift", [0.0, 3.0, -3.0])
def test_sweep_angles_match_a_hand_computation_for_the_bundled_robot(shift):
    lay = layout([wafer(dx=shift)])
    assert slow_scan.jab_front(lay, Z, 30.0) == pytest.approx(10.0, abs=1e-9)  # unmoved by it
    depth = 30.0  # the jab's deepest point: the beam 20 mm into the wafer
    first, last = slow_scan.sweep_pair(lay, Z, depth, 40.0)
    # Wrist frame: axis at the origin, heading +y; the beam at rho = 260, ends at s = -80, +80.
    rho = RADIUS
    cx, cy = shift, CENTER[1] - (BEAM_Y + depth - RADIUS)
    # Turning counter-clockwise carries the +80 end into the wafer and out again on its far side:
    # the last blocked angle is where it leaves; the -80 end likewise for negative angles.
    assert last == pytest.approx(_endpoint_roots(HALF, rho, cx, cy)[1], abs=1e-9)
    assert first == pytest.approx(_endpoint_roots(-HALF, rho, cx, cy)[0], abs=1e-9)
    if shift == 0.0:
        assert first == pytest.approx(-last, abs=1e-9)
    else:  # off-centre: both ends turn by the wafer's bearing from the wrist, atan(shift / 410)
        centred = slow_scan.sweep_pair(layout([wafer()]), Z, depth, 40.0)
        bearing = -math.degrees(math.atan2(shift, cy))
        assert 0.5 * (first + last) == pytest.approx(bearing, abs=2e-3)
        # The shifted centre is sqrt(cy² + 3²) - cy = 0.011 mm further out: a slightly
        # narrower pair (0.006 deg).
        assert last - first == pytest.approx(centred[1] - centred[0], abs=0.01)


def test_bracket_and_bisect_agrees_with_the_closed_form_within_its_tolerance():
    for lay in (layout([wafer(dx=3.0)]), layout([wafer(dx=-40.0, dy=-7.0)])):
        exact = slow_scan.sweep_pair(lay, Z, 10.0, 30.0)
        bisected = slow_scan.sweep_pair(lay, Z, 10.0, 30.0, exact=False)
        assert bisected == pytest.approx(exact, abs=2 * slow_scan.SWEEP_TOLERANCE_DEG)


def test_the_sweep_of_a_tilted_wafer_is_bisected_to_its_tolerance():
    tilt = math.radians(1.0)
    tilted = replace(wafer(), normal=(math.sin(tilt), 0.0, math.cos(tilt)))
    lay = layout([tilted])
    first, last = slow_scan.sweep_pair(lay, Z, 12.0, 30.0)
    for angle, inside in ((first, -1), (last, 1)):
        # Just inside the pair blocked, just outside clear: the edge is found to the tolerance.
        e, b = slow_scan.beam_at(lay, Z, 12.0, angle - inside * 1e-7)
        assert slow_scan.beam_hits_wafer(e, b, tilted)
        e, b = slow_scan.beam_at(lay, Z, 12.0, angle + inside * 1e-7)
        assert not slow_scan.beam_hits_wafer(e, b, tilted)


def test_an_empty_pocket_has_no_sweep():
    assert slow_scan.sweep_pair(layout([]), Z, 30.0, 30.0) is None


def test_scan_reports_front_and_sweep_and_judges_them():
    lay = layout([wafer(name="ok"), wafer(dx=3.0, seat=SEAT + 10, name="side"),
                  wafer(dy=-4.0, seat=SEAT + 20, name="out")], slots=4)
    result = scan_layout(lay)
    fronts = [p.front for p in result.pockets]
    assert fronts[:3] == pytest.approx([10.0, 10.0, 6.0], abs=1e-9)
    assert fronts[3] is None  # empty pocket: the jab went its whole reach
    assert result.pockets[3].depth == 30.0 and result.pockets[3].sweep is None
    assert result.pockets[1].shift == pytest.approx(3.0, abs=1e-3)
    assert abs(result.pockets[0].shift) < 1e-9
    assert result.code == "1560"
    assert any("slot 2" in w and "3.000 mm to the right" in w and "position error" in w
               for w in result.warnings)


def test_jab_decides_protrusion_when_made():
    # Pushed 1.5 mm: beyond the 1 mm limit for the jab and for the load port alike.
    lay = layout([wafer(dy=-1.5)])
    assert scan_layout(lay).code == "6"
    # A limit of 2 mm: present by the jab's front (8.5 against 10).
    lay = replace(lay, mapping=MappingTolerances(protrusion_limit=2.0))
    assert scan_layout(lay).code == "1"


def test_a_start_pose_inside_the_wafers_is_said_to_be_blind_to_protrusion():
    lay = replace(layout([wafer()]), beam=Beam((-HALF, 260.0, SEAT - 5), (1.0, 0.0, 0.0), 160.0))
    result = scan_layout(lay)
    assert result.pockets[0].front == 0.0
    assert any("cannot tell a protruding wafer" in w for w in result.warnings)


def test_sweep_blocked_at_its_end_is_said_and_not_judged():
    result = scan_layout(layout([wafer(dx=3.0)], sweep=10.0))
    assert result.pockets[0].sweep == (-10.0, 10.0)
    assert result.code == "1"
    assert any("still blocked at its end" in w for w in result.warnings)


def test_jab_and_sweep_zero_change_nothing():
    lay = layout([wafer(), wafer(dx=3.0, seat=SEAT + 10)], slots=2)
    plain = scan_layout(replace(lay, scan=replace(lay.scan, jab=0.0, sweep=0.0)))
    assert plain.pockets == ()
    assert plain.warnings == ()
    # Fast scans never jab.
    fast = scan_layout(replace(lay, scan=replace(lay.scan, mode="fast")))
    assert fast.pockets == ()


def test_move_time_trapezoid_and_triangle():
    assert slow_scan.move_time(100.0, 50.0) == pytest.approx(2.0)
    # Trapezoid: 100 mm at 50 mm/s, 100 mm/s²: 2 s cruising-equivalent + 0.5 s.
    assert slow_scan.move_time(100.0, 50.0, 100.0) == pytest.approx(2.5)
    # Triangle: 4 mm at 100 mm/s² never reaches 50 mm/s: 2 sqrt(4/100).
    assert slow_scan.move_time(4.0, 50.0, 100.0) == pytest.approx(0.4)


def test_slow_scan_takes_longer_than_fast_and_adds_the_arm_moves():
    lay = layout([wafer()], jab=30.0, sweep=30.0)
    plan = slot_plan(lay.scanned_carrier, lay.mapping)
    result = scan_layout(lay)
    fast = slow_scan.fast_duration(lay.scan)
    plain = slow_scan.slow_duration(lay.scan, plan)
    slow = slow_scan.slow_duration(lay.scan, plan, result.pockets)
    assert fast == pytest.approx(15.0 / 100.0)
    scan = lay.scan
    pocket = result.pockets[0]
    arm = 2 * slow_scan.move_time(pocket.depth, scan.arm_speed, scan.arm_acceleration)
    wrist = (2 * slow_scan.move_time(30.0, 90.0, 360.0) + slow_scan.move_time(60.0, 90.0, 360.0))
    # The pocket's window is 295..305 mm; the lift goes back down to 300.35 for the jab.
    lift_back = (305.0 - Z) / scan.scan_speed
    assert slow - plain == pytest.approx(arm + wrist + lift_back, rel=1e-9)
    assert slow > fast
    assert result.durations == pytest.approx({"fast": fast, "slow": slow})


def test_without_jab_or_sweep_the_mcs_files_are_as_before():
    from waferscan.cli import paper_scenario
    from waferscan.core.files.mcs import RESULT_COLUMNS, format_parameters, format_results
    from waferscan.core.files.report import result_dict
    from waferscan.core.files.scenario import read_scenario

    paper = read_scenario(paper_scenario())
    for mode in ("fast", "slow"):
        result = scan_layout(paper.with_scan(mode=mode))
        text = format_results(1, "SCF", result, timestamp="T")
        assert "\n" + "\t".join(RESULT_COLUMNS) + "\n" in text
        assert "front" not in text and "duration" not in text and "jab" not in text
        assert "jab" not in format_parameters(result.layout)
        data = result_dict(result)
        assert all(s["front"] is None and s["sweep"] is None for s in data["slots"])
        assert result.pockets == ()


def test_parameters_txt_sets_and_refuses_slow_settings():
    from waferscan.cli import paper_scenario
    from waferscan.core.errors import InputError
    from waferscan.core.files.mcs import apply_parameters, format_parameters, parse_parameters
    from waferscan.core.files.scenario import read_scenario

    paper = read_scenario(paper_scenario())
    layout = apply_parameters(paper, parse_parameters("mode = slow\njab = 6.25\nsweep = 30\n"
                                                      "wrist_speed = 45\n"))
    assert (layout.scan.jab, layout.scan.sweep, layout.scan.wrist_speed) == (6.25, 30.0, 45.0)
    assert "jab = 6.25\nsweep = 30.0\nwrist_speed = 45.0\n" in format_parameters(layout)
    with pytest.raises(InputError, match=r"parameters.txt:2: sweep: must be at most 90"):
        apply_parameters(paper, parse_parameters("jab = 1\nsweep = 91\n"))


def test_a_wafer_the_jab_passes_over_still_protrudes_by_the_load_port():
    """Issue 24 item 1: the jab runs at seat + t/2 (300.35); a wafer 1.5 mm out and 0.45 mm
    below its seat (299.55 to 300.25, inside the ±0.5 mm seat window) lies wholly below it, so
    the jab meets nothing; the load port's protrusion check still sees its front edge 1.5 mm
    out (SPEC §4: 6 however it is seated). The jab adds evidence, it never removes it."""
    low = wafer(dy=-1.5, seat=SEAT - 0.45)
    lay = layout([low], jab=20.0, sweep=0.0)
    result = scan_layout(lay)
    # By hand: the wafer's top 300.25 < the jab's height 300.35; the start pose's beam is at
    # Y = 240, the wafer's front edge at 250 - 1.5 = 248.5, so the jab could reach it (20 mm).
    assert SEAT - 0.45 + T < Z
    assert result.pockets[0].front is None
    assert [(name, round(mm, 9)) for name, mm in result.protrusions] == [("W", 1.5)]
    # The stepped run (fork in, 20 mm advanced) is a seated, present wafer by thickness and
    # position; the protrusion outranks it.
    assert result.code == "6"
    assert any("slot 1" in w and "1.500 mm" in w and "jab" in w for w in result.warnings)
    # The same wafer at the jab's height: the jab meets it 1.5 mm early and agrees.
    met = scan_layout(layout([wafer(dy=-1.5)], jab=20.0, sweep=0.0))
    assert met.pockets[0].front == pytest.approx(10.0 - 1.5, abs=1e-9)
    assert met.code == "6" and not any("jab" in w for w in met.warnings)


def test_a_blind_jab_keeps_the_load_ports_protrusion():
    """Issue 24 item 1, the paper's carrier with slot 8 loaded 6 (5 mm out): fast, slow without
    a jab and slow with a 5 mm jab all read 6 in slot 8 (the jab starts inside the wafers, so
    it is blind: it cannot clear a wafer the load port sees sticking out)."""
    from waferscan.cli import paper_scenario
    from waferscan.core.files.scenario import parse_scenario

    text = paper_scenario().read_text().replace('load = "1101221001220001010000010"',
                                                'load = "1101221601220001010000010"')
    paper = parse_scenario(text, "paper8.toml", folder=paper_scenario().parent)
    expected = "1101221601220001010000010"
    for scan in (dict(mode="fast"), dict(mode="slow"), dict(mode="slow", jab=5.0)):
        result = scan_layout(paper.with_scan(**scan))
        assert result.code == expected, scan
        # the load port's reading, the same in every mode: slot 8's wafer 5 mm out
        out = [(name, mm) for name, mm in result.protrusions if mm > 1e-9]
        assert [name for name, _ in out] == ["LP1_W06"] and out[0][1] == pytest.approx(5.0)
