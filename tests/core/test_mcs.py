"""The three MCS files (SPEC §5): parameters.txt read and applied, commands.txt parsed,
results.txt written byte for byte and atomically."""

import json
import os
import stat

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scenarios import PAPER as PAPER_PATH
from scenarios import PAPER_CODE, PAPER_TEXT, TWO_CARRIERS_TEXT

from waferscan.core.errors import InputError
from waferscan.core.files import mcs
from waferscan.core.files.mcs import (
    apply_parameters,
    format_parameters,
    format_results,
    parse_commands,
    parse_parameters,
    used_parameters,
)
from waferscan.core.files.text_files import atomic_write_text
from waferscan.core.files.scenario import parse_scenario, read_scenario
from waferscan.core.scan.layout_scan import scan_layout

PAPER = read_scenario(PAPER_PATH)

# A layout with two carriers, to see that parameters.txt's carrier = NAME picks one.
TWO_CARRIERS = TWO_CARRIERS_TEXT


def params(text, source="parameters.txt"):
    return apply_parameters(PAPER, parse_parameters(text, source))


# --- parameters.txt: what is read ----------------------------------------------------------

ALL_KEYS_TEXT = (
    "\ufeff# scan values from the MCS\r\n"
    "\r\n"
    "carrier = LP1\r\n"
    "start_z = 281.5  # mm\r\n"
    "final_z=540\r\n"
    "   z_step   =   0.01   \r\n"
    "mode = SLOW\r\n"
    "direction = updown#no space before the comment\r\n"
    "scan_speed = 250\r\n"
    "sensor_response = 0.002\r\n"
    "# a comment between keys\r\n"
    "slot_count = 13\r\n"
    "slot_pitch = 20\r\n"
    "first_slot_z = 300\r\n"
    "wafer_thickness = 0.775\r\n"
    "wafer_diameter = 200\r\n"
    "thickness_tolerance = 0.2\r\n"
    "position_tolerance = 0.3\r\n"
    "\t\r\n"
    "protrusion_limit = 2\r\n")

ALL_KEYS_VALUES = {
    "carrier": "LP1", "start_z": 281.5, "final_z": 540.0, "z_step": 0.01, "mode": "slow",
    "direction": "updown", "scan_speed": 250.0, "sensor_response": 0.002, "slot_count": 13,
    "slot_pitch": 20.0, "first_slot_z": 300.0, "wafer_thickness": 0.775,
    "wafer_diameter": 200.0, "thickness_tolerance": 0.2, "position_tolerance": 0.3,
    "protrusion_limit": 2.0,
}


def test_every_key_is_read_with_bom_crlf_comments_and_blank_lines():
    # SPEC §10's sensor keys are read in tests/core/test_sensor_settings.py, SPEC §13's slow-scan
    # keys in tests/core/test_slow_scan.py.
    from waferscan.core.recipe import RECIPE_KEYS  # SPEC §11: tests/core/test_recipe_keys.py
    from waferscan.core.scan.slow_scan import SETTING_KEYS as SLOW_KEYS
    from waferscan.core.sensor.settings import SETTING_KEYS
    # SPEC §15's clearance_min: tests/robot/test_clearance.py.
    assert set(ALL_KEYS_VALUES) | set(SETTING_KEYS) | set(SLOW_KEYS) | set(RECIPE_KEYS) | \
        {"clearance_min"} == set(mcs.PARAMETER_KEYS)
    p = parse_parameters(ALL_KEYS_TEXT, "parameters.txt")
    assert p.values == ALL_KEYS_VALUES
    assert type(p.values["slot_count"]) is int
    # The line each value came from, counted as an editor counts them (BOM and CR invisible).
    assert p.lines["carrier"] == 3 and p.lines["z_step"] == 6
    assert p.lines["slot_count"] == 12 and p.lines["protrusion_limit"] == 20


