"""Scenario files (SPEC §6): what they build, and every mistake named by file, line and key."""

import math

import pytest
import scenarios
from hypothesis import given, settings
from hypothesis import strategies as st
from scenarios import PAPER_TEXT, ROOT

from waferscan.core.errors import InputError
from waferscan.core.files.scenario import parse_scenario, read_scenario
from waferscan.core.scan.layout_scan import scan_layout

PAPER = read_scenario(scenarios.PAPER)

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

# A 12-slot carrier for load strings: the beam 16.6 mm deep into the wafers, as in the paper.
TWELVE = SMALL.replace("final_z = 160.0", "final_z = 230.0").replace("slots = 5", "slots = 12") \
    .replace('load = "10000"', 'support_span = 292.5\nload = "{load}"')


def line_of(text, fragment, nth=0):
    return [i for i, line in enumerate(text.splitlines(), 1) if fragment in line][nth]


def with_load(load, text=SMALL):
    return parse_scenario(text.replace('load = "10000"', f'load = "{load}"'), "load.toml")


# --- what a scenario builds ----------------------------------------------------------------

def test_the_papers_wafers():
    assert [w.name for w in PAPER.wafers] == [f"LP1_W{i:02d}" for i in range(1, 11)]
    slots = [w.slot for w in PAPER.wafers]
    assert slots == [1, 2, 4, 5, 7, 10, 11, 16, 18, 24]
    for w in PAPER.wafers:
        seat = 293.94 + 10.0 * (w.slot - 1)
        assert w.carrier == "LP1" and (w.diameter, w.thickness) == (300.0, 0.7)
        assert w.center[:2] == pytest.approx((0.0, 400.0))
        if w.slot in (5, 11):  # cross-slotted: half a pitch up, tilted
            assert w.center[2] == pytest.approx(seat + 5.0)
            assert w.normal[2] == pytest.approx(math.cos(math.atan(10.0 / 292.5)))
        else:
            assert w.center[2] == pytest.approx(seat) and w.normal == (0.0, 0.0, 1.0)
    assert PAPER.carrier == "LP1" and len(PAPER.carriers) == 1
    assert (PAPER.scan.start_z, PAPER.scan.final_z, PAPER.scan.z_step) == (280.0, 550.0, 0.05)
    assert PAPER.beam.emitter == (-80.0, 266.6, 280.0) and PAPER.beam.length == 160.0
    assert PAPER.robot.base == (0.0, -300.0, 0.0) and PAPER.robot.urdf is None
    assert PAPER.robot.base_yaw == 0.0
    assert scan_layout(PAPER).code == "1101221001220001010000010"


@pytest.mark.parametrize("digit, check", [
    ("0", lambda ws: ws == []),
    ("1", lambda ws: [(w.center, w.normal, w.thickness) for w in ws]
     == [((0.0, 400.0, 110.0), (0.0, 0.0, 1.0), 0.7)]),
    ("3", lambda ws: [w.center[2] for w in ws] == pytest.approx([110.0, 110.7])
     and all(w.thickness == 0.7 and w.normal == (0.0, 0.0, 1.0) for w in ws)),
    ("4", lambda ws: len(ws) == 1 and ws[0].thickness == pytest.approx(0.25 * 0.7)
     and ws[0].center == pytest.approx((0.0, 400.0, 110.0))),
    ("5", lambda ws: len(ws) == 1 and ws[0].center == pytest.approx((0.0, 400.0, 112.0))),
    ("6", lambda ws: len(ws) == 1 and ws[0].center == pytest.approx((0.0, 395.0, 110.0))),
])
def test_each_load_digit_builds_its_wafers(digit, check):
    layout = with_load(f"0{digit}000")
    wafers = [w for w in layout.wafers if w.slot == 2]
    assert len(wafers) == len(layout.wafers)
    assert check(wafers)
    assert [w.name for w in wafers] == [f"A_W{i:02d}" for i in range(1, len(wafers) + 1)]


