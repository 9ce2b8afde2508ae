"""SPEC §15: clearance along every motion of a scan, against hand computations.

The bundled robot (resources/robots/wafer_robot.urdf): each tine is a box 180 x 20 x 4 mm, its
inner edge 70 mm and its outer edge 90 mm from the fork's centre line, its tip at the beam, its
bottom face at the beam's height. In the paper's layout (heading +Y, beam at Y = 266.6) the tines
cover X in [-90, -70] and [70, 90] (tine_left, which carries the emitter, at X < 0)."""

import math
from dataclasses import replace
from pathlib import Path

import pytest

from waferscan.core.files.mcs import format_results, parse_parameters, apply_parameters
from waferscan.core.errors import InputError
from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import Wafer
from waferscan.core.scan import clearance as core
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.robot.clearance import RobotBody, clearance_for

ROOT = Path(__file__).resolve().parents[2]
PAPER = read_scenario(ROOT / "resources" / "examples" / "paper.toml")
SLOW = read_scenario(ROOT / "resources" / "examples" / "slow_jab.toml")
SEAT = PAPER.scanned_carrier.seat_z


def _wafer(name, center, normal=(0.0, 0.0, 1.0), bow=0.0):
    return Wafer(name, center, normal, 300.0, 0.7, bow=bow)


def test_paper_least_clearance_is_the_tine_corner_to_the_rim():
    # Hand: the tines' inner tip corners (±70, 266.6) lie sqrt(70² + 133.4²) - 150 mm from the
    # wafers' centre line (0, 400), and the stroke takes them through every wafer's height.
    report = clearance_for(PAPER)
    least = report.least
    assert least.distance == pytest.approx(math.hypot(70.0, 133.4) - 150.0, abs=1e-6)  # 0.650
    assert least.part in ("tine_left", "tine_right") and least.motion.kind == core.STROKE
    # Where: with the tine's 4 mm over a 0.7 mm wafer, z in [seat - 4, seat + 0.7].
    slot = least.slot
    assert SEAT(slot) - 4.0 - 1e-6 <= least.position <= SEAT(slot) + 0.7 + 1e-6
    # The distance reported is the distance at the reported position.
    body = RobotBody(PAPER)
    assert body.nearest(least.motion, least.position)[0] == pytest.approx(least.distance,
                                                                          abs=1e-6)
    # Under the default 1.0 mm that is a contact; paper.toml accepts 0.5 mm.
    assert PAPER.mapping.clearance_min == 0.5 and not report.contacts
    assert len(core.check_clearance(PAPER, body, clearance_min=1.0).contacts) == 1


def test_without_a_robot_the_scanner_heads_stand_in():
    # Hand: each head (radius 3) at (±80, 266.6) is sqrt(80² + 133.4²) - 150 - 3 from
    # a rim.
    report = clearance_for(replace(PAPER, robot=None))
    assert report.body == "scanner"
    assert report.least.distance == pytest.approx(math.hypot(80.0, 133.4) - 153.0, abs=1e-6)
    assert report.least.part in ("emitter head", "receiver head")  # X = -80 and +80: equal


def test_a_wafer_protruding_12_mm_meets_a_tine():
    # Hand: pushed 12 mm out, the rim passes X = 70 at Y = 388 - sqrt(150² - 70²) = 255.34,
    # inside the tine's tip (266.6): the tines overlap the wafer in plan, so the stroke runs
    # them through it. The least separation is vertical: the 0.7 mm wafer centred in the 4 mm
    # tine is 0.35 + 2 = 2.35 mm deep, at the scan position seat + 0.35 - 2.
    protruding = _wafer("out12", (0.0, 388.0, SEAT(3)))
    layout = replace(PAPER, wafers=(protruding,))
    report = clearance_for(layout)
    (contact,) = report.contacts
    assert contact.obstacle == "out12" and contact.slot == 3
    assert contact.part in ("tine_left", "tine_right")
    # A contact's depth is searched to CONTACT_RELATIVE of its margin (core/scan/clearance.py).
    assert -2.35 - 1e-6 <= contact.distance <= -2.35 + core.CONTACT_RELATIVE * (1.0 + 2.35)
    assert SEAT(3) - 4.0 <= contact.position <= SEAT(3) + 0.7
    deepest = RobotBody(layout).nearest(contact.motion, SEAT(3) - 1.65)
    assert deepest[0] == pytest.approx(-2.35, abs=1e-6) and deepest[2] == "out12"
    # The same wafer seated: clear by the paper's 0.650 mm.
    seated = clearance_for(replace(PAPER, wafers=(_wafer("in", (0.0, 400.0, SEAT(3))),)))
    assert seated.least.distance == pytest.approx(0.6505, abs=1e-4)


def _slow(wafers, jab, pockets, sweep=0.0):
    layout = replace(SLOW, wafers=tuple(wafers))
    layout = layout.with_scan(jab=jab, sweep=sweep)
    return layout, clearance_for(layout, pockets=pockets)


