"""The recipe's keys (SPEC §11) in every reader: parameters.txt, a scenario's [mapping]; one
validation for both naming file, line, key and value; results.txt's header and --json list what
a scan used; a scan without a recipe lists what it always did."""

import json

import pytest
from commands import waferscan
from scenarios import PAPER as PAPER_PATH
from scenarios import PAPER_TEXT

from waferscan.core import recipe
from waferscan.core.errors import InputError
from waferscan.core.files.mcs import (
    apply_parameters,
    format_parameters,
    format_results,
    parse_parameters,
    used_parameters,
)
from waferscan.core.files.scenario import parse_scenario, read_scenario
from waferscan.core.mapping import BOUNDARY
from waferscan.core.scan.layout_scan import scan_layout

PAPER = read_scenario(PAPER_PATH)

RECIPE_TEXT = ("thickness_min = 0.5\nthickness_max = 0.9\ndouble_threshold = 2.0\n"
               "position_below = 0.25\nposition_above = 0.75\nrules = boundary\n"
               "thickness_correction = 1.02\n")
RECIPE = {"thickness_min": 0.5, "thickness_max": 0.9, "double_threshold": 2.0,
          "position_below": 0.25, "position_above": 0.75, "rules": "boundary",
          "thickness_correction": 1.02}


def with_mapping(lines):
    """The paper's scenario with ``lines`` added to its [mapping] table."""
    assert PAPER_TEXT.count("[mapping]\n") == 1
    return PAPER_TEXT.replace("[mapping]\n", "[mapping]\n" + lines)


def test_parameters_txt_reads_every_recipe_key_into_the_scan_plan():
    layout = apply_parameters(PAPER, parse_parameters(RECIPE_TEXT))
    assert {k: getattr(layout.mapping, k) for k in recipe.RECIPE_KEYS} == RECIPE
    plan = scan_layout(layout).plan
    assert plan.thickness_window() == (0.5, 0.9)
    assert plan.position_window() == (0.25, 0.75)
    assert plan.double_limit() == 2.0
    assert (plan.rules, plan.thickness_correction) == (BOUNDARY, 1.02)


def test_a_scenario_mapping_table_reads_the_same_recipe():
    toml = "".join(f"{k} = {json.dumps(v)}\n" for k, v in RECIPE.items())
    layout = parse_scenario(with_mapping(toml), "s.toml", folder=PAPER_PATH.parent)
    from_file = apply_parameters(PAPER, parse_parameters(RECIPE_TEXT))
    assert layout.mapping == from_file.mapping


def test_results_header_and_json_list_the_recipe_used():
    layout = apply_parameters(PAPER, parse_parameters(RECIPE_TEXT))
    result = scan_layout(layout)
    header = format_results(7, "SCF", result, timestamp="T").split("\n\n")[0].splitlines()
    listed = {line.partition(" =")[0]: line.partition(" =")[2].strip() for line in header}
    for key, value in RECIPE.items():
        assert listed[key] == (value if isinstance(value, str) else repr(value))
    # after SPEC §4's tolerances, in RECIPE_KEYS' order
    keys = [line.split(" = ")[0] for line in header]
    assert keys.index("protrusion_limit") < keys.index("thickness_min")
    assert [k for k in keys if k in RECIPE] == list(recipe.RECIPE_KEYS)
    assert {k: used_parameters(layout)[k] for k in RECIPE} == RECIPE


def test_a_scan_without_a_recipe_lists_none_of_its_keys():
    assert not set(recipe.RECIPE_KEYS) & set(used_parameters(PAPER))


def test_the_written_parameters_read_back_as_the_same_recipe():
    layout = apply_parameters(PAPER, parse_parameters(RECIPE_TEXT))
    again = apply_parameters(PAPER, parse_parameters(format_parameters(layout)))
    assert recipe.recipe_fields(again.mapping) == recipe.recipe_fields(layout.mapping) == RECIPE