def test_every_key_is_applied_to_the_layout():
    layout = params(ALL_KEYS_TEXT)
    scan, carrier, mapping = layout.scan, layout.scanned_carrier, layout.mapping
    assert (scan.start_z, scan.final_z, scan.z_step) == (281.5, 540.0, 0.01)
    assert (scan.mode, scan.direction, scan.scan_speed, scan.sensor_response) == \
        ("slow", "updown", 250.0, 0.002)
    assert (carrier.slot_count, carrier.pitch, carrier.first_slot_z) == (13, 20.0, 300.0)
    assert (carrier.wafer_thickness, carrier.wafer_diameter) == (0.775, 200.0)
    assert (mapping.thickness_tolerance, mapping.position_tolerance,
            mapping.protrusion_limit) == (0.2, 0.3, 2.0)
    assert used_parameters(layout) == ALL_KEYS_VALUES
    assert layout.wafers == PAPER.wafers  # the MCS's nominal values do not move the wafers
    assert layout.beam == PAPER.beam


@pytest.mark.parametrize("key", sorted(ALL_KEYS_VALUES))  # the §10 keys: test_sensor_settings
def test_a_missing_key_keeps_the_layouts_value(key):
    others = {k: v for k, v in ALL_KEYS_VALUES.items() if k != key}
    text = "".join(f"{k} = {v}\n" for k, v in others.items())
    layout = params(text)
    used = used_parameters(layout)
    if key == "thickness_tolerance":
        # The paper leaves it at its default, half the (here changed) nominal thickness.
        assert layout.mapping.thickness_tolerance == PAPER.mapping.thickness_tolerance
        assert used[key] == 0.5 * 0.775
    else:
        assert used[key] == used_parameters(PAPER)[key]
    assert {k: used[k] for k in others} == others


def test_an_empty_file_changes_nothing():
    for text in ("", "\ufeff", "# nothing\n\n   \n", "\r\n\r\n"):
        layout = params(text)
        assert layout.scan == PAPER.scan and layout.scanned_carrier == PAPER.scanned_carrier
        assert layout.mapping == PAPER.mapping


def test_the_carrier_key_picks_which_carrier_the_other_keys_change():
    layout = parse_scenario(TWO_CARRIERS, "two.toml")
    assert layout.carrier == "LP1"
    moved = apply_parameters(layout, parse_parameters("carrier = LP2\nslot_count = 12\n"))
    assert moved.carrier == "LP2"
    assert moved.scanned_carrier.slot_count == 12 and moved.scanned_carrier.pitch == 20.0
    lp1 = next(c for c in moved.carriers if c.name == "LP1")
    assert lp1 == PAPER.scanned_carrier  # the other carrier is left alone


def test_format_parameters_reads_back_to_the_same_values():
    text = format_parameters(PAPER)
    assert text.endswith("\n") and "\r" not in text
    p = parse_parameters(text)
    # SPEC §10's keys are written only where they differ from the ideal sensor.
    assert set(p.values) == set(ALL_KEYS_VALUES)
    again = apply_parameters(PAPER, p)
    assert again.scan == PAPER.scan and again.scanned_carrier == PAPER.scanned_carrier
    assert used_parameters(again) == used_parameters(PAPER)


def _finite(lo, hi):
    return st.floats(min_value=lo, max_value=hi, allow_nan=False, allow_infinity=False,
                     allow_subnormal=False)


@settings(max_examples=150, deadline=None)
@given(start=_finite(-1000.0, 1000.0), span=_finite(0.0, 1000.0),
       step=st.one_of(st.just(0.0), _finite(0.001, 50.0)),
       mode=st.sampled_from(["fast", "slow"]), direction=st.sampled_from(["up", "down", "updown"]),
       speed=_finite(1e-3, 1e4), response=_finite(0.0, 1.0), slots=st.integers(1, 10_000),
       pitch=_finite(1.0, 50.0), first=_finite(-1e4, 1e4), thickness=_finite(0.01, 0.99),
       diameter=_finite(1.0, 450.0), tolerances=st.tuples(*[_finite(0.0, 10.0)] * 3))
def test_format_parameters_round_trips_any_valid_values(start, span, step, mode, direction,
                                                        speed, response, slots, pitch, first,
                                                        thickness, diameter, tolerances):
    assume(step == 0.0 or span / step < 1e6)
    text = (f"start_z = {start!r}\nfinal_z = {start + span!r}\nz_step = {step!r}\n"
            f"mode = {mode}\ndirection = {direction}\nscan_speed = {speed!r}\n"
            f"sensor_response = {response!r}\nslot_count = {slots}\nslot_pitch = {pitch!r}\n"
            f"first_slot_z = {first!r}\nwafer_thickness = {thickness!r}\n"
            f"wafer_diameter = {diameter!r}\nthickness_tolerance = {tolerances[0]!r}\n"
            f"position_tolerance = {tolerances[1]!r}\nprotrusion_limit = {tolerances[2]!r}\n")
    layout = params(text)
    again = apply_parameters(PAPER, parse_parameters(format_parameters(layout)))
    assert used_parameters(again) == used_parameters(layout)
    assert again.scan == layout.scan and again.scanned_carrier == layout.scanned_carrier