def test_a_protruding_wafer_moves_along_the_carriers_front():
    text = SMALL.replace('load = "10000"', 'front = [3.0, 4.0]\nload = "00060"')
    (wafer,) = parse_scenario(text).wafers
    assert wafer.center == pytest.approx((3.0, 404.0, 130.0))


@pytest.mark.parametrize("span", [292.5, 250.0])
def test_a_cross_slotted_wafer_tilts_by_atan_pitch_over_span(span):
    text = SMALL.replace('load = "10000"', f'support_span = {span}\nload = "02200"')
    (wafer,) = parse_scenario(text).wafers
    tilt = math.acos(wafer.normal[2])
    assert tilt == pytest.approx(math.atan(10.0 / span))
    assert math.hypot(*wafer.normal) == pytest.approx(1.0)
    assert wafer.normal[1] == pytest.approx(0.0, abs=1e-12)  # tilted about the front (y) axis
    assert wafer.center == pytest.approx((0.0, 400.0, 115.0))  # between slots 2 and 3
    assert wafer.slot == 2 and wafer.thickness == 0.7


def test_the_default_support_span_reaches_under_the_rim():
    (wafer,) = with_load("22000").wafers
    assert math.acos(wafer.normal[2]) == pytest.approx(math.atan(10.0 / (300.0 - 2 * 3.75)))


@pytest.mark.parametrize("load", ["101220345610", "000000000000", "111111111111",
                                  "222222222222", "333333333333", "444444444444",
                                  "555555555555", "666666666666", "345602210001"])
def test_scanning_a_load_gives_its_code(load):
    assert scan_layout(parse_scenario(TWELVE.format(load=load))).code == load


@settings(max_examples=80, deadline=None)
@given(st.lists(st.sampled_from(["0", "1", "22", "3", "4", "5", "6"]), min_size=1, max_size=12))
def test_scanning_any_load_gives_its_code(tokens):
    load = ""
    for token in tokens:
        if len(load) + len(token) <= 12:
            load += token
    load = load.ljust(12, "0")
    assert scan_layout(parse_scenario(TWELVE.format(load=load))).code == load


def test_explicit_wafers_replace_the_load_and_free_wafers_are_placed():
    text = SMALL.replace('load = "10000"', 'load = "12210"') + """
[[wafer]]
carrier = "A"
slot = 1
state = "double"

[[wafer]]
slot = 3
state = "cross"

[[wafer]]
slot = 5
state = "thin"

[[wafer]]
name = "loose"
center = [0.0, 400.0, 142.0]
normal = [0.0, 0.0, 2.0]
thickness = 0.5
"""
    layout = parse_scenario(text)
    # slot 1 double; the load's cross in 2-3 gives way to the explicit cross in 3-4, which
    # also takes slot 4's wafer; slot 5 thin; then the free wafer.
    assert [w.slot for w in layout.wafers[:4]] == [1, 1, 3, 5]
    assert [w.center[2] for w in layout.wafers[:4]] == pytest.approx([100.0, 100.7, 125.0, 140.0])
    assert [w.name for w in layout.wafers[:4]] == ["A_W01", "A_W02", "A_W03", "A_W04"]
    assert layout.wafers[3].thickness == pytest.approx(0.175)
    loose = layout.wafers[-1]
    assert (loose.name, loose.normal, loose.thickness, loose.diameter, loose.slot) == \
        ("loose", (0.0, 0.0, 1.0), 0.5, 300.0, None)
    assert len(layout.wafers) == 5


def test_an_explicit_absent_wafer_empties_its_slot():
    text = SMALL + '\n[[wafer]]\nslot = 1\nstate = "absent"\n'
    assert parse_scenario(text).wafers == ()


