"""The recipe's judgement (SPEC §11): thickness window, asymmetric position window, double
threshold, thickness correction and the two rule sets, each at its limits; the defaults judge as
SPEC §4 does."""

import random

import pytest

from waferscan.core.mapping import (BOUNDARY, CROSS, DOUBLE, EMPTY, POSITION_ERROR, PRESENT,
                                    THIN, WAFERSCAN, SlotPlan, judge_run, map_slots)

T = 0.7
BASE = dict(slot_count=5, pitch=10.0, first_slot_z=100.0, wafer_thickness=T,
            thickness_tolerance=0.35, position_tolerance=0.5)


def plan(**recipe):
    return SlotPlan(**{**BASE, **recipe})


def code(p, *runs):
    return map_slots(p, list(runs)).code


# --- the defaults are SPEC §4's rule --------------------------------------------------------

def test_default_windows_are_spec_4s():
    p = plan()
    assert p.thickness_window() == (T - 0.35, T + 0.35)
    assert p.position_window() == (0.5, 0.5)
    assert p.double_limit() == 2 * T + 0.35
    assert p.rules == WAFERSCAN and p.thickness_correction == 1.0


def test_boundary_rules_default_double_limit_is_two_and_a_half_t():
    assert plan(rules=BOUNDARY).double_limit() == 2.5 * T
    assert plan(rules=BOUNDARY, double_threshold=1.5).double_limit() == 1.5


def _spec4_state(bottom, top):
    """SPEC §4 written out independently for one run inside slots 1..5, seat 100 + 10 (i - 1)."""
    length = top - bottom
    if length > 2 * T + 0.35 + 1e-9:
        return "cross"
    slot = round((bottom - 100.0) / 10.0) + 1
    if abs(bottom - (100.0 + 10.0 * (slot - 1))) > 0.5 + 1e-9:
        return POSITION_ERROR
    if length < T - 0.35 - 1e-9:
        return THIN
    return PRESENT if length <= T + 0.35 + 1e-9 else DOUBLE


def test_an_explicit_recipe_equal_to_the_defaults_judges_every_run_alike():
    rng = random.Random(16)
    default = plan()
    explicit = plan(thickness_min=T - 0.35, thickness_max=T + 0.35, double_threshold=2 * T + 0.35,
                    position_below=0.5, position_above=0.5, thickness_correction=1.0)
    for _ in range(2000):
        bottom = rng.uniform(104.0, 136.0)
        top = bottom + rng.uniform(0.0, 2.5)
        found = judge_run(default, bottom, top)
        assert judge_run(explicit, bottom, top) == found
        expected = _spec4_state(bottom, top)
        if expected == "cross":
            assert {state for _, state in found} == {CROSS}
        else:
            assert [state for _, state in found] == [expected]


# --- each recipe key at its limits ----------------------------------------------------------

@pytest.mark.parametrize("rules", [WAFERSCAN, BOUNDARY])
@pytest.mark.parametrize("length, expected", [
    (0.60, PRESENT),     # thickness_min itself: present
    (0.59, THIN),
    (0.80, PRESENT),     # thickness_max itself: present
    (0.81, DOUBLE),
])
def test_thickness_window(rules, length, expected):
    p = plan(thickness_min=0.6, thickness_max=0.8, rules=rules)
    assert judge_run(p, 110.0, 110.0 + length) == [(2, expected)]


@pytest.mark.parametrize("rules", [WAFERSCAN, BOUNDARY])
@pytest.mark.parametrize("offset, expected", [
    (-0.20, PRESENT),    # position_below itself
    (-0.21, POSITION_ERROR),
    (0.60, PRESENT),     # position_above itself
    (0.61, POSITION_ERROR),
])
def test_asymmetric_position_window(rules, offset, expected):
    p = plan(position_below=0.2, position_above=0.6, rules=rules)
    assert judge_run(p, 110.0 + offset, 110.0 + offset + T) == [(2, expected)]


def test_position_above_wider_than_the_default_accepts_what_the_default_rejects():
    run = (110.55, 110.55 + T)
    assert code(plan(), run) == "05000"
    assert code(plan(position_above=0.6), run) == "01000"
    assert code(plan(position_below=0.6), run) == "05000"   # the other side only


@pytest.mark.parametrize("length, expected", [
    (1.20, "30000"),     # double_threshold itself: still double
    (1.21, "22000"),     # beyond: cross-slotted (midpoint 100.6 lies between seats 1 and 2)
])
def test_double_threshold(length, expected):
    assert code(plan(double_threshold=1.2), (100.0, 100.0 + length)) == expected


@pytest.mark.parametrize("rules", [WAFERSCAN, BOUNDARY])
def test_thickness_correction_divides_the_measured_diff(rules):
    p = plan(thickness_correction=1.1, rules=rules)
    # 1.155 / 1.1 = 1.05 = t + dt: present; uncorrected it would be double.
    assert judge_run(p, 110.0, 111.155) == [(2, PRESENT)]
    assert judge_run(plan(rules=rules), 110.0, 111.155) == [(2, DOUBLE)]
    # 1.16 / 1.1 = 1.0545 > 1.05: double.
    assert judge_run(p, 110.0, 111.16) == [(2, DOUBLE)]
    # 0.385 / 1.1 = 0.35 = t - dt: present; 0.38 / 1.1 < 0.35: thin.
    assert judge_run(p, 110.0, 110.385) == [(2, PRESENT)]
    assert judge_run(p, 110.0, 110.38) == [(2, THIN)]