# --- parameters.txt: mistakes --------------------------------------------------------------

@pytest.mark.parametrize("text, line, key, fragment", [
    ("start_z = 1\nbogus = 2\n", 2, "bogus", "unknown key 'bogus'"),
    ("\ufeff# c\r\n\r\nspead = 100\r\n", 3, "spead", "unknown key 'spead'"),
    ("start_z = 1\n# again:\nSTART_Z = 2\n", 3, "start_z", "start_z: given twice (first on line 1)"),
    ("# c\nstart_z 280\n", 2, "start_z", "expected 'key = value'"),
    # issue 25: a line that is not 'key = value' is not quoted (it may not be the MCS's)
    ("mode = fast\n= 3\n", 2, "(a line of 3 characters)", "expected 'key = value'"),
    ("z_step =\n", 1, "z_step", "z_step: no value"),
    ("carrier =    # which one?\n", 1, "carrier", "carrier: no value"),
    ("\n\nfinal_z = 5O0\n", 3, "final_z", "final_z: expected a number, got '5O0'"),
    ("scan_speed = 100 mm/s\n", 1, "scan_speed", "scan_speed: expected a number"),
    ("z_step = nan\n", 1, "z_step", "z_step: expected a finite number"),
    ("start_z = inf\n", 1, "start_z", "start_z: expected a finite number"),
    ("final_z = -Infinity\n", 1, "final_z", "final_z: expected a finite number"),
    ("first_slot_z = 1e999\n", 1, "first_slot_z", "first_slot_z: expected a finite number"),
    ("z_step = -0.05\n", 1, "z_step", "z_step: must not be negative"),
    ("sensor_response = -1\n", 1, "sensor_response", "must not be negative"),
    ("scan_speed = 0\n", 1, "scan_speed", "scan_speed: must be greater than 0"),
    ("slot_pitch = -10\n", 1, "slot_pitch", "slot_pitch: must be greater than 0"),
    ("wafer_diameter = 0\n", 1, "wafer_diameter", "must be greater than 0"),
    ("position_tolerance = -0.5\n", 1, "position_tolerance", "must not be negative"),
    ("slot_count = 25.5\n", 1, "slot_count", "slot_count: expected a whole number"),
    ("slot_count = 0\n", 1, "slot_count", "slot_count: expected a whole number"),
    ("slot_count = twenty\n", 1, "slot_count", "slot_count: expected a number"),
    ("mode = medium\n", 1, "mode", "mode: expected one of fast, slow"),
    ("direction = sideways\n", 1, "direction", "direction: expected one of up, down, updown"),
])
def test_bad_lines_name_file_line_and_key(text, line, key, fragment):
    with pytest.raises(InputError) as caught:
        parse_parameters(text, "/mcs/parameters.txt")
    error = caught.value
    assert error.line == line
    assert error.source == "/mcs/parameters.txt"
    assert str(error).startswith(f"/mcs/parameters.txt:{line}: ")
    assert key in str(error) and fragment in str(error)


