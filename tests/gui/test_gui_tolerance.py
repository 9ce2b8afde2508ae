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
                "workers": 1, "out": str(out), "n_document": N_DOCUMENT}
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