def test_free_wafers_take_their_carriers_defaults_and_get_names():
    text = SMALL.replace('load = "10000"', 'load = "00000"') + """
[[wafer]]
center = [1.0, 2.0, 3.0]

[[wafer]]
carrier = "A"
center = [0.0, 400.0, 120.0]
diameter = 200.0
"""
    first, second = parse_scenario(text).wafers
    assert (first.name, first.center, first.normal, first.diameter, first.thickness) == \
        ("W1", (1.0, 2.0, 3.0), (0.0, 0.0, 1.0), 300.0, 0.7)
    assert (second.name, second.carrier, second.diameter) == ("W2", "A", 200.0)


def test_scanning_explicit_and_free_wafers():
    text = SMALL + """
[[wafer]]
slot = 1
state = "double"

[[wafer]]
slot = 3
state = "cross"

[[wafer]]
name = "loose"
center = [0.0, 400.0, 142.0]
"""
    assert scan_layout(parse_scenario(text)).code == "30225"  # loose: 2 mm above slot 5's seat


def test_robot_table(tmp_path):
    scenario = tmp_path / "s.toml"
    scenario.write_text(SMALL + '\n[robot]\nurdf = "robots/arm.urdf"\nbase = [1, 2, 3]\n')
    with pytest.raises(InputError) as caught:
        read_scenario(scenario)
    assert caught.value.line == 22
    assert str(caught.value).startswith(f"{scenario}:22: [robot] urdf: no such file: ")
    assert str(caught.value).endswith("arm.urdf")
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "arm.urdf").write_text("<robot/>")
    robot = read_scenario(scenario).robot
    assert robot.urdf == str(tmp_path / "robots" / "arm.urdf")
    assert (robot.base, robot.base_yaw) == ((1.0, 2.0, 3.0), 0.0)
    defaults = parse_scenario(SMALL + "\n[robot]\n").robot
    assert (defaults.urdf, defaults.base, defaults.base_yaw) == (None, (0.0, 0.0, 0.0), 0.0)
    assert parse_scenario(SMALL + "\n[robot]\nbase_yaw = 90\n").robot.base_yaw == 90.0
    assert parse_scenario(SMALL).robot is None


def test_two_vectors_and_start_z_in_scan():
    text = SMALL.replace("emitter = [-80.0, 266.6, 90.0]", "emitter = [-80.0, 266.6]")
    layout = parse_scenario(text)
    assert layout.beam.emitter == (-80.0, 266.6, 90.0) and layout.scan.start_z == 90.0
    layout = parse_scenario(SMALL.replace("start_z = 90.0\n", ""))
    assert layout.scan.start_z == 90.0
    assert parse_scenario(SMALL.replace("direction = [1.0, 0.0, 0.0]",
                                        "direction = [2.0, 0.0, 0.0]")).beam.direction == \
        (1.0, 0.0, 0.0)


# --- mistakes ------------------------------------------------------------------------------