@pytest.mark.parametrize("text, line, key, fragment", [
    ("start_z = 100\nfinal_z = 50\n", 2, "final_z", "final_z (50) is below start_z (100)"),
    ("# only the start\nstart_z = 600\n", 2, "start_z", "final_z (550) is below start_z (600)"),
    ("final_z = 100\n", 1, "final_z", "final_z (100) is below start_z (280)"),
    ("z_step = 0.0000001\n", 1, "z_step", "z_step 1e-07 over 270 mm makes"),
    ("\nwafer_thickness = 12\n", 2, "wafer_thickness", "wafer thickness 12 must be less than the pitch 10"),
    ("wafer_thickness = 10\n", 1, "wafer_thickness", "must be less than the pitch"),
    ("mode = slow\nslot_pitch = 0.5\n", 2, "slot_pitch", "wafer thickness 0.7 must be less than the pitch 0.5"),
    ("carrier = LP9\n", 1, "carrier", "carrier: no carrier named 'LP9' in the layout (carriers: LP1)"),
    # Both keys given: the one changed from the layout's value is blamed.
    ("wafer_thickness = 0.7\nslot_pitch = 0.5\n", 2, "slot_pitch", "less than the pitch 0.5"),
    ("slot_pitch = 10\nwafer_thickness = 11\n", 2, "wafer_thickness", "thickness 11 must"),
    ("slot_pitch = 5\nwafer_thickness = 6\n", 2, "wafer_thickness", "thickness 6 must"),
])
def test_impossible_values_name_their_line_and_key(text, line, key, fragment):
    with pytest.raises(InputError) as caught:
        params(text, "/mcs/parameters.txt")
    assert caught.value.line == line
    assert str(caught.value).startswith(f"/mcs/parameters.txt:{line}: ")
    assert key in str(caught.value) and fragment in str(caught.value)


def test_exact_mode_is_a_valid_parameter():
    assert params("z_step = 0\n").scan.z_step == 0.0


def test_unreadable_parameters_file(tmp_path):
    bad = tmp_path / "parameters.txt"
    bad.write_bytes(b"start_z = 1\r\nmode = \xff\r\n")
    with pytest.raises(InputError) as caught:
        mcs.read_parameters(bad)
    assert caught.value.line == 2 and str(caught.value) == f"{bad}:2: not UTF-8 text"
    with pytest.raises(InputError, match=r"missing.txt: cannot read"):
        mcs.read_parameters(tmp_path / "missing.txt")
    good = tmp_path / "ok.txt"
    good.write_bytes("\ufeffz_step = 0.1\r\n".encode())
    assert mcs.read_parameters(good).values == {"z_step": 0.1}


def test_a_subnormal_step_is_refused_as_bad_input():
    with pytest.raises(InputError) as caught:
        params("z_step = 1e-320\n")
    assert caught.value.line == 1 and "z_step" in str(caught.value)


def test_a_huge_final_z_is_refused_as_bad_input():
    with pytest.raises(InputError) as caught:
        params("final_z = 1e308\n")
    assert caught.value.line == 1 and "final_z" in str(caught.value)


def test_a_too_fine_step_is_blamed_on_z_step():
    lines = format_parameters(PAPER).splitlines()
    index = next(i for i, line in enumerate(lines) if line.startswith("z_step"))
    lines[index] = "z_step = 1e-07"
    with pytest.raises(InputError) as caught:
        params("\n".join(lines) + "\n")
    assert caught.value.line == index + 1
    assert caught.value.message.startswith("z_step: ")


def test_only_lf_ends_a_line_when_counting():
    with pytest.raises(InputError) as caught:
        parse_parameters("start_z = 1\x0c\nbogus = 2\n")
    assert caught.value.line == 2


@pytest.mark.parametrize("bad", ["LP#1", "LP\u20281", "LP\t1"])
def test_a_carrier_name_that_parameters_txt_cannot_hold_is_refused_at_its_line(bad):
    # parameters.txt names the carrier and '#' starts a comment there: such a name would not
    # survive a round trip, so the scenario refuses it, naming the line.
    text = PAPER_TEXT.replace('"LP1"', json.dumps(bad), 1)
    line = PAPER_TEXT[:PAPER_TEXT.index('"LP1"')].count("\n") + 1
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "hash.toml")
    assert caught.value.line == line and "carrier" in str(caught.value)
    assert "cannot hold '#'" in str(caught.value)


def test_format_parameters_round_trips_the_carrier_name():
    layout = parse_scenario(PAPER_TEXT.replace('"LP1"', '"Load port 1 (A)"'), "name.toml")
    again = apply_parameters(layout, parse_parameters(format_parameters(layout)))
    assert again.carrier == "Load port 1 (A)"


VALID_LINES = format_parameters(PAPER).splitlines()


@settings(max_examples=200, deadline=None)
@given(st.lists(st.one_of(st.text(max_size=40), st.sampled_from(VALID_LINES)), max_size=12),
       st.sampled_from(["\n", "\r\n"]))
