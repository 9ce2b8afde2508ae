"""Every slot-code rule of SPEC §4, its boundaries, and the E87 map; then the same states built
physically from a scenario and found by scanning."""

import pytest
from scenarios import one_carrier

from waferscan.core.files.scenario import parse_scenario
from waferscan.core.mapping import SlotPlan, judge_run, map_slots
from waferscan.core.scan.layout_scan import scan_layout

T = 0.7
PLAN = SlotPlan(slot_count=5, pitch=10.0, first_slot_z=100.0, wafer_thickness=T,
                thickness_tolerance=0.35, position_tolerance=0.5)


def code(*runs, protruding=()):
    return map_slots(PLAN, list(runs), protruding).code


def test_empty_carrier():
    assert code() == "00000"


def test_present_wafer_at_its_seat():
    assert code((110.02, 110.70)) == "01000"


@pytest.mark.parametrize("bottom, expected", [
    (110.0 + 0.5, "01000"),          # bottom just within the position tolerance
    (110.0 - 0.5, "01000"),
    (110.0 + 0.51, "05000"),         # just outside: position error
    (110.0 - 0.51, "05000"),
    (114.0, "05000"),                # nearest seat still slot 2
    (116.0, "00500"),                # nearest seat now slot 3
])
def test_position_tolerance(bottom, expected):
    assert code((bottom, bottom + T)) == expected


@pytest.mark.parametrize("length, expected", [
    (T, "10000"),
    (T - 0.35, "10000"),             # t - dt: still present
    (T - 0.36, "40000"),             # thinner: thin
    (T + 0.35, "10000"),             # t + dt: still present
    (T + 0.36, "30000"),             # thicker: double
    (2 * T + 0.35, "30000"),         # 2t + dt: still double
])
def test_thickness_rules(length, expected):
    assert code((100.0, 100.0 + length)) == expected


def test_cross_slotted_marks_both_slots_around_the_midpoint():
    # 2t + dt = 1.75 exceeded; midpoint 115.0 lies between the seats of slots 2 and 3.
    assert code((112.3, 117.7)) == "02200"
    assert code((100.0, 100.0 + 2 * T + 0.36)) == "22000"


def test_cross_slotted_at_the_top_keeps_to_the_carrier():
    assert judge_run(PLAN, 142.0, 147.5) == [(5, 2)]


def test_runs_outside_the_carrier_are_left_out():
    assert code((50.0, 50.7), (300.0, 300.7)) == "00000"


def test_two_runs_in_one_slot_are_a_position_error():
    assert code((110.0, 110.7), (111.5, 112.2)) == "05000"


def test_worst_state_wins():
    # A cross-slotted wafer over slots 2-3 and a normal wafer in slot 3: slot 3 stays 2.
    assert code((112.3, 117.7), (120.0, 120.7)) == "02200"
    assert code((100.0, 100.7), protruding=[1]) == "60000"


def test_e87_map():
    slot_map = map_slots(PLAN, [(100.0, 100.7), (112.3, 117.7), (140.0, 141.4)])
    assert slot_map.code == "12203"
    assert slot_map.e87 == "35514"
    assert map_slots(PLAN, [(100.0, 100.1), (111.0, 111.7)], [3]).e87 == "22211"


@pytest.mark.parametrize("load", ["1220345601", "0000000000", "2222222222", "3333344444",
                                  "5656565656", "1111111111", "0122012200"])
def test_states_built_physically_are_found_by_the_scan(load):
    layout = parse_scenario(one_carrier(load))
    assert scan_layout(layout).code == load
    assert scan_layout(layout, "loop").code == load
