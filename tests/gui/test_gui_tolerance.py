"""The "Tolerance study…" command in a real FreeCAD GUI under Xvfb: its dialog runs a small
sweep (one Dask worker, in a QProcess of the venv's Python), follows its progress and shows the
summary and the plots; the summary is the one the library gives for the same seed."""

import json
from pathlib import Path

import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core import sweep
from waferscan.core.sweep.distributions import read_tolerances

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("tolerance_probe.py")
PAPER = REPO / "resources" / "examples" / "paper.toml"
TOLERANCES = REPO / "resources" / "examples" / "fab_tolerances.toml"
N, SEED = 1200, 9
N_DOCUMENT = 500


@pytest.fixture(scope="module")
def gui(run_gui_probe, tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "out"
    settings = {"input": str(PAPER), "tolerances": str(TOLERANCES), "n": N, "seed": SEED,
                "workers": 1, "out": str(out), "n_document": N_DOCUMENT,
                "stopped_out": str(out.with_name("stopped"))}
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SWEEP=json.dumps(settings),
                         WAFERSCAN_GUI_ARTIFACTS=str(REPO / "test-artifacts")), out


def test_the_dialog_runs_a_sweep_and_shows_its_plots(gui):
    result, out = gui
    assert result["opened"] and result["running"] == "running"
    assert result["state"] == "done", result["errors"]
    assert result["progress_end"][0] == result["progress_end"][1]
    # The bar followed the partitions: it was at some partition count short of the end.
    assert any(0 < v < m for v, m in result["progress_seen"]), result["progress_seen"]
    assert all(width and width > 100 for width in result["plots"])
    assert "confusion" in result["text"] and f"{N:,} layouts" in result["text"]
    assert (out / "summary.json").exists()


def test_the_dialogs_summary_is_the_librarys_for_that_seed(gui):
    result, _ = gui
    expected = sweep.run_sweep(read_scenario(PAPER), read_tolerances(TOLERANCES), N,
                               seed=SEED)
    assert result["summary"] == json.loads(json.dumps(expected))


def test_without_a_file_the_active_document_is_swept(gui):
    """The layout field left empty: the active document (the paper's layout, built in the GUI)
    is saved to a copy and swept; its summary is the scenario's for the same seed."""
    result, _ = gui
    assert result["document_state"] == "done", result["document_errors"]
    source = result["document_args"][3]
    assert source.endswith(f"{result['document']}.FCStd") and source != str(PAPER)
    expected = sweep.run_sweep(read_scenario(PAPER), read_tolerances(TOLERANCES), N_DOCUMENT,
                               seed=SEED)
    assert result["document_summary"] == json.loads(json.dumps(expected))


def test_run_and_stop_are_recorded_lines_a_macro_replays(gui):
    """Issue 27 item 12: the dialog's Run and Stop appear in the Python console as the calls a
    script would make, with the dialog's fields as arguments."""
    result, out = gui
    calls = result["console_calls"]
    runs = [c for c in calls if "run_tolerance_study(" in c]
    assert len(runs) == 3, calls  # the sweep, the stopped one, the active document's
    assert runs[0] == (
        f"waferscan.gui.commands.run_tolerance_study(input_path={str(PAPER)!r}, "
        f"tolerances={str(TOLERANCES)!r}, n={N}, seed={SEED}, workers=1, out={str(out)!r})")
    assert "input_path=''" in runs[2] and f"n={N_DOCUMENT}" in runs[2]
    assert calls.count("waferscan.gui.commands.stop_tolerance_study()") == 1


def test_stop_interrupts_a_long_sweep_and_writes_nothing(gui):
    """Issue 27 item 15: the study had no Stop; a 50 million layout sweep is stopped after its
    first partition: the process is gone, the dialog says so and nothing was written."""
    result, out = gui
    assert result["stop_enabled"] == [True, False]
    state, status, stop_enabled, run_enabled, no_process = result["stopped"]
    assert state == "stopped" and "interrupted" in status
    assert [stop_enabled, run_enabled, no_process] == [False, True, True]
    assert result["stopped_out"] is None  # the output folder was not made
    assert not Path(f"/proc/{result['pid']}").exists()


def test_a_click_enlarges_a_plot_in_a_window_of_its_own(gui):
    result, _ = gui
    visible, resizable, shown, full = result["enlarged"]
    assert visible and resizable
    assert shown < full  # the dialog shows it smaller than the PNG
    assert result["enlarged_width"] > shown


def test_the_dialog_fits_a_small_screen(run_gui_probe):
    """Issue 27 item 15: 1000 x 800 on a 1024 x 700 screen put Run off the screen."""
    result = run_gui_probe(PROBE, screen="1024x700", WAFERSCAN_GUI_SWEEP_SMALL="1",
                           WAFERSCAN_GUI_SWEEP=json.dumps({}),
                           WAFERSCAN_GUI_ARTIFACTS=str(REPO / "test-artifacts"))
    x, y, width, height = result["screen"]
    fx, fy, fwidth, fheight = result["frame"]
    assert fwidth <= width and fheight <= height, (result["screen"], result["frame"])
    assert result["buttons_on_screen"] == [True, True]
