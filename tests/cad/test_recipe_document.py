"""SPEC §11's recipe through the document: the ScanSettings object carries it, it survives save
and reload, a bad value names the object and property, a document without it judges by SPEC §4,
and a layout scans with it from the command line."""

import json
from dataclasses import replace

import FreeCAD as App
import pytest
from commands import waferscan

from waferscan.addon import paper_scenario
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import read_layout
from waferscan.core import recipe
from waferscan.core.errors import InputError
from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import MappingTolerances

PAPER = replace(read_scenario(paper_scenario()), robot=None)
RECIPE = {"thickness_min": 0.5, "thickness_max": 0.9, "double_threshold": 2.0,
          "position_below": 0.25, "position_above": 0.75, "rules": "boundary",
          "thickness_correction": 1.02}
WITH_RECIPE = replace(PAPER, mapping=replace(PAPER.mapping, **RECIPE))


@pytest.fixture
def doc(built):
    return built(WITH_RECIPE, "RecipeTest")


def test_the_settings_object_carries_the_recipe_and_it_reads_back(doc, tmp_path):
    settings = doc.getObject("ScanSettings")
    assert (settings.ThicknessMin, settings.ThicknessMax, settings.DoubleThreshold) == \
        (0.5, 0.9, 2.0)
    assert (settings.PositionBelow, settings.PositionAbove) == (0.25, 0.75)
    assert settings.Rules == "boundary" and settings.getEnumerationsOfProperty("Rules") == \
        ["waferscan", "boundary"]
    assert settings.ThicknessCorrection == 1.02
    assert recipe.recipe_fields(read_layout(doc).mapping) == RECIPE
    path = tmp_path / "recipe.FCStd"
    doc.saveCopy(str(path))
    again = App.openDocument(str(path))
    try:
        assert recipe.recipe_fields(read_layout(again).mapping) == RECIPE
    finally:
        App.closeDocument(again.Name)


def test_the_document_judges_with_its_recipe(doc):
    result = scan_document(doc)
    assert result.plan.rules == "boundary" and result.plan.thickness_window() == (0.5, 0.9)
    settings = doc.getObject("ScanSettings")
    settings.ThicknessMin = 0.66   # the paper's wafers read 0.65 (0.65 / 1.02 < 0.66): thin
    assert scan_document(doc).code == "1101221001220001010000010".replace("1", "4")


def test_a_document_without_a_recipe_judges_by_spec_4():
    plain = build_document(PAPER, "PlainRecipe")
    try:
        settings = plain.getObject("ScanSettings")
        assert settings.ThicknessMinSet is False and settings.Rules == "waferscan"
        assert read_layout(plain).mapping == PAPER.mapping
        for prop in ("ThicknessMin", "ThicknessMax", "DoubleThreshold", "PositionBelow",
                     "PositionAbove", "Rules", "ThicknessCorrection", "ThicknessMinSet",
                     "ThicknessMaxSet", "DoubleThresholdSet", "PositionBelowSet",
                     "PositionAboveSet"):
            settings.removeProperty(prop)  # as a document made before the recipe
        # paper.toml's clearance_min (SPEC §15) is no recipe key: its property stays.
        assert read_layout(plain).mapping == MappingTolerances(
            position_tolerance=0.5, protrusion_limit=1.0, clearance_min=0.5)
    finally:
        App.closeDocument(plain.Name)


@pytest.mark.parametrize("prop, value, message", [
    ("ThicknessMin", 0.95, "ScanSettings.ThicknessMin: thickness_min 0.95 must be less than "
                           "thickness_max 0.9"),
    ("DoubleThreshold", 0.8, "ScanSettings.DoubleThreshold: double_threshold 0.8 must be "
                             "greater than thickness_max 0.9"),
    ("ThicknessCorrection", 0.0, "ScanSettings.ThicknessCorrection: must be greater than 0, "
                                 "got 0.0"),
])
def test_a_bad_recipe_value_names_the_object_and_property(doc, prop, value, message):
    setattr(doc.getObject("ScanSettings"), prop, value)
    with pytest.raises(InputError) as caught:
        read_layout(doc)
    assert caught.value.message == message


def test_cli_scans_a_layout_with_its_recipe(tmp_path):
    path = tmp_path / "recipe.FCStd"
    document = build_document(WITH_RECIPE, "RecipeCli")
    try:
        document.saveAs(str(path))
    finally:
        App.closeDocument(document.Name)
    done = waferscan("scan", path, "--json")
    assert done.returncode == 0, done.stderr
    params = json.loads(done.stdout)["params"]
    assert {k: params[k] for k in RECIPE} == RECIPE
