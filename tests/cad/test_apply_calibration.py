"""A calibration written into the document it was made of (SPEC §11; the GUI's "Apply to
document"): the scanned carrier's taught seat and pitch, the scan range and the recipe, so that
the document then maps every wafer; undone in one step; a document without ScanSettings gets
them."""

import pytest
from scenarios import ROOT

from waferscan.cad.document_calibration import apply_calibration, calibrate_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.reader import read_layout
from waferscan.core.files.scenario import read_scenario

DRIFTED = ROOT / "resources" / "examples" / "calibration_drifted.toml"
LOAD = "1100100001000010000100011"


@pytest.fixture
def drifted(built):
    doc = built(read_scenario(DRIFTED), "DriftedApply")
    doc.UndoMode = 1
    return doc


def _settings(doc):
    return next(o for o in doc.Objects if "ThicknessCorrection" in o.PropertiesList)


def test_the_document_takes_the_calibrated_recipe_and_maps_every_wafer(drifted):
    before = read_layout(drifted)
    assert scan_document(drifted).code != LOAD  # the taught recipe misreads the upper slots
    calibration = calibrate_document(drifted)
    drifted.openTransaction("Apply calibration")
    written = apply_calibration(drifted, calibration)
    drifted.commitTransaction()
    now = read_layout(drifted)
    after = calibration.after
    carrier, expected = now.scanned_carrier, after.scanned_carrier
    assert carrier.first_slot_z == pytest.approx(expected.first_slot_z, abs=1e-9)
    assert carrier.first_slot_z != before.scanned_carrier.first_slot_z
    assert carrier.pitch == expected.pitch == 10.021
    assert (carrier.center, carrier.front) == (before.scanned_carrier.center,
                                                before.scanned_carrier.front)
    assert (now.scan.start_z, now.scan.final_z) == (after.scan.start_z, after.scan.final_z)
    assert now.mapping == after.mapping and now.mapping.thickness_correction == 0.964286
    assert now.wafers == before.wafers  # what the sensor measured stays where it is
    assert scan_document(drifted).code == LOAD
    assert written["ScanSettings"] is _settings(drifted)
    assert drifted.UndoNames[0] == "Apply calibration"
    drifted.undo()
    assert read_layout(drifted) == before


def test_a_document_without_scan_settings_gets_them_from_the_calibration(drifted):
    drifted.removeObject(_settings(drifted).Name)
    drifted.recompute()
    calibration = calibrate_document(drifted)
    apply_calibration(drifted, calibration)
    settings = _settings(drifted)
    now = read_layout(drifted)
    assert (float(settings.StartZ), float(settings.FinalZ)) == (
        calibration.after.scan.start_z, calibration.after.scan.final_z)
    assert now.mapping.thickness_correction == calibration.after.mapping.thickness_correction
    assert now.scanned_carrier.pitch == calibration.after.scanned_carrier.pitch