ERRORS = [
    # (change to SMALL, line fragment the error must point at, message fragment)
    (("pitch = 10.0", "pitch = = 10.0"), "pitch = = 10.0", "not valid TOML"),
    (("[sensor]", "[sensor"), "[sensor", "not valid TOML"),
    (("[scan]", "[scna]"), "[scna]", "unknown table or key 'scna'"),
    (("[scan]", "colour = 1\n[scan]"), "colour = 1", "unknown table or key 'colour'"),
    (("z_step = 0.05", "z_step = 0.05\nspeed = 3"), "speed = 3", "[scan] speed: unknown key"),
    (("length = 160.0", "length = 160.0\ncolour = 1"), "colour = 1", "[sensor] colour: unknown key"),
    (("load = \"10000\"", "load = \"10000\"\nlid = 1"), "lid = 1", "[[carrier]] #1 lid: unknown key"),
    (("[[carrier]]", "[mapping]\nslack = 1\n\n[[carrier]]"), "slack = 1",
     "[mapping] slack: unknown key"),
    (("[[carrier]]", "[robot]\narm = 1\n\n[[carrier]]"), "arm = 1", "[robot] arm: unknown key"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\nslot = 1\ncolor = 1"), "color = 1",
     "[[wafer]] #1 color: unknown key"),
    (("first_slot_z = 100.0\n", ""), "[[carrier]]", "[[carrier]] #1 missing key 'first_slot_z'"),
    (("center = [0.0, 400.0]\n", ""), "[[carrier]]", "missing key 'center'"),
    (("length = 160.0\n", ""), "[sensor]", "[sensor] missing key 'length'"),
    (("direction = [1.0, 0.0, 0.0]\n", ""), "[sensor]", "missing key 'direction'"),
    (("emitter = [-80.0, 266.6, 90.0]\n", ""), "[sensor]", "missing key 'emitter'"),
    (("final_z = 160.0\n", ""), "[scan]", "[scan] missing key 'final_z'"),
    (("center = [0.0, 400.0]", "center = [0.0, 400.0, 1.0]"), "center =", "expected a list of 2"),
    (("emitter = [-80.0, 266.6, 90.0]", "emitter = [-80.0, 266.6, 90.0, 1.0]"), "emitter =",
     "expected [x, y] or [x, y, z]"),
    (("direction = [1.0, 0.0, 0.0]", "direction = [1.0, 0.0]"), "direction =",
     "[sensor] direction: expected a list of 3"),
    (("direction = [1.0, 0.0, 0.0]", "direction = [0.0, 0.0, 0.0]"), "direction =",
     "must not be the zero vector"),
    (("direction = [1.0, 0.0, 0.0]", "direction = [1.0, \"x\", 0.0]"), "direction =",
     "expected a number, got 'x'"),
    (("pitch = 10.0", "pitch = -10.0"), "pitch =", "pitch: must be greater than 0, got -10.0"),
    (("wafer_diameter = 300.0", "wafer_diameter = 0"), "wafer_diameter =", "greater than 0"),
    (("wafer_thickness = 0.7", "wafer_thickness = -0.7"), "wafer_thickness =", "greater than 0"),
    (("length = 160.0", "length = 0.0"), "length =", "length: must be greater than 0"),
    (("length = 160.0", "length = \"long\""), "length =", "expected a number, got 'long'"),
    (("slots = 5", "slots = 2.5"), "slots =", "slots: expected a whole number"),
    (("load = \"10000\"", "load = \"1000\""), "load =", "expected a string of 5 digits"),
    (("load = \"10000\"", "load = \"100000\""), "load =", "expected a string of 5 digits"),
    (("load = \"10000\"", "load = 10000"), "load =", "expected a string of 5 digits"),
    (("load = \"10000\"", "load = \"12000\""), "load =", "slot 2: a cross-slotted wafer spans"),
    (("load = \"10000\"", "load = \"10002\""), "load =", "slot 5: a cross-slotted wafer spans"),
    (("load = \"10000\"", "load = \"22200\""), "load =", "slot 3: a cross-slotted wafer spans"),
    (("load = \"10000\"", "load = \"17000\""), "load =", "slot 2: '7' is not a slot state"),
    (("load = \"10000\"", "load = \"1x000\""), "load =", "slot 2: 'x' is not a slot state"),
    (("start_z = 90.0", "start_z = 91.0"), "start_z =", "differs from the emitter's z"),
    (("final_z = 160.0", "final_z = 80.0"), "final_z =", "final_z (80) is below start_z (90)"),
    (("z_step = 0.05", "z_step = -0.05"), "z_step =", "[scan] z_step: must not be negative"),
    (("z_step = 0.05", "z_step = true"), "z_step =", "expected a number, got True"),
    (("z_step = 0.05", "z_step = nan"), "z_step =", "expected a finite number"),
    (("z_step = 0.05", "mode = \"turbo\""), "mode =", "[scan] mode: expected one of fast, slow"),
    (("z_step = 0.05", "z_step = 0.05\ncarrier = \"B\""), "carrier = \"B\"",
     "[scan] carrier: no carrier named 'B' (carriers: A)"),
    (("wafer_thickness = 0.7", "wafer_thickness = 12.0"), "wafer_thickness =",
     "must be less than the pitch"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\nslot = 9"), "slot = 9",
     "[[wafer]] #1 slot: slot 9 is beyond the carrier's 5 slots"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\nslot = 2\nstate = \"gone\""),
     "state =", "[[wafer]] #1 state: expected one of"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\nslot = 2\ncarrier = \"Z\""),
     "carrier = \"Z\"", "[[wafer]] #1 carrier: no carrier named 'Z'"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\nname = \"A_W01\"\ncenter = [0, 0, 0]"),
     "name = \"A_W01\"", "[[wafer]] #1 name: a second wafer named 'A_W01'"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\nnormal = [0, 0, 1]"), "[[wafer]]",
     "[[wafer]] #1 missing key 'center'"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\ncenter = [0, 0, 0]\n"
                          "normal = [0, 0, 0]"), "normal =", "must not be the zero vector"),
    (("load = \"10000\"", "load = \"10000\"\n[[wafer]]\ncenter = [0, 0, 0]\n"
                          "thickness = 0  # none"), "# none", "greater than 0"),
    (("load = \"10000\"", "load = \"10000\"\n[robot]\nbase = [0, 0]"), "base =",
     "[robot] base: expected a list of 3"),
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


