"""``rules = "boundary"`` is the open load-port controller's rule set (SPEC §11, DOMAIN-NOTES,
decided in issue 24): a slot's reference is its seat + t/2; a run belongs to the slot whose
reference is nearest its centre and is placed by its centre; boundaries lie halfway between
references, none beyond the outer slots; a second run in one slot stays a finding (5) with a
warning naming the runs. The truth here is the controller's rule written out on its own
(lists of references and boundaries, nearest by search), and the issue's worked examples."""

import random

import pytest
from scenarios import free_wafer, one_carrier

from waferscan.core.files.scenario import parse_scenario
from waferscan.core.mapping import (
    BOUNDARY,
    CROSS,
    DOUBLE,
    POSITION_ERROR,
    PRESENT,
    THIN,
    WAFERSCAN,
    SlotPlan,
    judge_run,
    map_slots,
)
from waferscan.core.scan.layout_scan import scan_layout

T = 0.775
SEATS = (300.0, 310.0, 320.0)


def carrier(rules, **recipe):
    """The issue's 3-slot carrier: seats 300, 310, 320; t = 0.775, Δt = t/2, Δp = 0.5."""
    return SlotPlan(slot_count=3, pitch=10.0, first_slot_z=300.0, wafer_thickness=T,
                    thickness_tolerance=0.5 * T, position_tolerance=0.5, rules=rules,
                    **recipe)


def code(rules, *runs):
    return map_slots(carrier(rules), list(runs)).code


# --- the examples -------------------------------------------------------------------

def test_position_is_judged_by_the_centre_against_seat_plus_half_t():
    # bottom 0.4 above the seat (inside Δp), centre 320.975 is 0.5875 above 320.3875
    assert code(WAFERSCAN, (320.4, 321.55)) == "001"
    assert code(BOUNDARY, (320.4, 321.55)) == "005"


def test_boundaries_lie_halfway_between_references():
    # the boundary of slots 2 and 3 is 315.3875, not 315: the run crosses none; its centre
    # 314.875 is nearest slot 2's reference and 4.49 mm off it
    assert code(BOUNDARY, (314.5, 315.25)) == "050"
    # one that does reach past 315.3875 is cross-slotted
    assert code(BOUNDARY, (314.9, 315.6)) == "022"


def test_no_boundary_beyond_the_outer_slots():
    lone = 324.7, 324.7 + T            # above the top slot: its position error, not a cross
    assert code(BOUNDARY, lone) == "005"
    lone = 294.7, 294.7 + T            # below slot 1: the nearest reference's position error
    assert code(BOUNDARY, lone) == "500"
    # a long run near where a boundary beyond the carrier would be is thick, not cross-slotted
    assert code(BOUNDARY, (321.5, 321.5 + 2.6 * T)) == "003"
    assert code(BOUNDARY, (297.0, 297.0 + 2.6 * T)) == "300"


def test_a_long_run_within_a_third_of_a_pitch_of_a_boundary_is_cross_slotted():
    # boundary of slots 1 and 2 at 305.3875; a third of a pitch is 3.333 mm; 2.5 t = 1.9375
    length = 2.6 * T
    near = 305.3875 - 3.3 - 0.5 * length   # centre 3.3 mm below it
    far = 305.3875 - 3.4 - 0.5 * length    # centre 3.4 mm below it
    assert code(BOUNDARY, (near, near + length)) == "220"
    assert code(BOUNDARY, (far, far + length)) == "300"


# --- the controller's rule, written out on its own -----------------------------------------

def controller(bottom, top, seats=SEATS, t=T, pitch=10.0, dt=0.5 * T, dp=0.5):
    """The controller of DOMAIN-NOTES on one run, as a list of (slot, state)."""
    references = [s + t / 2 for s in seats]
    boundaries = [(references[i] + references[i + 1]) / 2 for i in range(len(seats) - 1)]
    centre = (bottom + top) / 2
    distances = [abs(centre - r) for r in references]
    slot = distances.index(min(distances)) + 1
    crossed = [i + 1 for i, b in enumerate(boundaries) if bottom < b < top]
    if crossed:
        return [(s, CROSS) for s in sorted({s for b in crossed for s in (b, b + 1)})]
    length = top - bottom
    if length > 2.5 * t:
        for i, b in enumerate(boundaries):
            if abs(centre - b) <= pitch / 3:
                return [(i + 1, CROSS), (i + 2, CROSS)]
    if length > t + dt:
        return [(slot, DOUBLE)]
    if length < t - dt:
        return [(slot, THIN)]
    if abs(centre - references[slot - 1]) > dp:
        return [(slot, POSITION_ERROR)]
    return [(slot, PRESENT)]


def test_judge_run_is_the_controllers_rule_on_random_runs():
    rng = random.Random(24)
    plan = carrier(BOUNDARY)
    kinds = set()
    for _ in range(20000):
        bottom = rng.uniform(285.0, 335.0)
        top = bottom + rng.choice([rng.uniform(0.0, 2.5), rng.uniform(0.6, 1.0),
                                   rng.uniform(1.5, 2.5), rng.uniform(2.5, 25.0)])
        want = controller(bottom, top)
        assert judge_run(plan, bottom, top) == want, (bottom, top)
        kinds.add(tuple(state for _, state in want))
    # every finding was met, a three-slot cross included
    assert {(PRESENT,), (THIN,), (DOUBLE,), (POSITION_ERROR,), (CROSS, CROSS),
            (CROSS, CROSS, CROSS)} <= kinds


def test_seated_wafers_of_any_good_thickness_are_present():
    """A seated wafer's centre sits on its reference whatever its thickness within SEMI M1's
    ± 20 µm; its bottom is on the seat."""
    plan = carrier(BOUNDARY)
    for seat in SEATS:
        for t in (T - 0.02, T, T + 0.02):
            assert judge_run(plan, seat, seat + t) == [(SEATS.index(seat) + 1, PRESENT)]


# --- two runs in one slot -------------------------------------------------------------------

def two_wafers_in_slot_2(rules):
    return parse_scenario(one_carrier("100", start=290.0, final=330.0, first_slot_z=300.0,
                                      thickness=0.775, mapping=f'rules = "{rules}"\n',
                                      extra=free_wafer("seated", 400.0, 310.0, 0.775)
                                      + free_wafer("above", 400.0, 312.0, 0.775)))


def test_two_runs_in_one_slot_stay_a_finding_with_a_warning_naming_both():
    result = scan_layout(two_wafers_in_slot_2(BOUNDARY))
    assert [(r.bottom, r.top) for r in result.runs] == [
        pytest.approx((300.0, 300.75)), pytest.approx((310.0, 310.75)),
        pytest.approx((312.0, 312.75))]
    assert result.code == "150"
    named = [w for w in result.warnings if w.startswith("slot 2 holds 2 sensor runs")]
    assert len(named) == 1, result.warnings
    assert "310.000 to 310.750 mm and 312.000 to 312.750 mm" in named[0]
    assert "position error (5)" in named[0] and "last run" in named[0]


def test_waferscan_rules_are_unchanged_by_two_runs():
    result = scan_layout(two_wafers_in_slot_2(WAFERSCAN))
    assert result.code == "150"
    assert not any("sensor runs" in w for w in result.warnings)
