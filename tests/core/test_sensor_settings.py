"""SPEC §10's settings through scenarios, parameters.txt, JSON and results.txt."""

import re

import pytest
from scenarios import PAPER as PAPER_PATH
from scenarios import PAPER_TEXT

from waferscan.core.errors import InputError
from waferscan.core.files.mcs import (
    apply_parameters,
    format_parameters,
    format_results,
    parse_parameters,
)
from waferscan.core.files.report import result_dict
from waferscan.core.files.scenario import parse_scenario, read_scenario
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.spot import Amplifier, BeamSpot



def with_lines(table, *lines):
    """The paper's scenario with lines added at the top of [table]; the first added line's
    number."""
    source = PAPER_TEXT.splitlines()
    at = source.index(f"[{table}]") + 1
    return "\n".join(source[:at] + list(lines) + source[at:]) + "\n", at + 1


def test_scenario_keys_reach_the_layout():
    text, _ = with_lines("sensor", "spot_diameter = 1.0", "threshold_on = 0.6",
                         "threshold_off = 0.4")
    source = text.splitlines()
    at = source.index("[scan]") + 1
    text = "\n".join(source[:at] + ['latch = "sampled"', "acceleration = 2000",
                                    "sample_period = 0.001"] + source[at:]) + "\n"
    layout = parse_scenario(text, "s.toml")
    assert layout.spot == BeamSpot(diameter=1.0)
    assert layout.amplifier == Amplifier(0.6, 0.4)
    assert (layout.scan.latch, layout.scan.acceleration, layout.scan.sample_period) == \
        ("sampled", 2000.0, 0.001)


@pytest.mark.parametrize("lines,key,words", [
    (["spot_diameter = -1"], "spot_diameter", "must not be negative"),
    (["threshold_on = 1.5"], "threshold_on", "fraction"),
    (["threshold_on = 0.4", "threshold_off = 0.6"], "threshold_off", "must not exceed"),
    (["spot_diameter = 1", "spot_width = 2"], "spot_width", "not both"),
    (["spot_width = 2"], "spot_width", "both spot_width and spot_height"),
])
def test_bad_sensor_values_name_the_file_and_line(lines, key, words):
    text, first = with_lines("sensor", *lines)
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "s.toml")
    line = first + next(i for i, l in enumerate(lines) if l.startswith(key))
    assert str(caught.value).startswith(f"s.toml:{line}: [sensor] {key}: ")
    assert words in str(caught.value)


@pytest.mark.parametrize("lines,key,words", [
    (['latch = "strobe"'], "latch", "expected one of step, encoder, sampled"),
    (['latch = "sampled"'], "latch", "needs sample_period"),
    (["acceleration = 0"], "acceleration", "greater than 0"),
])
def test_bad_latch_values_name_the_file_and_line(lines, key, words):
    text, first = with_lines("scan", *lines)
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "s.toml")
    assert str(caught.value).startswith(f"s.toml:{first}: [scan] {key}: ")
    assert words in str(caught.value)


def test_parameters_txt_sets_the_sensor_and_writes_it_back():
    paper = read_scenario(PAPER_PATH)
    p = parse_parameters("spot_width = 2\nspot_height = 0.5\nthreshold_on = 0.3\n"
                         "latch = encoder\nacceleration = 1500\n")
    layout = apply_parameters(paper, p)
    assert layout.spot == BeamSpot(width=2.0, height=0.5)
    assert layout.amplifier.threshold_on == layout.amplifier.off_level == 0.3
    assert (layout.scan.latch, layout.scan.acceleration) == ("encoder", 1500.0)
    text = format_parameters(layout)
    for line in ("spot_width = 2.0", "spot_height = 0.5", "threshold_on = 0.3",
                 "latch = encoder", "acceleration = 1500.0"):
        assert line in text.splitlines()
    assert "threshold_off" not in text  # it follows threshold_on unless set
    again = apply_parameters(paper, parse_parameters(text))
    assert (again.spot, again.amplifier.threshold_on, again.scan) == \
        (layout.spot, 0.3, layout.scan)
    # The ideal sensor writes none of the new keys: the paper's file is as it was.
    assert "spot" not in format_parameters(paper) and "latch" not in format_parameters(paper)