def test_a_scenario_needs_a_carrier_and_a_sensor():
    no_carrier = SMALL[:SMALL.index("[[carrier]]")]
    with pytest.raises(InputError, match=r"^bad.toml: no \[\[carrier\]\] table"):
        parse_scenario(no_carrier, "bad.toml")
    no_sensor = SMALL.replace("[sensor]\nemitter = [-80.0, 266.6, 90.0]\n"
                              "direction = [1.0, 0.0, 0.0]\nlength = 160.0\n", "")
    with pytest.raises(InputError, match=r"^bad.toml: no \[sensor\] table"):
        parse_scenario(no_sensor, "bad.toml")


TWO = SMALL + SMALL[SMALL.index("[[carrier]]"):].replace('name = "A"', 'name = "B"')


def test_several_carriers_need_a_choice():
    with pytest.raises(InputError) as caught:
        parse_scenario(TWO, "two.toml")
    assert caught.value.line == line_of(TWO, "[scan]")
    assert "[scan] several carriers (A, B): say which one" in str(caught.value)
    assert parse_scenario(TWO.replace("[scan]", '[scan]\ncarrier = "B"')).carrier == "B"
    two_wafers = [w.name for w in parse_scenario(TWO.replace("[scan]",
                                                             '[scan]\ncarrier = "A"')).wafers]
    assert two_wafers == ["A_W01", "B_W01"]
    with pytest.raises(InputError, match=r"^two.toml:2: \[scan\] carrier: no carrier named 'C'"):
        parse_scenario(TWO.replace("[scan]", '[scan]\ncarrier = "C"'), "two.toml")
    # A slot-and-state wafer in a layout of two carriers must say which.
    text = TWO.replace("[scan]", '[scan]\ncarrier = "A"') + "\n[[wafer]]\nslot = 2\n"
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "two.toml")
    assert caught.value.line == line_of(text, "[[wafer]]") and "several carriers" in str(caught.value)


def test_duplicate_carrier_names():
    same = SMALL + SMALL[SMALL.index("[[carrier]]"):]
    with pytest.raises(InputError) as caught:
        parse_scenario(same, "same.toml")
    assert "[[carrier]] #2 name: a second carrier named 'A'" in str(caught.value)
    assert caught.value.line == line_of(same, 'name = "A"', nth=1)


