"""A slow scan's jabs and sweeps in the GUI (SPEC §13): after Run scan on resources/examples/
slow_jab.toml the arm jabs and sweeps pocket by pocket in the document; the task panel says the
pocket, the phase and the advance or wrist angle; the beam the robot holds is the closed form's."""

import shutil
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
    assert (jab["pocket"], jab["phase"], jab["arm"]) == ("pocket 8", "jab in", "advance 26.60 mm")
    assert jab["beam"] == "blocked"
    assert jab["found"] == "front 5.000 mm, sweep -33.845° to +33.845°"
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
    assert abs(jab["fork"][1] - start["fork"][1]) == pytest.approx(26.6, abs=1e-6)
    assert jab["forearm"] != pytest.approx(start["forearm"], abs=1.0)


def test_after_the_pockets_the_results_open_and_a_screenshot_of_a_jab_is_left(gui):
    assert "1151221601220001010000010" in gui["code"]
    assert "Done" in gui["panel_status"]
    assert (ARTIFACTS / "gui-jab.png").stat().st_size > 10_000


def test_the_panel_says_where_the_sweep_turns_a_tine_into_a_wafer(gui):
    from waferscan.core.scan.layout_scan import scan_layout

    lines = [w for w in scan_layout(LAYOUT).warnings if "a tine" in w]
    assert len(lines) == 3  # the seated pockets together, slot 3 and slot 8
    for line in lines:
        assert f"Warning: {line}" in gui["panel_status"]


def test_the_results_table_shows_front_and_sweep(gui):
    from waferscan.core.scan.layout_scan import scan_layout

    assert gui["headers"][-3:] == ["Front [mm]", "Sweep first [°]", "Sweep last [°]"]
    result = scan_layout(LAYOUT)
    rows = {int(r[0]): r for r in gui["rows"]}
    for probe in result.pockets:
        front, first, last = rows[probe.slot][-3:]
        assert front == ("" if probe.front is None else f"{probe.front:.3f}")
        if probe.sweep is None:
            assert (first, last) == ("", "")
        else:
            assert (first, last) == (f"{probe.sweep[0]:+.3f}", f"{probe.sweep[1]:+.3f}")
    assert rows[8][-3:] == ["5.000", "-33.845", "+33.845"]


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


def slow_scan_result():
    from waferscan.core.scan.layout_scan import scan_layout
    return scan_layout(LAYOUT)


def test_the_table_has_no_row_numbers_and_no_sideways_scrolling(gui):
    """Issue 27 item 15: a row-number column beside the Slot column, and the Front and Sweep
    columns behind a sideways scroll bar at the table's default size."""
    look = gui["table_look"]
    assert look["row_numbers"] is False
    assert look["sideways"] == 0, look
