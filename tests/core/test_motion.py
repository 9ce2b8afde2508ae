"""Motion and latching (SPEC §10): trapezoidal strokes and encoder/sampled latches, against
hand-checkable cases."""

import math

import pytest
from sensor_layouts import SEAT, T, one_wafer, oracle_edges

from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.motion import Stroke
from waferscan.core.sensor.spot import Amplifier, BeamSpot


def test_constant_speed_lag_is_speed_times_response():
    up = Stroke(0.0, 100.0, 200.0)
    down = Stroke(100.0, 0.0, 200.0)
    assert up.latched(40.0, 250e-6) == pytest.approx(40.05, abs=1e-12)
    assert down.latched(40.0, 250e-6) == pytest.approx(39.95, abs=1e-12)
    assert up.duration == pytest.approx(0.5)
    # After the stroke's end the axis stands still.
    assert up.latched(99.99, 0.1) == 100.0


def test_an_edge_in_the_acceleration_phase():
    # 1000 mm/s², 100 mm/s: 5 mm to reach full speed. The edge at 1 mm is passed at
    # sqrt(2 mm / 1000 mm/s²) and latched 10 ms later, still accelerating.
    stroke = Stroke(0.0, 100.0, 100.0, 1000.0)
    t = math.sqrt(2.0 * 1.0 / 1000.0) + 0.010
    assert t < 0.1
    assert stroke.latched(1.0, 0.010) == pytest.approx(0.5 * 1000.0 * t * t, abs=1e-12)
    # In the cruise: lag v tau; in the deceleration: distance left 0.5 a (T - t)^2.
    assert stroke.latched(50.0, 0.010) == pytest.approx(51.0, abs=1e-12)
    total = 2 * 0.1 + 90.0 / 100.0
    assert stroke.duration == pytest.approx(total)
    t = stroke.time_at(98.0) + 0.010
    assert stroke.latched(98.0, 0.010) == pytest.approx(100.0 - 0.5 * 1000.0 * (total - t) ** 2)


def test_a_short_stroke_is_a_triangle():
    stroke = Stroke(10.0, 6.0, 100.0, 1000.0)  # 4 mm: 100² / 1000 = 10 mm would be needed
    peak_time = math.sqrt(4.0 / 1000.0)
    assert stroke.duration == pytest.approx(2 * peak_time)
    assert stroke.position(peak_time) == pytest.approx(8.0)
    assert stroke.position(2 * peak_time) == pytest.approx(6.0)
    for z in (9.5, 8.0, 6.5):
        assert stroke.position(stroke.time_at(z)) == pytest.approx(z, abs=1e-12)


def test_sampled_latch_within_one_sample_period_of_the_encoder():
    stroke = Stroke(0.0, 300.0, 200.0, 2000.0)
    period = 1e-3
    for z in [0.3 + 7.1 * i for i in range(40)]:
        encoder = stroke.latched(z, 250e-6)
        sampled = stroke.latched(z, 250e-6, "sampled", period)
        assert encoder <= sampled <= encoder + 200.0 * period + 1e-12
        # The read it latched at is a whole number of periods from the start.
        t = stroke.time_at(sampled) if sampled < 300.0 else None
        if t is not None:
            assert abs(t / period - round(t / period)) < 1e-6


@pytest.mark.parametrize("spot", [BeamSpot(), BeamSpot(diameter=1.0)])
def test_encoder_scan_lags_by_speed_times_response(spot):
    layout = one_wafer(spot, z_step=0.05, scan_speed=200.0, sensor_response=250e-6,
                       latch="encoder")
    (run,) = scan_layout(layout).runs
    # Continuous edges (no grid): the faces cross the spot's centre at threshold 0.5.
    assert run.z_in == pytest.approx(SEAT + 0.05, abs=1e-6)
    assert run.z_out == pytest.approx(SEAT + T + 0.05, abs=1e-6)
    down = scan_layout(one_wafer(spot, z_step=0.05, scan_speed=200.0, sensor_response=250e-6,
                                 latch="encoder", direction="down"))
    (run,) = down.runs
    assert run.z_in == pytest.approx(SEAT + T - 0.05, abs=1e-6)
    assert run.z_out == pytest.approx(SEAT - 0.05, abs=1e-6)


def test_updown_averages_the_strokes_and_lists_every_edge_in_latch_order():
    layout = one_wafer(BeamSpot(diameter=1.0), Amplifier(0.7, 0.3), scan_speed=200.0,
                       sensor_response=250e-6, latch="encoder", direction="updown")
    result = scan_layout(layout)
    (run,) = result.runs
    edges = result.edges
    assert [(e["stroke"], e["edge"]) for e in edges] == [("up", "on"), ("up", "off"),
                                                         ("down", "on"), ("down", "off")]
    # Each stroke's edges are the band oracle's for its direction, lagging 0.05 mm in it.
    spot = layout.spot
    up_on, up_off = oracle_edges(spot, 0.7, 0.3, True)
    down_on, down_off = oracle_edges(spot, 0.7, 0.3, False)
    expected = [up_on + 0.05, up_off + 0.05, down_on - 0.05, down_off - 0.05]
    assert [e["z"] for e in edges] == pytest.approx(expected, abs=1e-6)
    assert run.z_in == pytest.approx(0.5 * (edges[0]["z"] + edges[3]["z"]), abs=1e-12)
    assert run.z_out == pytest.approx(0.5 * (edges[1]["z"] + edges[2]["z"]), abs=1e-12)
    # The symmetric band makes the two strokes mirror images: the mean is centred on the wafer.
    assert 0.5 * (run.z_in + run.z_out) == pytest.approx(SEAT + T / 2, abs=1e-6)


def test_a_scan_too_short_for_full_speed_latches_on_the_triangle():
    # 10 mm at 1000 mm/s² never reaches 200 mm/s (40 mm would be needed): the axis speeds up
    # for 5 mm, to the wafer's bottom face, and slows down after. The edge is passed at the
    # peak, t = 0.1 s, and latched 1 ms later, 0.5 a (0.2 s - 0.101 s)^2 before the end.
    layout = one_wafer(BeamSpot(), scan_speed=200.0, sensor_response=1e-3, latch="encoder",
                       acceleration=1000.0)
    (run,) = scan_layout(layout).runs
    assert run.z_in == pytest.approx(SEAT + 5.0 - 0.5 * 1000.0 * (0.2 - 0.101) ** 2, abs=1e-9)
    assert run.z_in - SEAT < 100.0 * 1e-3  # the peak speed is 100 mm/s
    # The top face at 0.7 mm further, passed while slowing down.
    t = 0.2 - math.sqrt(2 * (5.0 - T) / 1000.0) + 1e-3
    assert run.z_out == pytest.approx(SEAT + 5.0 - 0.5 * 1000.0 * (0.2 - t) ** 2, abs=1e-9)
