"""Scenario files: what they build, and every mistake named by file, line and key."""

import math
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from waferscan.core.errors import InputError
from waferscan.core.scan import scan_layout
from waferscan.core.scenario import parse_scenario, read_scenario

ROOT = Path(__file__).resolve().parents[2]
PAPER_TEXT = (ROOT / "resources/examples/paper.toml").read_text()
PAPER = parse_scenario(PAPER_TEXT, "paper.toml")

SMALL = """\
[scan]
start_z = 90.0
final_z = 160.0
z_step = 0.05

[sensor]
emitter = [-80.0, 266.6, 90.0]
direction = [1.0, 0.0, 0.0]
length = 160.0

[[carrier]]
name = "A"
slots = 5
pitch = 10.0
first_slot_z = 100.0
center = [0.0, 400.0]
wafer_diameter = 300.0
wafer_thickness = 0.7
load = "10000"
"""


def line_of(text, fragment):
    return next(i for i, line in enumerate(text.splitlines(), 1) if fragment in line)


def test_the_papers_wafers():
    assert [w.name for w in PAPER.wafers] == [f"LP1_W{i:02d}" for i in range(1, 11)]
    seats = [w.center[2] for w in PAPER.wafers if w.normal == (0.0, 0.0, 1.0)]
    assert seats == pytest.approx([293.94, 303.94, 323.94, 353.94, 383.94, 443.94, 463.94, 523.94])
    assert PAPER.robot.base == (0.0, -300.0, 0.0) and PAPER.robot.urdf is None


def test_load_digits_build_their_wafers():
    layout = parse_scenario(SMALL.replace('load = "10000"', 'load = "22346"'))
    by_slot = {}
    for w in layout.wafers:
        by_slot.setdefault(w.slot, []).append(w)
    (cross,) = by_slot[1]
    tilt = math.degrees(math.acos(cross.normal[2]))
    assert tilt == pytest.approx(math.degrees(math.atan(10.0 / (300.0 - 7.5))))
    assert cross.center[2] == pytest.approx(105.0)
    assert [w.center[2] for w in by_slot[3]] == pytest.approx([120.0, 120.7])
    assert by_slot[4][0].thickness == pytest.approx(0.175)
    assert by_slot[5][0].center == pytest.approx((0.0, 395.0, 140.0))
    raised = parse_scenario(SMALL.replace('load = "10000"', 'load = "05000"')).wafers[0]
    assert raised.center[2] == pytest.approx(112.0)


def test_explicit_wafers_replace_the_load_and_free_wafers_are_placed():
    text = SMALL + """
[[wafer]]
carrier = "A"
slot = 1
state = "double"

[[wafer]]
slot = 3
state = "cross"

[[wafer]]
name = "loose"
center = [0.0, 400.0, 142.0]
normal = [0.0, 0.0, 2.0]
thickness = 0.5
"""
    layout = parse_scenario(text)
    assert [(w.slot, w.center[2]) for w in layout.wafers[:3]] == \
        [(1, 100.0), (1, 100.7), (3, 125.0)]
    loose = layout.wafers[-1]
    assert (loose.name, loose.normal, loose.thickness, loose.diameter) == \
        ("loose", (0.0, 0.0, 1.0), 0.5, 300.0)
    assert scan_layout(layout).code == "30225"  # the loose wafer: 2 mm above slot 5's seat


ERRORS = [
    # (change to SMALL, line fragment the error must point at, message fragment)
    (("pitch = 10.0", "pitch = = 10.0"), "pitch = = 10.0", "not valid TOML"),
    (("[scan]", "[scna]"), "[scna]", "unknown table or key 'scna'"),
    (("z_step = 0.05", "z_step = 0.05\nspeed = 3"), "speed = 3", "[scan] speed: unknown key"),
    (("length = 160.0", "length = 160.0\ncolour = 1"), "colour = 1", "[sensor] colour: unknown key"),
    (("load = \"10000\"", "load = \"10000\"\nlid = 1"), "lid = 1", "[[carrier]] #1 lid: unknown key"),
    (("first_slot_z = 100.0\n", ""), "[[carrier]]", "missing key 'first_slot_z'"),
    (("center = [0.0, 400.0]\n", ""), "[[carrier]]", "missing key 'center'"),
    (("length = 160.0\n", ""), "[sensor]", "missing key 'length'"),
    (("direction = [1.0, 0.0, 0.0]\n", ""), "[sensor]", "missing key 'direction'"),
    (("final_z = 160.0\n", ""), "[scan]", "missing key 'final_z'"),
    (("center = [0.0, 400.0]", "center = [0.0, 400.0, 1.0]"), "center =", "expected a list of 2"),
    (("direction = [1.0, 0.0, 0.0]", "direction = [0.0, 0.0, 0.0]"), "direction =",
     "must not be the zero vector"),
    (("pitch = 10.0", "pitch = -10.0"), "pitch =", "must be greater than 0, got -10.0"),
    (("wafer_diameter = 300.0", "wafer_diameter = 0"), "wafer_diameter =", "greater than 0"),
    (("length = 160.0", "length = \"long\""), "length =", "expected a number, got 'long'"),
    (("load = \"10000\"", "load = \"1000\""), "load =", "expected a string of 5 digits"),
    (("load = \"10000\"", "load = \"12000\""), "load =", "slot 2: a cross-slotted wafer spans"),
    (("load = \"10000\"", "load = \"17000\""), "load =", "slot 2: '7' is not a slot state"),
    (("start_z = 90.0", "start_z = 91.0"), "start_z =", "differs from the emitter's z"),
    (("final_z = 160.0", "final_z = 80.0"), "final_z =", "final_z (80) is below start_z (90)"),
    (("z_step = 0.05", "z_step = true"), "z_step =", "expected a number, got True"),
    (("wafer_thickness = 0.7", "wafer_thickness = 12.0"), "wafer_thickness =",
     "must be less than the pitch"),
]