def test_any_text_is_accepted_or_refused_cleanly(lines, newline):
    text = newline.join(lines)
    try:
        apply_parameters(PAPER, parse_parameters(text, "p.txt"))
    except InputError as exc:
        assert str(exc).startswith("p.txt")
        assert exc.line is None or 1 <= exc.line <= len(text.splitlines())


NUMBERS = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False, allow_subnormal=False,
              min_value=-1e9, max_value=1e9).map(repr),
    st.integers(-10**6, 10**6).map(str),
    st.sampled_from(["nan", "inf", "-inf", "1e999", "", "0", "-0", "fast", "up", "LP1"]))


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_mutated_valid_files_are_accepted_or_refused_with_the_mutated_line(data):
    lines = list(VALID_LINES)
    index = data.draw(st.integers(1, len(lines) - 1))  # line 0 is the comment
    key = lines[index].split("=")[0].strip()
    how = data.draw(st.sampled_from(["value", "text", "delete", "duplicate"]))
    if how == "value":
        lines[index] = f"{key} = {data.draw(NUMBERS)}"
    elif how == "text":
        lines[index] = data.draw(st.text(alphabet=st.characters(blacklist_characters="\r\n#"),
                                         max_size=20))
    elif how == "delete":
        del lines[index]
    else:
        lines.append(lines[index])
    try:
        apply_parameters(PAPER, parse_parameters("\n".join(lines) + "\n", "p.txt"))
    except InputError as exc:
        assert str(exc).startswith("p.txt")
        if how == "duplicate":
            assert exc.line == len(lines) and "given twice" in exc.message
        elif how == "value":
            # The scan range's checks blame final_z when the file has every key: see
            # test_a_too_fine_step_is_blamed_on_z_step.
            assert exc.line == index + 1 or (
                "below start_z" in exc.message or "positions" in exc.message)
        elif how == "delete":
            pytest.fail(f"a file with a key left out is complete: {exc}")
    else:
        assert how != "duplicate"


# --- commands.txt --------------------------------------------------------------------------

def _rows(commands):
    return [(c.seq, c.name, c.args, c.line, c.problem) for c in commands]


def test_commands_with_args_crlf_bom_and_comments():
    text = "\ufeff# from the MCS\r\n1 SCF\r\n2 scs 5 fast   # slot 5\r\n\r\n  3\tSTOP#now\r\n"
    assert _rows(parse_commands(text)) == [
        (1, "SCF", (), 2, None), (2, "SCS", ("5", "fast"), 3, None), (3, "STOP", (), 5, None)]


def test_a_half_written_last_line_waits_for_its_newline():
    full = "1 SCF\n2 SCS 3\n"
    seen = [[c.seq for c in parse_commands(full[:n])] for n in range(len(full) + 1)]
    assert seen[:6] == [[]] * 6
    assert all(s == [1] for s in seen[6:len(full)])
    assert seen[-1] == [1, 2]
    crlf = "1 SCF\r\n2 SCS\r"
    assert [c.seq for c in parse_commands(crlf)] == [1]
    assert [c.seq for c in parse_commands(crlf + "\n")] == [1, 2]
    assert parse_commands("1 SCF") == [] and parse_commands("") == []


def test_command_problems():
    commands = parse_commands("5 SCF\n4 SCF\nx SCF\n6 JUMP\n7\n8 SCF\n8 SCF\n1.5 SCF\n9 stop\n")
    assert _rows(commands) == [
        (5, "SCF", (), 1, None),
        (4, "SCF", (), 2, "seq 4 is not above the one before (5)"),
        (None, "SCF", (), 3, "seq must be a whole number, got 'x'"),
        (6, "JUMP", (), 4, "unknown command 'JUMP' (known: SCF, SCS, STOP, CAL, LOAD)"),
        (7, "", (), 5, "no command after the seq"),
        (8, "SCF", (), 6, None),
        (8, "SCF", (), 7, "seq 8 is not above the one before (8)"),
        (None, "SCF", (), 8, "seq must be a whole number, got '1.5'"),
        (9, "STOP", (), 9, None),
    ]


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=200))
def test_any_commands_text_parses(text):
    commands = parse_commands(text)
    complete = text[:text.rfind("\n") + 1]
    assert len(commands) <= complete.count("\n")
    assert [c.line for c in commands] == sorted(set(c.line for c in commands))
    good = [c.seq for c in commands if c.problem is None]
    assert good == sorted(set(good))
    for c in commands:
        assert c.seq is None or isinstance(c.seq, int)
        assert c.problem is not None or c.name in mcs.COMMAND_NAMES


