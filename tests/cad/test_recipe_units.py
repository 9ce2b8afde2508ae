"""Issue 27 item 13 through the document: the recipe's limits are lengths (they follow the
user's unit schema in the property editor) and "not set" is a ticked-off box beside each
(``ThicknessMinSet``...), not a magic -1. A document saved before, with the limits as bare
floats and -1 for "not set", still opens and scans the same."""

from dataclasses import replace

import FreeCAD as App
import pytest

from waferscan.addon import paper_scenario
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import read_layout
from waferscan.core.files.scenario import read_scenario

PAPER = replace(read_scenario(paper_scenario()), robot=None)
LIMITS = ("ThicknessMin", "ThicknessMax", "DoubleThreshold", "PositionBelow", "PositionAbove")
THIN = "1101221001220001010000010".replace("1", "4")  # from 0.66 mm the paper's wafers are thin


def test_the_limits_are_lengths_with_a_box_for_not_set():
    doc = build_document(PAPER, "RecipeUnits")
    try:
        settings = doc.getObject("ScanSettings")
        for prop in LIMITS:
            assert settings.getTypeIdOfProperty(prop) == "App::PropertyLength"
            assert settings.getTypeIdOfProperty(prop + "Set") == "App::PropertyBool"
            assert getattr(settings, prop + "Set") is False
        assert read_layout(doc).mapping == PAPER.mapping
        settings.ThicknessMin = App.Units.Quantity("0.026 in")  # 0.6604 mm
        assert read_layout(doc).mapping == PAPER.mapping  # not ticked: still SPEC §4's rule
        settings.ThicknessMinSet = True
        assert read_layout(doc).mapping.thickness_min == pytest.approx(0.6604)
        assert scan_document(doc).code == THIN
    finally:
        App.closeDocument(doc.Name)


def _saved_the_old_way(tmp_path, thickness_min):
    """The paper's layout with the recipe as earlier versions saved it: App::PropertyFloat in mm,
    -1 for "not set" (and no ...Set boxes)."""
    doc = build_document(PAPER, "RecipeOld")
    try:
        settings = doc.getObject("ScanSettings")
        for prop in LIMITS:
            tip = settings.getDocumentationOfProperty(prop)
            settings.removeProperty(prop)
            if prop + "Set" in settings.PropertiesList:
                settings.removeProperty(prop + "Set")
            settings.addProperty("App::PropertyFloat", prop, "WaferScan", tip)
            setattr(settings, prop, -1.0)
        settings.ThicknessMin = thickness_min
        path = tmp_path / "old.FCStd"
        doc.saveAs(str(path))
    finally:
        App.closeDocument(doc.Name)
    return path


@pytest.mark.parametrize("thickness_min, code", [(-1.0, "1101221001220001010000010"),
                                                 (0.66, THIN)])
def test_a_document_saved_the_old_way_scans_the_same(tmp_path, thickness_min, code):
    doc = App.openDocument(str(_saved_the_old_way(tmp_path, thickness_min)))
    try:
        mapping = read_layout(doc).mapping
        assert mapping.thickness_min == (None if thickness_min < 0 else thickness_min)
        assert (mapping.thickness_max, mapping.double_threshold, mapping.position_below,
                mapping.position_above) == (None, None, None, None)
        assert scan_document(doc).code == code
    finally:
        App.closeDocument(doc.Name)


def test_an_old_document_is_brought_up_to_date_without_changing_its_recipe(tmp_path):
    from waferscan.cad import recipe_properties

    doc = App.openDocument(str(_saved_the_old_way(tmp_path, 0.66)))
    try:
        settings = doc.getObject("ScanSettings")
        before = read_layout(doc).mapping
        assert recipe_properties.upgrade(settings) is True
        assert settings.getTypeIdOfProperty("ThicknessMin") == "App::PropertyLength"
        assert settings.ThicknessMinSet is True and settings.ThicknessMaxSet is False
        assert settings.ThicknessMin.Value == pytest.approx(0.66)
        assert settings.ThicknessMax.Value == 0.0
        assert read_layout(doc).mapping == before
        assert recipe_properties.upgrade(settings) is False  # once is enough
    finally:
        App.closeDocument(doc.Name)
