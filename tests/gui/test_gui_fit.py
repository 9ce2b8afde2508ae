"""The workbench on a small screen and in FreeCAD's default layout: task panels in the 264 px
combo view, dialogs on a 1024×700 screen; the scan panel's playback in real time, Stop then
Replay, one set of results dialogs per document, Export CSV… next to the document, the
cross-check's table in a fixed-pitch font."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("fit_probe.py")
ARTIFACTS = REPO / "test-artifacts"
SHOTS = ("gui-scan-panel-264.png", "gui-mcs-panel-264.png", "gui-results-1024x700.png",
         "gui-slot-code-1024x700.png")


@pytest.fixture(scope="module")
def fit(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("fit")
    for name in SHOTS:
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, screen="1024x700", WAFERSCAN_GUI_MCS=str(folder),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), folder


def test_the_scan_panel_fits_the_default_combo_view(fit):
    gui, _ = fit
    assert gui["combo_width"] <= 270
    assert gui["scan_panel"]["clipped"] == []
    assert gui["scan_panel"]["sideways"] is False
    assert gui["sensor_fields_shown"] == 9  # the Sensor and slow scan section, opened
    assert gui["scan_panel_sensor"]["clipped"] == []
    assert gui["scan_panel_sensor"]["sideways"] is False


def test_the_mcs_panel_fits_the_default_combo_view(fit):
    gui, _ = fit
    assert gui["mcs_rows"] == 2
    assert gui["mcs_panel"]["clipped"] == []
    assert gui["mcs_panel"]["sideways"] is False
    assert gui["mcs_log_sideways"] is False, gui["mcs_log_sizes"]


def test_the_dialogs_fit_a_1024_by_700_screen(fit):
    gui, _ = fit
    width, height = gui["screen_for_dialogs"]
    assert width <= 1024 and height <= 700
    for title, (w, h) in list(gui["dialog_sizes"].items()) + list(gui["dialog_minimums"].items()):
        assert w <= width and h <= height - 40, title  # 40 px for a window's title bar
    assert gui["export_inside"] is True


def test_titles_name_the_document_and_a_second_scan_replaces_the_dialogs(fit):
    gui, _ = fit
    assert set(gui["dialog_sizes"]) == {"WaferScan results: paper-fit",
                                        "WaferScan slot code: paper-fit"}
    assert gui["dialogs_after_second_scan"] == ["WaferScan results: paper-fit",
                                                "WaferScan slot code: paper-fit"]
    assert gui["second_geometry"] == gui["first_geometry"]


def test_playback_is_in_seconds_and_a_stopped_scan_replays(fit):
    gui, _ = fit
    assert gui["playback"] == [" s", 30.0, 30.0]
    assert gui["position_has_arrows"] is False
    assert gui["position_text"].endswith(" mm")
    assert gui["after_stop"][0] is True and "Stopped" in gui["after_stop"][1]
    assert gui["replay_new_panel"] is True and gui["replay_seconds"] == 30.0
    assert gui["replay_seconds_after"] == 1.0
    assert gui["replay_completed"] is True


def test_export_starts_next_to_the_document(fit):
    gui, folder = fit
    assert gui["export_start"] == [str(folder / "paper-fit-results.csv")]


def test_the_cross_check_table_is_fixed_pitch(fit):
    gui, _ = fit
    assert gui["crosscheck"] == [True, "WaferScan cross-check: paper-fit", True]


def test_screenshots_saved(fit):
    for name in SHOTS:
        assert (ARTIFACTS / name).stat().st_size > 1000, name