COMMAND_LINES = st.lists(st.one_of(
    st.builds(lambda s, n, a: f"{s} {n} {a}".rstrip(), st.integers(-3, 40),
              st.sampled_from(["SCF", "SCS", "STOP", "scf", "JUMP", ""]),
              st.sampled_from(["", "5", "fast 3", "# note"])),
    st.sampled_from(["", "# comment", "   ", "x SCF"])), max_size=15)


@settings(max_examples=200, deadline=None)
@given(COMMAND_LINES, st.sampled_from(["\n", "\r\n"]), st.booleans(), st.data())
def test_a_growing_file_only_adds_commands(lines, newline, bom, data):
    """The MCS appends; whatever prefix the simulator reads, what it parsed before stays."""
    text = ("\ufeff" if bom else "") + "".join(line + newline for line in lines)
    cut = data.draw(st.integers(0, len(text)))
    before, after = parse_commands(text[:cut]), parse_commands(text)
    assert after[:len(before)] == before
    assert len(after) == sum(1 for line in lines if line.split("#")[0].strip())


# --- results.txt ---------------------------------------------------------------------------

# SPEC §4: the SEMI E87 SlotMap beside the code.
E87 = {"0": "1", "1": "3", "2": "5", "3": "4", "4": "2", "5": "2", "6": "2"}
STATE = {"0": "empty", "1": "present", "2": "cross-slotted"}
STAMP = "2026-01-02T03:04:05Z"


def expected_results(seq, command, engine):
    """results.txt for the paper's scan, written out here from SPEC §5's columns and the known
    figures: seats 293.94 + 10 (slot - 1); a 0.7 mm wafer on the 0.05 mm grid from 280 is
    first met at the next step above its seat (seat + 0.01) and last at seat + 0.66; the two
    cross-slotted wafers' runs are 336.60..341.95 and 396.60..401.95."""
    header = [
        ("seq", seq), ("command", command), ("status", "ok"), ("message", ""),
        ("code", PAPER_CODE), ("e87", "".join(E87[c] for c in PAPER_CODE)),
        ("timestamp", STAMP), ("engine", engine),
        ("carrier", "LP1"), ("start_z", "280.0"), ("final_z", "550.0"), ("z_step", "0.05"),
        ("mode", "fast"), ("direction", "up"), ("scan_speed", "100.0"),
        ("sensor_response", "0.0"), ("slot_count", "25"), ("slot_pitch", "10.0"),
        ("first_slot_z", "293.94"), ("wafer_thickness", "0.7"), ("wafer_diameter", "300.0"),
        ("thickness_tolerance", "0.35"), ("position_tolerance", "0.5"),
        ("protrusion_limit", "1.0")]
    out = [f"{k} = {v}" if v != "" else f"{k} =" for k, v in header]
    out += ["", "slot\tslot_z\twafer\tin\tout\tdiff\tstate"]
    seats = {slot: f"{293.94 + 10 * (slot - 1):.3f}" for slot in range(1, 26)}
    cross = {5: ("336.600", "341.950"), 11: ("396.600", "401.950")}
    number = 0
    for slot in range(1, 26):
        digit = PAPER_CODE[slot - 1]
        cells = [str(slot), seats[slot]]
        if slot in cross:
            number += 1
            cells += [f"LP1_W{number:02d}", *cross[slot], "5.350"]
        elif digit == "1":
            number += 1
            seat = 293.94 + 10 * (slot - 1)
            cells += [f"LP1_W{number:02d}", f"{seat + 0.01:.3f}", f"{seat + 0.66:.3f}", "0.650"]
        else:
            cells += ["-", "", "", ""]
        out.append("\t".join(cells + [STATE[digit]]))
    assert number == 10
    return "\n".join(out) + "\n"


PAPER_RESULT = scan_layout(PAPER)


def test_results_byte_for_byte():
    text = format_results(7, "SCF", PAPER_RESULT, timestamp=STAMP)
    assert text == expected_results("7", "SCF", "analytic")