def test_wafer_entry_errors():
    with pytest.raises(InputError) as caught:
        parse_scenario(SMALL + "\n[[wafer]]\nslot = 5\nstate = \"cross\"\n", "w.toml")
    assert caught.value.line == 22 and "slot 5 needs a slot above" in str(caught.value)
    with pytest.raises(InputError) as caught:
        parse_scenario(SMALL + "\n[[wafer]]\nslot = 2\ncenter = [0, 0, 0]\n", "w.toml")
    assert caught.value.line == 23 and "give either carrier + slot + state" in str(caught.value)
    with pytest.raises(InputError, match=r"^w.toml:21: \[\[wafer\]\] #1 missing key 'slot'"):
        parse_scenario(SMALL + "\n[[wafer]]\nstate = \"thin\"\n", "w.toml")
    text = SMALL + "\n[[wafer]]\nslot = 1\n\n[[wafer]]\nslot = 0\n"
    with pytest.raises(InputError, match=r"^w.toml:25: \[\[wafer\]\] #2 slot: expected a whole"):
        parse_scenario(text, "w.toml")


def test_array_and_table_shapes():
    with pytest.raises(InputError, match=r"write it as \[\[carrier\]\] tables"):
        parse_scenario(SMALL.replace("[[carrier]]", "[carrier]"))
    with pytest.raises(InputError, match=r"write it as a \[scan\] table"):
        parse_scenario("scan = 5\n" + SMALL.replace("[scan]", "[extra_scan]"))


def test_unreadable_files(tmp_path):
    with pytest.raises(InputError) as caught:
        read_scenario(tmp_path / "missing.toml")
    assert str(caught.value).startswith(f"{tmp_path / 'missing.toml'}: cannot read the scenario")
    assert caught.value.line is None
    bad = tmp_path / "bad.toml"
    bad.write_bytes(SMALL.encode().replace(b'"A"', b'"\xff"'))
    with pytest.raises(InputError) as caught:
        read_scenario(bad)
    assert str(caught.value) == f"{bad}:12: not UTF-8 text"
    crlf = tmp_path / "crlf.toml"
    crlf.write_bytes(b"\xef\xbb\xbf" + SMALL.replace("\n", "\r\n").encode())
    assert read_scenario(crlf).wafers == parse_scenario(SMALL).wafers
    with pytest.raises(InputError, match=r"cannot read the scenario"):
        read_scenario(tmp_path)


# --- bugs found ----------------------------------------------------------------------------

@pytest.mark.parametrize("old, new", [("z_step = 0.05", "z_step = 1e-320"),
                                      ("final_z = 550.0", "final_z = 1e308")])
def test_extreme_scan_ranges_are_input_errors(old, new):
    text = PAPER_TEXT.replace(old, new)
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "x.toml")
    assert caught.value.line == line_of(text, new)


@pytest.mark.parametrize("old, new, same_as", [
    ("direction = [1.0, 0.0, 0.0]", "direction = [1e-200, 0.0, 0.0]", "direction = [1.0, 0.0, 0.0]"),
    ("direction = [1.0, 0.0, 0.0]", "direction = [1e200, 1e200, 0.0]", "direction = [1.0, 1.0, 0.0]"),
    ("length = 160.0", "length = 160.0\nlift_axis = [0.0, 0.0, 1e-200]", "length = 160.0"),
    ('load = "10000"', 'load = "10000"\n[[wafer]]\ncenter = [0, 400, 130]\nnormal = [0.0, 1e-200, 0.0]',
     'load = "10000"\n[[wafer]]\ncenter = [0, 400, 130]\nnormal = [0.0, 1.0, 0.0]'),
])
def test_vectors_with_tiny_or_huge_components_normalise_to_their_direction(old, new, same_as):
    # Their squared length underflows or overflows, but the direction is well defined.
    layout = parse_scenario(SMALL.replace(old, new), "v.toml")
    expected = parse_scenario(SMALL.replace(old, same_as), "v.toml")
    assert layout == expected
    assert scan_layout(layout, "analytic") == scan_layout(expected, "analytic")


def test_a_line_separator_in_a_comment_does_not_shift_line_numbers():
    text = "# a\u2028b\n" + SMALL.replace("z_step = 0.05", "z_step = -1")
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "u.toml")
    assert caught.value.line == 5


