"""Sensor defaults from outside a scenario (the GUI's preferences, SPEC §10): they fill what a
scenario's [sensor] and [scan] tables leave unset, group by group, and nothing else."""

import math

import scenarios
from scenarios import PAPER_TEXT as TEXT

from waferscan.core.files.scenario import parse_scenario
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.settings import defaults_not_given, values_with_defaults
from waferscan.core.sensor.spot import Amplifier, BeamSpot

PREFERRED = {"spot_diameter": 1.0, "threshold_on": 0.6, "threshold_off": 0.4,
             "latch": "encoder", "acceleration": 2000.0, "sensor_response": 0.00025}


def with_lines(table, *lines):
    """The paper's scenario with ``lines`` added at the top of its [table]."""
    return scenarios.with_lines(TEXT, table, *lines)


def test_no_defaults_leave_the_layout_as_the_scenario_reads():
    assert parse_scenario(TEXT, default_sensor={}) == parse_scenario(TEXT)
    assert parse_scenario(TEXT, default_sensor=None) == parse_scenario(TEXT)


def test_defaults_fill_a_scenario_that_sets_none_of_them():
    plain = parse_scenario(TEXT)
    layout = parse_scenario(TEXT, default_sensor=PREFERRED)
    assert layout.spot == BeamSpot(diameter=1.0)
    assert layout.amplifier == Amplifier(0.6, 0.4)
    assert (layout.scan.latch, layout.scan.acceleration) == ("encoder", 2000.0)
    assert layout.scan.sensor_response == 0.00025
    # Everything else is the scenario's.
    assert layout.wafers == plain.wafers and layout.beam == plain.beam
    assert (layout.scan.start_z, layout.scan.z_step) == (plain.scan.start_z, plain.scan.z_step)


def test_what_the_scenario_sets_wins_by_group():
    text = with_lines("sensor", "spot_width = 2.0", "spot_height = 0.5", "threshold_on = 0.7")
    text = text.replace("[scan]\n", "[scan]\nsensor_response = 0.0\nlatch = \"step\"\n", 1)
    layout = parse_scenario(text, default_sensor=PREFERRED)
    # The scenario's slit, not the preferred round spot mixed in; its ON level with OFF
    # following it (not the preferred 0.4); its latch and its explicit zero response.
    assert layout.spot == BeamSpot(width=2.0, height=0.5)
    assert layout.amplifier == Amplifier(0.7)
    assert layout.scan.latch == "step" and layout.scan.sensor_response == 0.0
    assert layout.scan.acceleration == 2000.0  # the one group the scenario leaves unset


def test_a_preferred_spot_changes_the_scan_as_the_same_scenario_line_would():
    # At threshold 0.2 a 1 mm spot's runs start steps below the line's (at 0.5 they would
    # round to the same steps).
    preferred = scan_layout(parse_scenario(TEXT, default_sensor={"spot_diameter": 1.0,
                                                                 "threshold_on": 0.2}))
    written = scan_layout(parse_scenario(with_lines("sensor", "spot_diameter = 1.0",
                                                    "threshold_on = 0.2")))
    ideal = scan_layout(parse_scenario(TEXT))
    assert preferred.runs == written.runs and preferred.runs != ideal.runs


def test_groups_and_values_for_a_new_settings_object():
    assert defaults_not_given(PREFERRED, {"spot_diameter", "latch"}) == {
        "threshold_on": 0.6, "threshold_off": 0.4, "acceleration": 2000.0,
        "sensor_response": 0.00025}
    values = values_with_defaults({})
    assert values == {"spot_diameter": 0.0, "spot_width": 0.0, "spot_height": 0.0,
                      "threshold_on": 0.5, "threshold_off": 0.5, "latch": "step",
                      "acceleration": math.inf, "sample_period": 0.0}
    assert values_with_defaults({"threshold_on": 0.7})["threshold_off"] == 0.7
    assert values_with_defaults(PREFERRED)["threshold_off"] == 0.4
