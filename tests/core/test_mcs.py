"""The three MCS files: parameters.txt in and applied, commands.txt parsed, results.txt written
byte for byte and atomically."""

import os
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from waferscan.core import mcs
from waferscan.core.errors import InputError
from waferscan.core.mcs import (apply_parameters, atomic_write_text, format_parameters,
                                format_results, parse_commands, parse_parameters)
from waferscan.core.scan import scan_layout
from waferscan.core.scenario import read_scenario

PAPER = read_scenario(Path(__file__).resolve().parents[2] / "resources/examples/paper.toml")


# --- parameters.txt ------------------------------------------------------------------------

def test_every_key_with_bom_crlf_comments_and_blank_lines():
    text = ("\ufeff# scan values\r\n\r\ncarrier = LP1\r\nstart_z = 281.5  # mm\r\n"
            "final_z=540\r\nz_step = 0.01\r\nmode = SLOW\r\ndirection = updown\r\n"
            "scan_speed = 250\r\nsensor_response = 0.002\r\nslot_count = 13\r\n"
            "slot_pitch = 20\r\nfirst_slot_z = 300\r\nwafer_thickness = 0.775\r\n"
            "wafer_diameter = 300\r\nthickness_tolerance = 0.2\r\nposition_tolerance = 0.3\r\n"
            "protrusion_limit = 2\r\n")
    p = parse_parameters(text, "parameters.txt")
    assert set(p.values) == set(mcs.PARAMETER_KEYS)
    assert p.values["start_z"] == 281.5 and p.values["mode"] == "slow"
    assert p.values["slot_count"] == 13 and p.lines["carrier"] == 3
    layout = apply_parameters(PAPER, p)
    assert (layout.scan.start_z, layout.scan.final_z, layout.scan.z_step) == (281.5, 540.0, 0.01)
    assert (layout.scan.mode, layout.scan.direction) == ("slow", "updown")
    carrier = layout.scanned_carrier
    assert (carrier.slot_count, carrier.pitch, carrier.first_slot_z) == (13, 20.0, 300.0)
    assert layout.mapping.thickness_tolerance == 0.2
    assert layout.wafers == PAPER.wafers  # the MCS's values do not move the wafers


def test_a_missing_key_keeps_the_layouts_value():
    layout = apply_parameters(PAPER, parse_parameters("z_step = 0.1\n"))
    assert layout.scan.z_step == 0.1
    assert layout.scan.start_z == PAPER.scan.start_z
    assert layout.scanned_carrier == PAPER.scanned_carrier
    assert layout.mapping == PAPER.mapping


def test_format_parameters_reads_back_to_the_same_layout():
    text = format_parameters(PAPER)
    again = apply_parameters(PAPER, parse_parameters(text))
    assert again.scan == PAPER.scan and again.scanned_carrier == PAPER.scanned_carrier


@pytest.mark.parametrize("text, line, fragment", [
    ("start_z = 1\nbogus = 2\n", 2, "unknown key 'bogus'"),
    ("start_z = 1\nstart_z = 2\n", 2, "start_z: given twice (first on line 1)"),
    ("# c\nstart_z 280\n", 2, "expected 'key = value'"),
    ("z_step =\n", 1, "z_step: no value"),
    ("\n\nfinal_z = 5O0\n", 3, "final_z: expected a number, got '5O0'"),
    ("z_step = nan\n", 1, "z_step: expected a finite number"),
    ("start_z = inf\n", 1, "start_z: expected a finite number"),
    ("z_step = -0.05\n", 1, "z_step: must not be negative"),
    ("scan_speed = 0\n", 1, "scan_speed: must be greater than 0"),
    ("slot_count = 25.5\n", 1, "slot_count: expected a whole number"),
    ("mode = medium\n", 1, "mode: expected one of fast, slow"),
    ("direction = sideways\n", 1, "direction: expected one of up, down, updown"),
])
def test_bad_lines_name_file_line_and_key(text, line, fragment):
    with pytest.raises(InputError) as caught:
        parse_parameters(text, "/mcs/parameters.txt")
    assert caught.value.line == line
    assert str(caught.value).startswith(f"/mcs/parameters.txt:{line}: ")
    assert fragment in str(caught.value)


@pytest.mark.parametrize("text, line, fragment", [
    ("start_z = 100\nfinal_z = 50\n", 2, "final_z: final_z (50) is below start_z (100)"),
    ("z_step = 0.0000001\n", 1, "z_step: z_step 1e-07 over 270 mm makes"),
    ("\nwafer_thickness = 12\n", 2, "wafer_thickness: wafer thickness 12 must be less than the pitch"),
    ("carrier = LP9\n", 1, "carrier: no carrier named 'LP9' in the layout (carriers: LP1)"),
])
def test_impossible_values_name_their_line(text, line, fragment):
    with pytest.raises(InputError) as caught:
        apply_parameters(PAPER, parse_parameters(text, "parameters.txt"))
    assert caught.value.line == line
    assert fragment in str(caught.value)


def test_unreadable_parameters_file(tmp_path):
    bad = tmp_path / "parameters.txt"
    bad.write_bytes(b"start_z = 1\nmode = \xff\n")
    with pytest.raises(InputError, match=r"parameters.txt:2: not UTF-8 text"):
        mcs.read_parameters(bad)
    with pytest.raises(InputError, match="cannot read"):
        mcs.read_parameters(tmp_path / "missing.txt")


VALID = format_parameters(PAPER).splitlines()