def test_a_bad_parameter_names_its_line():
    paper = read_scenario(PAPER_PATH)
    with pytest.raises(InputError) as caught:
        apply_parameters(paper, parse_parameters("threshold_on = 0.3\nthreshold_off = 0.5\n",
                                                 "parameters.txt"))
    assert str(caught.value).startswith("parameters.txt:2: threshold_off: ")
    with pytest.raises(InputError) as caught:
        parse_parameters("# x\nlatch = fast\n", "parameters.txt")
    assert str(caught.value).startswith("parameters.txt:2: latch: ")


def test_json_edges_and_slot_readings():
    paper = read_scenario(PAPER_PATH)
    data = result_dict(scan_layout(paper))
    # The ideal sensor too lists its edges: IN and OUT of each run, upwards.
    assert [e["z"] for e in data["edges"]] == [z for r in data["runs"] for z in (r["in"], r["out"])]
    assert [e["edge"] for e in data["edges"]] == ["on", "off"] * len(data["runs"])
    slot1 = data["slots"][0]
    assert (slot1["thickness"], slot1["bottom"]) == (data["runs"][0]["diff"],
                                                   data["runs"][0]["in"])
    assert data["slots"][2]["thickness"] is None and data["slots"][2]["bottom"] is None
    # A cross-slotted wafer's two slots read its one run.
    assert data["slots"][4]["thickness"] == data["slots"][5]["thickness"] > 5.0


def test_results_txt_has_the_readings_only_with_a_real_sensor():
    paper = read_scenario(PAPER_PATH)
    plain = format_results(1, "SCF", scan_layout(paper), timestamp="T")
    assert "slot\tslot_z\twafer\tin\tout\tdiff\tstate\n" in plain
    spotted = scan_layout(apply_parameters(paper, parse_parameters("spot_diameter = 1.0\n")))
    text = format_results(1, "SCF", spotted, timestamp="T")
    assert "spot_diameter = 1.0" in text.splitlines()
    table = text.split("\n\n", 1)[1].splitlines()
    assert table[0] == "slot\tslot_z\twafer\tin\tout\tdiff\tstate\tthickness\tbottom"
    first = table[1].split("\t")
    assert first[7] == first[5] and first[8] == first[3]  # ON-to-OFF length, lower edge
    empty = table[3].split("\t")
    assert empty[6] == "empty" and empty[7:] == ["", ""]


def test_a_missed_wafer_is_said_in_the_warnings():
    paper = read_scenario(PAPER_PATH)
    layout = apply_parameters(paper, parse_parameters("spot_diameter = 4\nthreshold_on = 0.4\n"))
    result = scan_layout(layout)
    assert result.code == "0" * 4 + "22" + "0" * 4 + "22" + "0" * 13
    missed = [w for w in result.warnings if "missed" in w]
    assert len(missed) == 8
    assert re.search(r"LP1_W01 near slot 1 blocked at most \d+\.\d% of the beam spot", missed[0])


def test_results_txt_echoes_the_z_step_asked_and_says_the_one_used_under_latching():
    """Issue 24, item 6: under encoder or sampled latching the edges are continuous (SPEC §10:
    no z_step grid), and results.txt said z_step = 0.0 where parameters.txt said 0.05. The
    header echoes what was asked (as parameters.txt has it) and, on a line of its own right
    after it, what the scan used; JSON's params the same. A stepped scan lists z_step once."""
    paper = read_scenario(PAPER_PATH)
    for latch in ("encoder", "sampled"):
        asked = apply_parameters(paper, parse_parameters(f"latch = {latch}\nscan_speed = 100\n"
                                                         "sample_period = 0.001\n"))
        assert format_parameters(asked).splitlines().count("z_step = 0.05") == 1
        result = scan_layout(asked)
        head = format_results(1, "SCF", result, timestamp="T").split("\n\n")[0].splitlines()
        at = head.index("z_step = 0.05")
        assert head[at + 1] == "z_step_used = 0.0"
        assert "z_step = 0.0" not in head
        params = result_dict(result)["params"]
        assert (params["z_step"], params["z_step_used"]) == (0.05, 0.0)
        assert list(params).index("z_step_used") == list(params).index("z_step") + 1
    stepped = format_results(1, "SCF", scan_layout(paper), timestamp="T")
    assert "z_step = 0.05" in stepped.splitlines() and "z_step_used" not in stepped
    exact = scan_layout(paper.with_scan(z_step=0.0))
    assert "z_step_used" not in format_results(1, "SCF", exact, timestamp="T")
    assert "z_step_used" not in result_dict(exact)["params"]
