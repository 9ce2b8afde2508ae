"""Fast scans up, down and both ways with the sensor's latch lag; slow scans over the pockets."""

from dataclasses import replace

import pytest

from waferscan.addon import paper_scenario
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

LAYOUT = read_scenario(paper_scenario())
REFERENCE = scan_layout(LAYOUT)


def pairs(result):
    return [(r.z_in, r.z_out) for r in result.runs]


def test_up_stroke_reports_bottom_then_top():
    assert all(r.z_in < r.z_out for r in REFERENCE.runs)


def test_down_stroke_reports_top_then_bottom_and_the_same_code():
    down = scan_layout(LAYOUT.with_scan(direction="down"))
    assert pairs(down) == [(b, a) for a, b in pairs(REFERENCE)]
    assert down.code == REFERENCE.code


@pytest.mark.parametrize("direction, sign", [("up", 1.0), ("down", -1.0)])
def test_latch_lags_by_speed_times_response_in_the_direction_of_motion(direction, sign):
    lagged = scan_layout(LAYOUT.with_scan(direction=direction, scan_speed=200.0,
                                          sensor_response=0.0005))
    plain = scan_layout(LAYOUT.with_scan(direction=direction))
    for (i0, o0), (i1, o1) in zip(pairs(plain), pairs(lagged)):
        assert i1 - i0 == pytest.approx(sign * 0.1)
        assert o1 - o0 == pytest.approx(sign * 0.1)


def test_up_and_down_averaged_cancels_the_lag():
    both = scan_layout(LAYOUT.with_scan(direction="updown", scan_speed=200.0,
                                        sensor_response=0.0005))
    for (i0, o0), (i1, o1) in zip(pairs(REFERENCE), pairs(both)):
        assert i1 == pytest.approx(i0, abs=1e-12)
        assert o1 == pytest.approx(o0, abs=1e-12)


def test_a_large_lag_turns_the_code_into_position_errors():
    lagged = scan_layout(LAYOUT.with_scan(scan_speed=500.0, sensor_response=0.002))  # 1 mm
    assert lagged.code == "5505225005220005050000050"


def test_slow_scan_reads_at_rest_and_sweeps_only_the_pockets():
    slow = scan_layout(LAYOUT.with_scan(mode="slow", scan_speed=500.0, sensor_response=0.002))
    assert pairs(slow) == pairs(REFERENCE)  # no latch lag at rest
    assert slow.code == REFERENCE.code


def test_slow_scan_does_not_see_below_the_first_pocket():
    low = LAYOUT.with_scan(start_z=250.0)
    stray = replace(LAYOUT.wafers[0], name="stray", center=(0.0, 400.0, 270.0))
    layout = replace(low, wafers=low.wafers + (stray,))
    fast = scan_layout(layout)
    slow = scan_layout(layout.with_scan(mode="slow"))
    assert any("stray" in r.wafers for r in fast.runs)
    assert not any("stray" in r.wafers for r in slow.runs)
    assert slow.code == fast.code == REFERENCE.code  # below every slot: in no slot's code
    stray = next(w for w in slow.wafers if w.name == "stray")
    assert stray.z_in is None


def test_exact_mode_gives_continuous_edges():
    exact = scan_layout(LAYOUT.with_scan(z_step=0.0))
    assert exact.code == REFERENCE.code
    first = exact.runs[0]
    # The geometric edges: the touching tolerance does not leak into what is reported.
    assert first.z_in == pytest.approx(293.94, abs=1e-12)
    assert first.z_out == pytest.approx(294.64, abs=1e-12)