def test_a_cross_slotted_wafer_meets_the_left_tine_only():
    # A wafer across slots 5 and 6, as the scenario builds it: its bottom face through the
    # supports' inner edges, rising 10 mm over 292.5 mm to the right: bottom at X is
    # seat5 + 5 + X * 10 / 292.5. A 45 mm jab from Y = 240 puts the tips at Y = 285, over the
    # wafer at both tines.
    # - Pocket 5 (z = seat5 + 0.35, tines' band seat5 + 0.35 .. + 4.35): under tine_left
    #   (X -90 .. -70) the bottom lies at seat5 + 1.92 .. 2.61: inside the band, a contact;
    #   under tine_right (X 70 .. 90) at + 7.39 .. 8.08: above it.
    # - Pocket 6 (band seat5 + 10.35 ..): the top face under tine_right's outer edge (X = 90) is
    #   at seat5 + 5 + 90 * 10 / 292.5 + 0.7 / cos(tilt) = seat5 + 8.777: 1.573 mm below the
    #   tine, 1.573 cos(tilt) = 1.572 mm across.
    slope = 10.0 / 292.5
    s, c = slope / math.hypot(1.0, slope), 1.0 / math.hypot(1.0, slope)
    cross = _wafer("cross", (0.0, 400.0, SEAT(5) + 5.0), (-s, 0.0, c))
    _, report = _slow([cross], 45.0, [5, 6])
    jabs = {m.motion.slot: m for m in report.closest if m.motion.kind == core.JAB}
    assert jabs[5].distance < 0.0 and jabs[5].part == "tine_left" and jabs[5].obstacle == "cross"
    top = 5.0 + 90.0 * slope + 0.7 / c
    assert jabs[6].part == "tine_right"
    assert jabs[6].distance == pytest.approx((10.35 - top) * c, abs=2e-3)
    # From an advance of 40 mm (the corner (90, 280) on the rim) on, the gap stays the same.
    assert 40.0 - 0.5 <= jabs[6].position <= 45.0


def test_a_4_mm_bow_sags_onto_the_tines_below():
    # A 150 mm jab puts the tines under the wafer's middle (tips at Y = 390). Pocket 2's Z steps
    # (the fork in) end at seat3 - 5: the tines' top at seat3 - 1. A flat wafer in slot 3 is
    # then 1.000 mm above them; bowed 4 mm down (centre low), its bottom under the inner tip
    # (70, 390), r = sqrt(70² + 10²), is at seat3 - 4 (1 - r²/150²) = seat3 - 3.111: the tines
    # are inside it by 2.111 mm there: a contact.
    flat = _wafer("flat", (0.0, 400.0, SEAT(3)))
    _, report = _slow([flat], 150.0, [2])
    steps = [m for m in report.closest if m.motion.kind == core.STEPS][0]
    assert steps.distance == pytest.approx(1.0, abs=1e-6)
    assert steps.position == pytest.approx(SEAT(3) - 5.0, abs=1e-6)
    bowed = _wafer("bowed", (0.0, 400.0, SEAT(3)), bow=-4.0)
    _, report = _slow([bowed], 150.0, [2])
    steps = [m for m in report.closest if m.motion.kind == core.STEPS][0]
    assert steps in report.contacts and steps.obstacle == "bowed"
    assert steps.part in ("tine_left", "tine_right")
    assert -2.2 < steps.distance < 0.0


def test_the_sweep_search_finds_the_turn_where_a_tine_comes_within_reach():
    # The Lipschitz search on a turn: slot 1 of slow_jab.toml, a ±40° sweep at the 26.6 mm jab.
    # Its least distance is a contact; the search's result agrees with a fine scan of the turn.
    layout, report = _slow([_wafer("w1", (0.0, 400.0, SEAT(1)))], 26.6, [1], sweep=40.0)
    sweep = [m for m in report.closest if m.motion.kind == core.SWEEP][0]
    body = RobotBody(layout)
    fine = min(body.nearest(sweep.motion, a / 20.0)[0] for a in range(-800, 801))
    assert sweep.distance <= fine + 1e-9
    assert sweep.distance < 0.0 and sweep in report.contacts


def test_results_txt_and_json_say_the_clearance():
    result = replace(scan_layout(PAPER), clearance=clearance_for(PAPER))
    text = format_results(1, "SCF", result, timestamp="T")
    assert "\nstatus = ok\n" in text
    assert "\nclearance_min = 0.5\nclearance = 0.650\n" in text and "collision" not in text
    strict = replace(PAPER, mapping=replace(PAPER.mapping, clearance_min=1.0))
    result = replace(scan_layout(strict), clearance=clearance_for(strict))
    text = format_results(1, "SCF", result, timestamp="T")
    lines = text.splitlines()
    assert "status = error" in lines and "clearance_min = 1.0" in lines
    (collision,) = [line for line in lines if line.startswith("collision = ")]
    assert collision.startswith("collision = 0.650 mm between tine_")
    assert "fast stroke up at scan position" in collision
    assert "slot\t" not in text  # the robot must not run it: no table


def test_clearance_min_is_a_parameters_key_checked_like_the_others():
    layout = apply_parameters(PAPER, parse_parameters("clearance_min = 2.5\n"))
    assert layout.mapping.clearance_min == 2.5
    with pytest.raises(InputError) as info:
        parse_parameters("start_z = 280\nclearance_min = -1\n", "parameters.txt")
    assert str(info.value).startswith("parameters.txt:2: clearance_min")


def test_a_scan_without_motions_checked_scanner_report_is_empty():
    report = clearance_for(replace(PAPER, robot=None, wafers=()))
    assert report.least.distance == math.inf and not report.contacts
    assert report.carrier == core.CARRIER_NOT_CHECKED


def test_the_mcs_link_answers_a_contact_with_status_error_in_file_and_log(tmp_path):
    from waferscan.core.files.mcs_link import McsLink

    strict = replace(PAPER, mapping=replace(PAPER.mapping, clearance_min=1.0))
    result = replace(scan_layout(strict), clearance=clearance_for(strict))
    logged = []
    link = McsLink(tmp_path, lambda command, should_stop: result, log=logged.append)
    (tmp_path / "commands.txt").write_text("1 SCF\n")
    (answer,) = link.poll()
    assert answer.status == "error" and answer.message.startswith("clearance: 1 motion closer")
    assert any(line.startswith("seq 1 SCF: error (clearance: ") for line in logged)
    text = (tmp_path / "results.txt").read_text()
    assert "\nstatus = error\n" in text and "\ncollision = 0.650 mm between tine_" in text