def test_results_figures_spot_checks():
    """A few figures spelled out, in case the builder above and the code agree by accident."""
    lines = format_results(7, "SCF", PAPER_RESULT, timestamp=STAMP).split("\n")
    assert lines[0] == "seq = 7" and lines[-1] == ""
    assert "e87 = 3313553113551113131111131" in lines
    table = lines[lines.index("") + 1:-1]
    assert len(table) == 26
    assert table[1] == "1\t293.940\tLP1_W01\t293.950\t294.600\t0.650\tpresent"
    assert table[5] == "5\t333.940\tLP1_W04\t336.600\t341.950\t5.350\tcross-slotted"
    assert table[6] == "6\t343.940\t-\t\t\t\tcross-slotted"
    assert table[11] == "11\t393.940\tLP1_W07\t396.600\t401.950\t5.350\tcross-slotted"
    assert table[24] == "24\t523.940\tLP1_W10\t523.950\t524.600\t0.650\tpresent"
    assert table[25] == "25\t533.940\t-\t\t\t\tempty"


def test_results_without_seq_and_for_a_slow_scan():
    text = format_results(None, "SCS", PAPER_RESULT, timestamp=STAMP)
    assert text.startswith("seq =\ncommand = SCS\nstatus = ok\nmessage =\n")
    assert text.endswith("\n") and not text.endswith("\n\n")


def test_the_timestamp_defaults_to_utc_now():
    text = format_results(1, "SCF", PAPER_RESULT)
    stamp = next(line for line in text.splitlines() if line.startswith("timestamp = "))
    import re
    assert re.fullmatch(r"timestamp = \d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", stamp)


def test_error_results_have_one_line_message_and_no_table():
    error = InputError("parameters.txt", 3, "z_step: must\nnot be\tnegative\r\n")
    text = format_results(8, "SCS", error=error, timestamp=STAMP)
    assert text == ("seq = 8\ncommand = SCS\nstatus = error\n"
                    "message = parameters.txt:3: z_step: must not be negative\ncode =\ne87 =\n"
                    f"timestamp = {STAMP}\n")
    # A result given beside the error is not reported as if it were good.
    text = format_results(9, "SCF", PAPER_RESULT, error="stopped", timestamp=STAMP)
    assert "status = error" in text and PAPER_CODE not in text and "\t" not in text


# --- atomic writes -------------------------------------------------------------------------

def test_atomic_write_replaces_and_leaves_nothing_behind(tmp_path):
    target = tmp_path / "results.txt"
    target.write_text("old\n" * 100)
    atomic_write_text(target, "new\n")
    assert target.read_bytes() == b"new\n"
    atomic_write_text(target, "ü\n")
    assert target.read_bytes() == "ü\n".encode("utf-8")
    atomic_write_text(tmp_path / "fresh.txt", "a\nb\n")
    assert (tmp_path / "fresh.txt").read_bytes() == b"a\nb\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fresh.txt", "results.txt"]


@pytest.mark.parametrize("failing", ["replace", "fsync"])
def test_a_failed_write_keeps_the_old_file(tmp_path, monkeypatch, failing):
    target = tmp_path / "results.txt"
    target.write_text("old\n")
    calls = []

    def fail(*args, **kwargs):
        calls.append(args)
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, failing, fail)
    with pytest.raises(OSError, match="No space left"):
        atomic_write_text(target, "new\n" * 1000)
    monkeypatch.undo()
    assert calls
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.txt"]


def test_an_interrupted_write_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "results.txt"
    target.write_text("old\n")

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", interrupt)
    with pytest.raises(KeyboardInterrupt):
        atomic_write_text(target, "new\n")
    monkeypatch.undo()
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["results.txt"]


def test_atomic_write_keeps_the_files_permissions(tmp_path):
    target = tmp_path / "results.txt"
    target.write_text("old\n")
    target.chmod(0o644)
    atomic_write_text(target, "new\n")
    assert stat.S_IMODE(target.stat().st_mode) == 0o644
    target.chmod(0o640)
    atomic_write_text(target, "newer\n")
    assert stat.S_IMODE(target.stat().st_mode) == 0o640 and target.read_text() == "newer\n"


def test_atomic_write_gives_a_new_file_the_umasks_mode(tmp_path):
    old = os.umask(0o027)
    try:
        atomic_write_text(tmp_path / "results.txt", "x\n")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "results.txt").stat().st_mode) == 0o640