def test_unknown_rules_are_refused():
    with pytest.raises(ValueError, match="rules must be one of waferscan, boundary"):
        plan(rules="nearest")


# --- the "boundary" rules at their limits ---------------------------------------------------

def test_boundary_a_run_across_a_boundary_is_cross_slotted_at_any_length():
    b = plan(rules=BOUNDARY)
    # references at seat + t/2 (100.35, 110.35, ...): the boundary of slots 1 and 2 is 105.35
    assert code(b, (104.6, 105.4)) == "22000"
    assert code(b, (104.6, 105.35)) == "50000"          # reaches the boundary, does not cross:
    # centre 104.975 -> slot 1, 4.625 above its reference: position error
    assert code(b, (104.0, 116.0)) == "22200"           # spans three slots: all three


def test_boundary_a_long_run_near_a_boundary_is_cross_slotted_far_from_it_thick():
    b = plan(rules=BOUNDARY)                             # double limit 2.5 t = 1.75
    # centre 102.05: 3.3 mm below the boundary at 105.35 (a third of a pitch is 3.33): cross.
    assert code(b, (101.15, 102.95)) == "22000"
    # centre 101.95: 3.4 mm from it: thick, and the thickness is judged before the position.
    assert code(b, (101.05, 102.85)) == "30000"
    # the same near the lower boundary of slot 2 (at 105.35): centre 108.65 is 3.3 above it.
    assert code(b, (107.75, 109.55)) == "22000"
    # exactly 2.5 t near a boundary: not beyond the limit, so thick.
    assert code(b, (101.25, 103.0)) == "30000"


def test_boundary_run_is_placed_by_its_centre_against_its_reference():
    b = plan(rules=BOUNDARY)
    # bottom 0.4 above the seat (seated by its bottom edge), 1.0 long: its centre 110.9 is
    # 0.55 above the reference 110.35 -- a position error by the centre
    assert judge_run(b, 110.4, 111.4) == [(2, POSITION_ERROR)]
    assert judge_run(plan(), 110.4, 111.4) == [(2, PRESENT)]
    # bottom 0.6 below the seat, 1.0 long: centre 109.9 is 0.45 below the reference: present
    assert judge_run(b, 109.4, 110.4) == [(2, PRESENT)]
    assert judge_run(plan(), 109.4, 110.4) == [(2, POSITION_ERROR)]
    # bottom 104.9 (nearest seat 1) and centre 105.25: crosses 105.35 -> slots 1 and 2.
    assert judge_run(b, 104.9, 105.6) == [(1, CROSS), (2, CROSS)]
    assert judge_run(plan(), 104.9, 105.6) == [(1, POSITION_ERROR)]


# --- the two rule sets on the same runs -----------------------------------------------------

@pytest.mark.parametrize("run, by_waferscan, by_boundary", [
    # SPEC §11's example: a thick run off its seat is 5 by one and 3 by the other.
    ((110.8, 112.2), "05000", "03000"),
    # a thin run off its seat: position first (5) or thickness first (4)
    ((110.8, 111.1), "05000", "04000"),
    # a run of wafer thickness across the boundary of slots 1 and 2 (at 105.35)
    ((104.7, 105.4), "50000", "22000"),
    # 2.57 t, far from any boundary: cross by its length alone, or thick
    ((110.0, 111.8), "02200", "03000"),
    # a seated wafer and a clean double: both alike
    ((110.0, 110.7), "01000", "01000"),
    ((110.0, 111.4), "03000", "03000"),
    # off its seat but of good thickness: both a position error
    ((110.6, 111.3), "05000", "05000"),
])
def test_the_two_rule_sets_on_the_same_runs(run, by_waferscan, by_boundary):
    assert code(plan(), run) == by_waferscan
    assert code(plan(rules=BOUNDARY), run) == by_boundary


def test_the_two_rule_sets_on_a_whole_carrier():
    runs = [(100.0, 100.7),     # slot 1 seated: 1 by both
            (110.8, 112.2),     # slot 2, thick and 0.8 off its seat: 5 | 3
            (124.7, 125.4),     # bottom nearest seat 3 (4.7 off): 5 | across 125.35: 3, 4 get 2
            (130.0, 131.8)]     # 2.57 t: cross in slots 4, 5 | thick in slot 4, outranked by 2
    assert map_slots(plan(), runs).code == "15522"
    assert map_slots(plan(rules=BOUNDARY), runs).code == "13220"


def test_empty_stays_empty_under_both_rule_sets():
    assert code(plan()) == code(plan(rules=BOUNDARY)) == "0" * 5
    assert EMPTY == 0