@pytest.mark.parametrize("change, at, message", ERRORS)
def test_mistakes_name_file_line_and_key(change, at, message):
    text = SMALL.replace(*change)
    assert text != SMALL
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "bad.toml")
    assert caught.value.line == line_of(text, at), str(caught.value)
    assert str(caught.value).startswith(f"bad.toml:{caught.value.line}: ")
    assert message in str(caught.value)


def test_carrier_choice_errors():
    two = SMALL + SMALL[SMALL.index("[[carrier]]"):].replace('name = "A"', 'name = "B"')
    with pytest.raises(InputError, match="several carriers \\(A, B\\): say which one"):
        parse_scenario(two)
    assert parse_scenario(two.replace("[scan]", '[scan]\ncarrier = "B"')).carrier == "B"
    with pytest.raises(InputError, match=r":2: \[scan\] carrier: no carrier named 'C'"):
        parse_scenario(two.replace("[scan]", '[scan]\ncarrier = "C"'))
    same = SMALL + SMALL[SMALL.index("[[carrier]]"):]
    second = [i for i, line in enumerate(same.splitlines(), 1) if line == 'name = "A"'][1]
    with pytest.raises(InputError) as caught:
        parse_scenario(same)
    assert "a second carrier named 'A'" in str(caught.value)
    assert caught.value.line == second


def test_wafer_entry_errors():
    base = SMALL + "\n[[wafer]]\nslot = 9\n"
    with pytest.raises(InputError, match=r":22: \[\[wafer\]\] #1 slot: slot 9 is beyond"):
        parse_scenario(base)
    with pytest.raises(InputError, match="slot 5 needs a slot above"):
        parse_scenario(SMALL + "\n[[wafer]]\nslot = 5\nstate = \"cross\"\n")
    with pytest.raises(InputError, match="give either carrier \\+ slot \\+ state"):
        parse_scenario(SMALL + "\n[[wafer]]\nslot = 2\ncenter = [0, 0, 0]\n")


def test_robot_table(tmp_path):
    scenario = tmp_path / "s.toml"
    scenario.write_text(SMALL + '\n[robot]\nurdf = "robots/arm.urdf"\nbase = [1, 2, 3]\n')
    with pytest.raises(InputError, match=r"s.toml:22: \[robot\] urdf: no such file: .*arm.urdf"):
        read_scenario(scenario)
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "arm.urdf").write_text("<robot/>")
    robot = read_scenario(scenario).robot
    assert robot.urdf == str(tmp_path / "robots" / "arm.urdf")
    assert (robot.base, robot.base_yaw) == ((1.0, 2.0, 3.0), 0.0)


def test_unreadable_files(tmp_path):
    with pytest.raises(InputError, match="missing.toml: cannot read the scenario"):
        read_scenario(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_bytes(SMALL.encode().replace(b'"A"', b'"\xff"'))
    with pytest.raises(InputError, match=r"bad.toml:12: not UTF-8 text"):
        read_scenario(bad)


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_mutated_scenarios_are_accepted_or_refused_cleanly(data):
    lines = PAPER_TEXT.splitlines()
    index = data.draw(st.integers(0, len(lines) - 1))
    how = data.draw(st.sampled_from(["delete", "value"]))
    if how == "delete":
        del lines[index]
    elif "=" in lines[index]:
        key = lines[index].split("=")[0]
        value = data.draw(st.one_of(st.text(max_size=10), st.floats().map(repr),
                                    st.integers(-1000, 1000).map(str)))
        lines[index] = f"{key}= {value}"
    try:
        parse_scenario("\n".join(lines), "m.toml", folder=ROOT)
    except InputError as exc:
        assert str(exc).startswith("m.toml")