@settings(max_examples=200, deadline=None)
@given(st.lists(st.one_of(st.text(max_size=40), st.sampled_from(VALID)), max_size=12))
def test_any_text_is_accepted_or_refused_cleanly(lines):
    try:
        apply_parameters(PAPER, parse_parameters("\n".join(lines), "p.txt"))
    except InputError as exc:
        assert str(exc).startswith("p.txt")


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(sorted(mcs.PARAMETER_KEYS)),
       st.one_of(st.text(max_size=12), st.floats(allow_nan=True, allow_infinity=True).map(repr),
                 st.integers(-10**6, 10**6).map(str)))
def test_any_value_for_any_key_is_accepted_or_refused_with_its_line(key, value):
    text = f"# parameters\n{key} = {value}\n"
    try:
        apply_parameters(PAPER, parse_parameters(text, "p.txt"))
    except InputError as exc:
        assert exc.line in (2, None) or "\n" in value or "#" in value or "=" in value


# --- commands.txt --------------------------------------------------------------------------

def test_commands_with_args_crlf_bom_and_comments():
    text = "\ufeff# from the MCS\r\n1 SCF\r\n2 scs 5 fast   # slot 5\r\n\r\n3 STOP\r\n"
    commands = parse_commands(text)
    assert [(c.seq, c.name, c.args, c.line, c.problem) for c in commands] == [
        (1, "SCF", (), 2, None), (2, "SCS", ("5", "fast"), 3, None), (3, "STOP", (), 5, None)]


def test_a_half_written_last_line_waits_for_its_newline():
    assert [c.seq for c in parse_commands("1 SCF\n2 SC")] == [1]
    assert [c.seq for c in parse_commands("1 SCF\n2 SCF")] == [1]
    assert [c.seq for c in parse_commands("1 SCF\n2 SCF\n")] == [1, 2]
    assert parse_commands("1 SCF") == []


def test_command_problems():
    commands = parse_commands("5 SCF\n4 SCF\nx SCF\n6 JUMP\n7\n8 SCF\n")
    problems = [(c.seq, c.problem) for c in commands]
    assert problems[0] == (5, None)
    assert problems[1] == (4, "seq 4 is not above the one before (5)")
    assert problems[2] == (None, "seq must be a whole number, got 'x'")
    assert problems[3] == (6, "unknown command 'JUMP' (known: SCF, SCS, STOP)")
    assert problems[4] == (7, "no command after the seq")
    assert problems[5] == (8, None)


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=200))
def test_any_commands_text_parses(text):
    for command in parse_commands(text):
        assert command.seq is None or isinstance(command.seq, int)


# --- results.txt ---------------------------------------------------------------------------

def expected_results():
    """results.txt for the paper's scan, written out here from SPEC §5 and Table 1's figures."""
    header = ["seq = 7", "command = SCF", "status = ok", "message =",
              "code = 1101221001220001010000010", "e87 = 3313553113551113131111131",
              "timestamp = 2026-01-02T03:04:05Z", "engine = analytic", "carrier = LP1",
              "start_z = 280.0", "final_z = 550.0", "z_step = 0.05", "mode = fast",
              "direction = up", "scan_speed = 100.0", "sensor_response = 0.0",
              "slot_count = 25", "slot_pitch = 10.0", "first_slot_z = 293.94",
              "wafer_thickness = 0.7", "wafer_diameter = 300.0", "thickness_tolerance = 0.35",
              "position_tolerance = 0.5", "protrusion_limit = 1.0"]
    wafers = {1: 1, 2: 2, 4: 3, 5: 4, 7: 5, 10: 6, 11: 7, 16: 8, 18: 9, 24: 10}
    rows = ["slot\tslot_z\twafer\tin\tout\tdiff\tstate"]
    for slot in range(1, 26):
        seat = 293.94 + (slot - 1) * 10.0
        if slot in (5, 11):
            low = 336.6 if slot == 5 else 396.6
            rows.append(f"{slot}\t{seat:.3f}\tLP1_W{wafers[slot]:02d}\t{low:.3f}\t"
                        f"{low + 5.35:.3f}\t5.350\tcross-slotted")
        elif slot in (6, 12):
            rows.append(f"{slot}\t{seat:.3f}\t-\t\t\t\tcross-slotted")
        elif slot in wafers:
            rows.append(f"{slot}\t{seat:.3f}\tLP1_W{wafers[slot]:02d}\t{seat + 0.01:.3f}\t"
                        f"{seat + 0.66:.3f}\t0.650\tpresent")
        else:
            rows.append(f"{slot}\t{seat:.3f}\t-\t\t\t\tempty")
    return "\n".join(header + [""] + rows) + "\n"


def test_results_byte_for_byte():
    result = scan_layout(PAPER)
    text = format_results(7, "SCF", result, timestamp="2026-01-02T03:04:05Z")
    assert text == expected_results()


def test_error_results_have_no_table():
    text = format_results(8, "SCS", error="parameters.txt:3: z_step: must\nnot be negative",
                          timestamp="2026-01-02T03:04:05Z")
    assert text == ("seq = 8\ncommand = SCS\nstatus = error\n"
                    "message = parameters.txt:3: z_step: must not be negative\ncode =\ne87 =\n"
                    "timestamp = 2026-01-02T03:04:05Z\n")


def test_atomic_write_replaces_and_leaves_nothing_behind(tmp_path):
    target = tmp_path / "results.txt"
    target.write_text("old\n")
    atomic_write_text(target, "new\n")
    assert target.read_text() == "new\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.txt"]


@pytest.mark.parametrize("failing", ["replace", "fsync"])
def test_a_failed_write_keeps_the_old_file(tmp_path, monkeypatch, failing):
    target = tmp_path / "results.txt"
    target.write_text("old\n")

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, failing, fail)
    with pytest.raises(OSError):
        atomic_write_text(target, "new\n" * 1000)
    monkeypatch.undo()
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.txt"]
