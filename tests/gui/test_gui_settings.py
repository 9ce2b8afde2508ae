"""Settings as FreeCAD users expect them: the preferences dialog accepted untouched changes
nothing, in the mm and in an inch unit schema, and shows enough digits to read a tolerance; the
MCS link panel with no folder asks for one instead of writing into FreeCAD's working folder."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("settings_probe.py")
ARTIFACTS = REPO / "test-artifacts"
EXACT = {"ThicknessTolerance": 0.125, "PositionTolerance": 0.2, "ProtrusionLimit": 2.0}


@pytest.fixture(scope="module")
def settings(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("mcs-folder")
    return run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(folder),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS)), folder


@pytest.mark.parametrize("schema", ["mm", "inch"])
def test_preferences_accepted_untouched_keep_every_value_exactly(settings, schema):
    gui, _ = settings
    stored = gui[schema]["stored"]
    assert {name: stored[name] for name in EXACT} == EXACT  # exact, not approximately
    assert stored["McsFolder"] == "" and stored["PlaybackSeconds"] == 7.25


def test_the_fields_show_enough_digits_in_each_unit(settings):
    gui, _ = settings
    assert gui["mm"]["texts"] == {"ThicknessTolerance": "0.125 mm",
                                  "PositionTolerance": "0.2 mm", "ProtrusionLimit": "2 mm"}
    texts = gui["inch"]["texts"]
    for name, value in EXACT.items():
        number, unit = texts[name].split()
        assert unit == "in"
        # Six significant digits: the value read back to within a millionth.
        assert float(number) * 25.4 == pytest.approx(value, rel=1e-6)


def test_only_the_edited_field_changes(settings):
    gui, _ = settings
    stored = gui["inch_edited"]["stored"]
    assert stored["PositionTolerance"] == pytest.approx(0.254, abs=1e-12)  # typed 0.01 (in)
    assert stored["ThicknessTolerance"] == 0.125 and stored["ProtrusionLimit"] == 2.0


def test_an_empty_mcs_folder_asks_for_one(settings):
    gui, folder = settings
    assert gui["mcs_folder_shown"] == ""
    assert gui["start_cancelled"] == [False, "no MCS folder: choose one with Browse…"]
    assert gui["save_cancelled"][0] is False
    assert "no MCS folder" in gui["save_cancelled"][1]
    assert gui["cwd_parameters"] is False
    assert len(gui["asked"]) == 3 and all("MCS folder" in title for title in gui["asked"])
    assert gui["saved"] is True
    assert Path(gui["folder_after_save"]) == folder
    assert (folder / "parameters.txt").read_text(encoding="utf-8").startswith("#")


def test_screenshots_saved(settings):
    for key in ("mm", "inch"):
        assert (ARTIFACTS / f"gui-preferences-{key}.png").stat().st_size > 1000
