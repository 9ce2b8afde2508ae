"""A slow scan's jabs and sweeps in the GUI (SPEC §13): after Run scan on resources/examples/
slow_jab.toml the arm jabs and sweeps pocket by pocket in the document; the task panel says the
pocket, the phase and the advance or wrist angle; the beam the robot holds is the closed form's.
The sweeps stop where the fork comes within clearance_min (SPEC §13 amended): the reference is
the core's scan with the robot layer's limits (``slow_scan_result``)."""

import functools
from pathlib import Path

import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import slow_scan

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "resources" / "examples" / "slow_jab.toml"
PROBE = Path(__file__).resolve().with_name("pockets_probe.py")
ARTIFACTS = REPO / "test-artifacts"
LAYOUT = read_scenario(EXAMPLE)


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    (ARTIFACTS / "gui-jab.png").unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(EXAMPLE),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


def test_the_panel_shows_pocket_phase_and_advance_or_angle(gui):
    assert gui["panel_title"] == "WaferScan jabs and sweeps"
    jab = gui["jab"]
    assert (jab["pocket"], jab["phase"], jab["arm"]) == ("pocket 8", "jab in", "advance 20.00 mm")
    assert jab["beam"] == "blocked"
    # The wafer pushed 5 mm out: met 5 mm early, and the sweep stopped at ±0.339° (hand:
    # tests/robot/test_sweep_reach.py's geometry), still blocked.
    assert jab["found"] == "front 5.000 mm, sweep -0.339° to +0.339°"
    sweep = gui["sweep"]
    assert (sweep["pocket"], sweep["phase"]) == ("pocket 3", "sweep")
    assert sweep["arm"] == f"wrist {sweep['frame'][4]:+.2f}°" and sweep["frame"][4] < 0
    assert gui["start"]["beam"] == "beam clear"  # slot 1's jab starts 10 mm in front


@pytest.mark.parametrize("which", ["start", "jab", "sweep"])
def test_the_robot_holds_the_beam_where_the_closed_form_puts_it(gui, which):
    slot, phase, z, advance, turn = gui[which]["frame"]
    emitter, beam = slow_scan.beam_at(LAYOUT, z, advance, turn)
    assert gui[which]["emitter"] == pytest.approx(list(emitter), abs=1e-6)
    assert gui[which]["direction"] == pytest.approx(list(beam.direction), abs=1e-9)


def test_the_jab_moves_the_arms_links(gui):
    start, jab = gui["start"]["links"], gui["jab"]["links"]
    assert abs(jab["fork"][1] - start["fork"][1]) == pytest.approx(20.0, abs=1e-6)
    assert jab["forearm"] != pytest.approx(start["forearm"], abs=1.0)


def test_after_the_pockets_the_results_open_and_a_screenshot_of_a_jab_is_left(gui):
    assert "1111221601220001010000010" in gui["code"]
    assert "Done" in gui["panel_status"]
    assert (ARTIFACTS / "gui-jab.png").stat().st_size > 10_000


def test_the_panel_says_where_the_sweep_stopped_short_of_a_wafer(gui):
    lines = [w for w in slow_scan_result().warnings if "the sweep stopped where" in w]
    assert len(lines) == 3  # the seated pockets together, slot 3 and slot 8
    for line in lines:
        assert line.split(" (-")[0] in gui["panel_status"]
    assert "a real fork would strike" not in gui["panel_status"]


def test_the_results_table_shows_front_and_sweep(gui):
    assert gui["headers"][-3:] == ["Front [mm]", "Sweep first [°]", "Sweep last [°]"]
    rows = {int(r[0]): r for r in gui["rows"]}
    for probe in slow_scan_result().pockets:
        front, first, last = rows[probe.slot][-3:]
        assert front == ("" if probe.front is None else f"{probe.front:.3f}")
        if probe.sweep is None:
            assert (first, last) == ("", "")
        else:  # the document's robot stops within the search's 0.001 mm, as the core's does
            assert [float(first), float(last)] == pytest.approx(list(probe.sweep), abs=2e-3)
    assert rows[8][-3:] == ["5.000", "-0.339", "+0.339"]


def test_the_pockets_can_be_paused_sped_up_and_jumped_to(gui):
    """Issue 27 item 15: the pocket phase (about a minute on slow_jab.toml) had no pause, no
    speed and no way to a pocket."""
    held_at, text, timer_active, later_k, arm_still = gui["paused"]
    assert text == "Resume" and timer_active is False
    assert later_k == held_at and arm_still  # 400 ms later: not a frame further
    went = gui["went_to"]
    assert went["choices"] == [f"pocket {p.slot}" for p in slow_scan_result().pockets]
    assert went["pocket"] == "pocket 12" and went["frame"][0] == 12
    assert went["frame"][1] == "jab" and went["frame"][3] == 0.0  # the jab's first frame
    probe = next(p for p in slow_scan_result().pockets if p.slot == 12)
    assert went["emitter_z"] == pytest.approx(probe.z, abs=1e-6)
    assert went["paused"] is True
    assert gui["resumed_text"] == "Pause"
    steps = gui["fast_steps"]
    assert steps and all(step == 8 for step in steps[:-1]), steps  # 8x: every 8th frame shown


@functools.cache
def slow_scan_result():
    """The scan the GUI makes, by the core's closed forms with the robot's clearance limits."""
    from waferscan.core.scan.clearance import turn_limits
    from waferscan.core.scan.layout_scan import scan_layout
    from waferscan.robot.clearance import RobotBody

    return scan_layout(LAYOUT, turn_limits=turn_limits(RobotBody(LAYOUT),
                                                       LAYOUT.mapping.clearance_min))


def test_the_table_has_no_row_numbers_and_no_sideways_scrolling(gui):
    """Issue 27 item 15: a row-number column beside the Slot column, and the Front and Sweep
    columns behind a sideways scroll bar at the table's default size."""
    look = gui["table_look"]
    assert look["row_numbers"] is False
    assert look["sideways"] == 0, look
