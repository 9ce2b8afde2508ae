"""Each rule every reader applies lives in one function (core/rules.py); the readers agree with
it. The doctests (the examples in rules.py, errors.py and the public geometry) run here too."""

import doctest

import pytest

from waferscan.core import errors, rules
from waferscan.core.errors import EngineError, InputError, ShapeError, WaferScanError
from waferscan.core.files.validation import carrier_problems
from waferscan.core.geometry import beam as geometry
from waferscan.core.model import Beam, Carrier, Layout, MappingTolerances, ScanParameters
from waferscan.core.scan.engines import ENGINES


@pytest.mark.parametrize("module", [rules, errors, geometry])
def test_doctests(module):
    failures, tried = doctest.testmod(module)
    assert tried > 0 and failures == 0


def test_every_error_is_a_waferscan_error():
    assert issubclass(InputError, WaferScanError)
    assert issubclass(ShapeError, WaferScanError) and issubclass(ShapeError, ValueError)
    from waferscan.core.schema import ScanRangeError
    assert issubclass(ScanRangeError, WaferScanError)


@pytest.mark.parametrize("thickness, pitch", [(0.775, 10.0), (9.999, 10.0), (10.0, 10.0),
                                              (12.0, 10.0)])
def test_validation_follows_the_thickness_rule(thickness, pitch):
    carrier = Carrier("LP1", 25, pitch, 0.0, (0.0, 0.0), 300.0, thickness)
    blamed = any(p.key == "wafer_thickness" for p in carrier_problems(carrier))
    assert blamed == (not rules.thickness_fits_pitch(thickness, pitch)) == (thickness >= pitch)


def _layout(carriers, chosen):
    return Layout(carriers=tuple(carriers), wafers=(), beam=Beam((0, 0, 0), (1, 0, 0), 1.0),
                  scan=ScanParameters(0.0, 60.0), carrier=chosen)


def test_the_layout_follows_the_carrier_rule():
    one, two = Carrier("A", 5, 10.0, 0.0, (0.0, 0.0), 300.0, 0.7), Carrier("B", 5, 10.0, 0.0, (0.0, 0.0), 300.0, 0.7)
    assert _layout([one], None).scanned_carrier is one
    assert _layout([one, two], "B").scanned_carrier is two
    with pytest.raises(ValueError, match="several carriers"):
        _layout([one, two], None).scanned_carrier
    with pytest.raises(ValueError, match="no carrier named 'C'"):
        _layout([one, two], "C").scanned_carrier


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_exact_edges_only_from_the_engine_the_rule_names(engine):
    layout = _layout([Carrier("A", 5, 10.0, 0.0, (0.0, 0.0), 300.0, 0.7)], None).with_scan(z_step=0.0, start_z=0.0,
                                                                      final_z=60.0)
    if rules.offers_exact_edges(engine):
        assert ENGINES[engine](layout).runs == ()
    else:
        with pytest.raises(EngineError, match="only offered by the analytic engine"):
            ENGINES[engine](layout)


def test_stored_thickness_tolerance_round_trips():
    for tolerance in (None, 0.0, 0.35):
        stored = rules.stored_thickness_tolerance(tolerance)
        assert rules.thickness_tolerance_from_stored(stored) == tolerance
        assert MappingTolerances(thickness_tolerance=rules.thickness_tolerance_from_stored(
            stored)).thickness_tolerance_for(0.7) == (0.35 if tolerance is None else tolerance)


def test_a_scenario_without_a_mapping_table_gets_the_default_mapping_given():
    """open_scenario's rule (the preferences' tolerances where the file sets none), read in the
    one parse of the file."""
    from waferscan.addon import paper_scenario
    from waferscan.core.files.scenario import parse_scenario

    paper = paper_scenario().read_text(encoding="utf-8")
    # The whole table, to the blank line before [[carrier]] (SPEC §15's clearance_min in it).
    start = paper.index("[mapping]\n")
    mapping_table = paper[start:paper.index("\n\n", start) + 1]
    assert mapping_table.startswith("[mapping]\nposition_tolerance = 0.5\nprotrusion_limit = 1.0\n")
    assert mapping_table.endswith("clearance_min = 0.5\n")
    text = paper.replace(mapping_table, "")
    given = MappingTolerances(thickness_tolerance=0.2, position_tolerance=0.9,
                              protrusion_limit=7.0)
    assert parse_scenario(text, default_mapping=given).mapping == given
    assert parse_scenario(text).mapping == MappingTolerances()
    assert parse_scenario(paper, default_mapping=given).mapping == MappingTolerances(
        position_tolerance=0.5, protrusion_limit=1.0, clearance_min=0.5)


@pytest.mark.parametrize("diameter, thickness", [
    (300.0, 0.775), (300.0, 0.7), (299.2, 0.775), (200.0, 0.725), (150.0, 0.675),
    (100.0, 0.525), (125.0, 0.625), (450.0, 0.925)])
def test_semi_wafers_are_wafer_like(diameter, thickness):
    assert rules.wafer_like(diameter, thickness) is None


@pytest.mark.parametrize("diameter, thickness, reason", [
    (0.8, 160.0, "0.8 mm across and 160 mm high"),  # a rod
    (120.0, 300.0, "at least 20 times as wide as thick"),  # the robot's column
    (160.0, 20.0, "at least 20 times"),  # a collar
    (300.0, 16.0, "at least 20 times"),  # a 300 mm plate 16 mm thick
    (250.0, 0.775, "not a wafer size"),
    (302.0, 0.775, "not a wafer size (100, 125, 150, 200, 300, 450 mm, ± 1 mm)")])
def test_other_cylinders_are_not_wafers_and_say_why(diameter, thickness, reason):
    assert reason in rules.wafer_like(diameter, thickness)


def test_the_sizes_the_user_gives_replace_semis():
    assert rules.wafer_like(250.0, 0.7, diameters=(250.0,)) is None
    assert "not a wafer size (250 mm" in rules.wafer_like(300.0, 0.7, diameters=(250.0,))