def test_the_recipe_changes_the_paper_code_as_its_rules_say():
    # The paper's wafers read 0.65 on the 0.05 mm grid: a window from 0.66 calls them thin (4),
    # cross-slotted runs (5.35 mm) stay 2 under either rule set.
    layout = apply_parameters(PAPER, parse_parameters("thickness_min = 0.66\n"))
    assert scan_layout(layout).code == "1101221001220001010000010".replace("1", "4")
    # a thickness correction of 0.65 / 0.7 brings them back
    layout = apply_parameters(PAPER, parse_parameters(
        f"thickness_min = 0.66\nthickness_correction = {0.65 / 0.7!r}\n"))
    assert scan_layout(layout).code == "1101221001220001010000010"


@pytest.mark.parametrize("text, line, message", [
    ("thickness_min = 0.9\nthickness_max = 0.8\n", 1,
     "thickness_min: thickness_min 0.9 must be less than thickness_max 0.8"),
    ("thickness_min = 1.2\n", 1,                      # above the default max t + Δt = 1.05
     "thickness_min: thickness_min 1.2 must be less than thickness_max 1.05"),
    ("thickness_max = 0.9\ndouble_threshold = 0.9\n", 2,
     "double_threshold: double_threshold 0.9 must be greater than thickness_max 0.9"),
    ("# a comment\nthickness_max = 2.0\n", 2,         # above the default 2t + Δt = 1.75
     "thickness_max: double_threshold 1.75 must be greater than thickness_max 2"),
    ("position_below = -0.1\n", 1, "position_below: must not be negative, got ' -0.1'"),
    ("position_above = x\n", 1, "position_above: expected a number, got 'x'"),
    ("rules = nearest\n", 1, "rules: expected one of waferscan, boundary, got ' nearest'"),
    ("thickness_correction = 0\n", 1, "thickness_correction: must be greater than 0, got ' 0'"),
])
def test_parameters_txt_refuses_a_recipe_that_is_no_window(text, line, message):
    with pytest.raises(InputError) as caught:
        apply_parameters(PAPER, parse_parameters(text, "recipe.txt"))
    assert (caught.value.source, caught.value.line, caught.value.message) == \
        ("recipe.txt", line, message)


@pytest.mark.parametrize("toml, key, message", [
    ('thickness_min = 0.9\nthickness_max = 0.8\n', "thickness_min",
     "[mapping] thickness_min: thickness_min 0.9 must be less than thickness_max 0.8"),
    ('double_threshold = 1.0\n', "double_threshold",
     "[mapping] double_threshold: double_threshold 1 must be greater than thickness_max 1.05"),
    ('rules = "nearest"\n', "rules",
     "[mapping] rules: expected one of waferscan, boundary, got 'nearest'"),
    ('position_above = -1.0\n', "position_above",
     "[mapping] position_above: must not be negative, got -1.0"),
])
def test_a_scenario_refuses_the_same_with_its_line(toml, key, message):
    text = with_mapping(toml)
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "s.toml", folder=PAPER_PATH.parent)
    expected_line = next(i for i, line in enumerate(text.splitlines(), 1)
                         if line.startswith(key + " ="))
    assert (caught.value.line, caught.value.message) == (expected_line, message)


def test_the_command_line_scans_with_a_recipe_and_refuses_a_bad_one(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("rules = boundary\nposition_above = 0.7\n")
    run = waferscan("scan", "--engine", "analytic", "--json", "--params", params, PAPER_PATH)
    assert run.returncode == 0, run.stderr
    params_used = json.loads(run.stdout)["params"]
    assert (params_used["rules"], params_used["position_above"]) == ("boundary", 0.7)
    params.write_text("thickness_min = 0.9\nthickness_max = 0.8\n")
    run = waferscan("scan", "--engine", "analytic", "--params", params, PAPER_PATH)
    assert run.returncode == 2
    assert run.stderr == (f"waferscan: error: {params}:1: thickness_min: thickness_min 0.9 must "
                          "be less than thickness_max 0.8\n")
