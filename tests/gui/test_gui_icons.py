"""Each role its own icon, in the toolbar and in the tree: WaferScan's objects get their view
providers in a GUI session, also when the document was built and saved headless."""

from pathlib import Path

import pytest

from waferscan.cad.layout_files import opened_layout
from waferscan.addon import paper_scenario

PROBE = Path(__file__).resolve().with_name("icons_probe.py")
ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"
ICONS = {"Carrier": "WaferScan_Carrier.svg", "Scanner": "WaferScan_Scanner.svg",
         "ScanSettings": "WaferScan_ScanSettings.svg", "Wafer": "WaferScan_Wafer.svg"}


@pytest.fixture(scope="module")
def icons(run_gui_probe, tmp_path_factory):
    path = tmp_path_factory.mktemp("headless") / "paper-headless.FCStd"
    with opened_layout(paper_scenario()) as doc:  # plain Python: no GUI, no view providers
        doc.getObjectsByLabel("LP1_W02")[0].Visibility = False  # hidden in the file: stays so
        doc.saveAs(str(path))
    return run_gui_probe(PROBE, WAFERSCAN_GUI_LAYOUT=str(path),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))


@pytest.mark.parametrize("built", ["headless_built", "gui_built"])
def test_each_role_shows_its_own_icon(icons, built):
    found = icons[built]
    assert set(found) == set(ICONS)
    for role, (proxy, icon, drawn_as_icon, visible, display_mode, app_visible) in found.items():
        assert proxy == "ViewProviderRole", role
        assert icon == ICONS[role]
        assert drawn_as_icon is True, role
    # The carrier and the scanner are drawn (a document built headless used to open blank).
    assert found["Carrier"][3:] == [True, True, True], found
    assert found["Scanner"][3:] == [True, True, True], found


def test_a_document_built_headless_opens_with_everything_shown(icons):
    shown = icons["headless_shown"]
    assert shown == {"LP1 assembly": [True, True], "Robot": [True, True],
                     "LP1_W01": [True, True], "LP1_W02": [False, False]}, shown


def test_the_wafers_tree_items_show_the_wafer_icon_not_parts_cylinder(icons):
    # Issue 27 (item 15): the flat wafers WaferScan builds were Part::Cylinders, whose tree
    # items showed Part's cylinder icon. How far each wafer's tree item icon is from the wafer's
    # SVG and from a Part::Cylinder's tree item icon (mean channel difference at 16 px; the
    # tree draws an SVG a little differently from Qt alone: 2.7 here, against 84).
    for label, (from_wafer, from_cylinder) in icons["tree_icons"].items():
        assert from_wafer < 0.1 * from_cylinder, (label, from_wafer, from_cylinder)
    assert sorted(icons["tree_icons"]) == ["LP1_W01", "LP1_W04"]
    assert icons["gui_built"]["Wafer"][:2] == ["ViewProviderRole", "WaferScan_Wafer.svg"]
