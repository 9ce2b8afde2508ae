"""Issue 25: the MCS link panel that loses the folder's lock to another link (the lock file
deleted, or the folder removed and recreated, and another link locking it) stops watching,
says so in red, offers Start again, and answers nothing more."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("mcs_lock_probe.py")
ARTIFACTS = REPO / "test-artifacts"


@pytest.fixture(scope="module")
def lost(run_gui_probe, tmp_path_factory):
    base = tmp_path_factory.mktemp("gui-mcs-lock")
    return run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(base),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), base


@pytest.mark.parametrize("case", ["lock_deleted", "folder_recreated"])
def test_a_panel_that_lost_its_lock_stops_and_says_so(lost, case):
    probe, base = lost
    seen = probe[case]
    folder = base / case
    assert seen["watching_before"] is True
    assert seen["state"].startswith(f"stopped: {folder}: lost the folder's lock to another "
                                    "WaferScan link")
    assert seen["state"].endswith(": this link stops answering")
    assert "color: #c01010" in seen["style"]
    assert seen["panel_open"] is True
    assert (seen["start_enabled"], seen["stop_enabled"]) == (True, False)
    # seq 1 was answered before the loss; 2 and 3 are the other link's, never this panel's.
    assert [row[1:4] for row in seen["rows"]] == [["1", "SCF", "ok"]]
    assert seen["rows_after"] == 1
    if case == "lock_deleted":
        assert seen["results_after"].startswith("seq = 1\n")
        assert seen["history_after"] == ["results-00000001.txt"]
    else:  # the recreated folder holds no answer at all
        assert seen["results_after"] is None and seen["history_after"] == []
    assert (ARTIFACTS / f"gui-mcs-lock-lost-{case}.png").stat().st_size > 1000