def test_a_quoted_table_header_keeps_line_numbers():
    text = SMALL.replace("[scan]", '["scan"]').replace("z_step = 0.05", "z_step = -1")
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "q.toml")
    assert caught.value.line == 4


def test_a_multi_line_string_value_keeps_its_line():
    text = SMALL.replace('load = "10000"', 'load = """\n17000"""')
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "m.toml")
    assert caught.value.line == 19


@pytest.mark.parametrize("old, new, bad_key", [
    # A multi-line array whose lines look like keys.
    ("emitter = [-80.0, 266.6, 90.0]", "emitter = [\n  -80.0,\n  266.6, # x = 1\n  90.0,\n]",
     "length = 160.0"),
    # Strings that hold '=', brackets and quotes.
    ('name = "A"', 'name = "A [1] = \\"x\\" \'y\'"', "slots = 5"),
    # Multi-line strings with lines that look like headers and comments.
    ('load = "10000"', 'load = "10000"\n[[wafer]]\nname = \'\'\'\n[scan]\nW # 1\'\'\'\n'
     'center = [0, 400, 130] # """\nthickness = 0.5', "thickness = 0.5"),
    ('load = "10000"', 'load = "10000"\n[[wafer]]\nname = """W\\"""\n= 1"""\n'
     'center = [0, 400, 130]\nthickness = 0.5', "thickness = 0.5"),
    # Dotted keys at the top level instead of the [scan] table.
    ("[scan]\nstart_z = 90.0\nfinal_z = 160.0\nz_step = 0.05\n",
     "scan.start_z = 90.0\nscan.final_z = 160.0\nscan.z_step = 0.05\n", "scan.final_z = 160.0"),
    # A quoted, spaced header of an array of tables.
    ("[[carrier]]", "[[ 'carrier' ]]  # the load port", "slots = 5"),
])
def test_line_numbers_survive_toml_that_spans_lines(old, new, bad_key):
    key = bad_key.split(" = ")[0]
    text = SMALL.replace(old, new).replace(bad_key, f"{key} = -1")
    for newline in ("\n", "\r\n"):
        with pytest.raises(InputError) as caught:
            parse_scenario(text.replace("\n", newline), "t.toml")
        assert caught.value.line == text.split("\n").index(f"{key} = -1") + 1, str(caught.value)
        assert key.split(".")[-1] in caught.value.message


# --- any mutation --------------------------------------------------------------------------

VALUES = st.one_of(
    st.text(max_size=10),
    st.floats(allow_subnormal=False, min_value=-1e6, max_value=1e6).map(repr),
    st.sampled_from(["nan", "inf", "-inf", "true", "[]", "[1, 2]", "[0, 0, 0]", "[1, 2, 3]",
                     '"22"', '"0"', '"LP1"', '"x"', "{}", "[[1]]"]),
    st.integers(-1000, 1000).map(str))


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_mutated_scenarios_are_accepted_or_refused_cleanly(data):
    lines = PAPER_TEXT.splitlines()
    index = data.draw(st.integers(0, len(lines) - 1))
    how = data.draw(st.sampled_from(["delete", "value", "duplicate", "swap"]))
    if how == "delete":
        del lines[index]
    elif how == "duplicate":
        lines.insert(index, lines[index])
    elif how == "swap":
        other = data.draw(st.integers(0, len(lines) - 1))
        lines[index], lines[other] = lines[other], lines[index]
    elif "=" in lines[index]:
        key = lines[index].split("=")[0]
        lines[index] = f"{key}= {data.draw(VALUES)}"
    text = "\n".join(lines) + "\n"
    try:
        layout = parse_scenario(text, "m.toml", folder=ROOT)
    except InputError as exc:
        assert str(exc).startswith("m.toml")
        assert exc.line is None or 1 <= exc.line <= len(lines)
    else:
        assert layout.carrier in [c.name for c in layout.carriers]
        assert all(c.wafer_thickness < c.pitch for c in layout.carriers)
        assert layout.scan.final_z >= layout.scan.start_z
