"""The sensor's signal in the GUI (SPEC §10): after Run scan on the paper's layout with a 1 mm
beam spot, the scan panel's trace follows the beam, and the slot-code dialog draws b(z) over the
whole scan with its thresholds and edges."""

from pathlib import Path

import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

# The colours of gui/signal_view.py (which imports Qt, so not in this process).
TRACE, THRESHOLD_ON = (30, 100, 200), (200, 40, 40)

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO / "resources" / "examples" / "paper.toml"
PROBE = Path(__file__).resolve().with_name("signal_probe.py")


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    path = tmp_path_factory.mktemp("gui-signal") / "spot.toml"
    path.write_text(PAPER.read_text().replace("[sensor]\n", "[sensor]\nspot_diameter = 1.0\n", 1))
    return path


@pytest.fixture(scope="module")
def gui(run_gui_probe, scenario):
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(scenario))


def test_the_live_trace_follows_the_beam(gui):
    windows = gui["live_windows"]
    assert len(windows) > 10
    # The window is the spot's height and a wafer's thickness either side of the beam: 1.7 mm.
    for z, (low, high) in windows:
        assert low == pytest.approx(z - 1.7) and high == pytest.approx(z + 1.7)
    assert gui["live_cursor"] == pytest.approx(550.0)
    z, b = gui["live_samples"]
    assert min(z) <= 548.3 + 0.2 and max(z) >= 550.0 and max(b) == 0.0  # nothing up there


def test_the_slot_code_dialog_draws_the_whole_signal(gui, scenario):
    result = scan_layout(read_scenario(scenario))
    assert gui["dialog_window"] == [280.0, 550.0]
    assert gui["thresholds"] == [0.5, 0.5]
    assert gui["edges"] == 2 * len(result.runs) == 20
    drawn = {tuple(rgb): n for rgb, n in gui["dialog_colours"]}
    # The trace's and the threshold's colours are on screen (antialiasing shades the rest).
    assert drawn.get(TRACE, 0) >= 50
    # The dashed threshold, antialiased across two pixel rows: its red, lightened.
    reddish = sum(n for (r, g, b), n in drawn.items() if r >= 200 and g <= 170 and b <= 170
                  and r - g >= 60)
    assert reddish >= 100


def _round_step(ticks):
    values = [v for v, _ in ticks]
    steps = {round(b - a, 9) for a, b in zip(values, values[1:])}
    assert len(steps) == 1, steps
    step = steps.pop()
    mantissa = step / 10 ** __import__("math").floor(__import__("math").log10(step))
    assert round(mantissa, 6) in (1.0, 2.0, 5.0), step
    return step


def test_b_of_z_has_z_tick_labels(gui):
    """Issue 27 item 15: b(z) had no Z tick labels, only the range in its caption."""
    ticks = gui["dialog_ticks"]
    assert len(ticks) >= 3, ticks
    step = _round_step(ticks)
    assert 280.0 <= ticks[0][0] < 280.0 + step and 550.0 - step < ticks[-1][0] <= 550.0
    assert all(label == f"{value:.0f}" for value, label in ticks)  # whole mm at this span
    live = gui["live_ticks"]  # 3.4 mm of Z around the beam at the end
    assert len(live) >= 2, live
    step = _round_step(live)
    assert all(548.3 - 1e-9 <= value <= 551.7 + 1e-9 for value, _ in live)
    assert all(float(label) == pytest.approx(value) for value, label in live)
