"""A jab or a sweep that makes no sense with the layout's beam or carrier is bad input (SPEC §13,
SPEC §7): the scenario, parameters.txt and the command line name the file, the line and the
value, exit status 2, no traceback. One check (core/files/validation.py) for every reader."""

import math
import re

import pytest
from commands import waferscan
from scenarios import SLOW_JAB_WITHOUT_ROBOT as NO_ROBOT

from waferscan.core.errors import InputError
from waferscan.core.files.mcs import apply_parameters, parse_parameters
from waferscan.core.files.scenario import parse_scenario


def scenario(**replace):
    """The example (no robot) with ``key = value`` lines replaced, each key once in the file
    (``direction`` here is the [sensor]'s vector; the [scan]'s is written as "up")."""
    text = NO_ROBOT
    for key, value in replace.items():
        pattern = re.compile(rf"^{key} = \[.*\]$" if key in ("direction", "emitter")
                             else rf"^{key} = [^\n#]*?(?=\s*(#|$))", re.M)
        assert len(pattern.findall(text)) == 1, key
        text = pattern.sub(f"{key} = {value}", text)
    return text


def line_of(text, key):
    """1-based number of the line that sets ``key`` (the first such)."""
    return next(i for i, line in enumerate(text.splitlines(), 1)
                if line.startswith(f"{key} ="))


def refused(text, key, *fragments):
    with pytest.raises(InputError) as caught:
        parse_scenario(text, "s.toml")
    message = str(caught.value)
    assert message.startswith(f"s.toml:{line_of(text, key)}: [scan] {key}: "), message
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message
    return message


def test_the_example_without_its_robot_is_accepted():
    assert parse_scenario(NO_ROBOT, "s.toml").scan.jab == 20.0


def test_a_vertical_beam_gives_the_jab_no_heading():
    refused(scenario(direction="[0.0, 0.0, 1.0]"), "jab", "20 mm", "[0, 0, 1]", "vertical")


def test_a_vertical_beam_gives_the_sweep_no_heading_when_there_is_no_jab():
    # The wrist axis is vertical: a vertical beam would turn about an axis parallel to itself.
    refused(scenario(direction="[0.0, 0.0, 1.0]", jab="0.0"), "sweep", "40 degrees", "vertical")


def test_a_nearly_vertical_beam_is_refused_and_a_steep_one_accepted():
    # Horizontal part 0.05 / |(0.05, 0, 1)| < 0.1 after normalising: refused.
    refused(scenario(direction="[0.05, 0.0, 1.0]"), "jab", "vertical")
    # 0.2 / |(0.2, 0, 1)| = 0.196: the fork has a heading (and the jab meets the wafers).
    layout = parse_scenario(scenario(direction="[0.2, 0.0, 1.0]", length="20.0"), "s.toml")
    assert layout.beam.direction[0] == pytest.approx(0.2 / math.hypot(0.2, 1.0))


def test_a_beam_along_the_lift_axis_into_the_carrier_has_a_heading_along_the_opening():
    # Lift axis and beam tilted towards the carrier (+Y): the beam's horizontal part points
    # into the carrier, so the heading across it runs along the opening (X): no jab, no sweep.
    text = scenario(direction="[0.0, 0.5, 1.0]").replace(
        "length = 160.0", "length = 160.0\nlift_axis = [0.0, 0.5, 1.0]")
    refused(text, "jab", "runs along carrier LP1's opening", "front [0, -1]")
    refused(text.replace("jab = 20.0", "jab = 0.0"), "sweep", "runs along")
    # Without a jab or a sweep the same layout is not this check's business.
    parse_scenario(text.replace("jab = 20.0", "jab = 0.0").replace("sweep = 40.0", "sweep = 0.0"),
                   "s.toml")


def test_a_carrier_whose_opening_faces_away_from_the_fork():
    # front = [0, 1]: the heading into the opening is -Y, and the carrier's centre (y = 400)
    # lies 160 mm behind the beam (y = 240) along it: the jab would draw back.
    refused(scenario(front="[0.0, 1.0]"), "jab", "160.000 mm behind", "faces away")
    refused(scenario(front="[0.0, 1.0]", jab="0.0"), "sweep", "faces away")


def test_a_jab_that_would_drive_the_tines_into_a_seated_wafer():
    # Hand computation: the beam's ends at x = ±80 mm, y = 240; a seated wafer's rim (r = 150
    # about (0, 400)) is at y = 400 - sqrt(150² - 80²) under them: they reach it after this.
    deepest = 400.0 - math.sqrt(150.0 ** 2 - 80.0 ** 2) - 240.0
    assert parse_scenario(scenario(jab=f"{deepest - 1e-6:.7f}"), "s.toml").scan.jab > 33.11
    refused(scenario(jab=f"{deepest + 1e-6:.7f}"), "jab", f"after {deepest:.3f} mm", "'LP1'")


def test_tines_already_inside_the_wafers_allow_no_jab_at_all():
    # A 100 mm beam at y = 280, 30 mm behind the rim's front point: its ends (±50, 280) are
    # inside a seated wafer's rim (50² + 120² < 150²): any jab strikes.
    text = scenario(emitter="[-50.0, 280.0, 280.0]", length="100.0", jab="0.5")
    refused(text, "jab", "already stands inside")


def test_a_beam_passing_beside_the_wafers_takes_any_jab_within_the_limits():
    # Both ends on the same side (x from 200 to 360): the tines never reach a seated wafer.
    text = scenario(emitter="[200.0, 240.0, 280.0]", jab="500.0")
    assert parse_scenario(text, "s.toml").scan.jab == 500.0
    refused(scenario(emitter="[200.0, 240.0, 280.0]", jab="2000000.0"), "jab",
            "at most 1,000,000 mm")


def test_a_wrist_axis_beyond_the_layouts_limits():
    refused(scenario(sweep_radius="1e300"), "sweep_radius", "at most 1,000,000 mm", "1e+300")


@pytest.mark.parametrize("key, value", [("arm_speed", "5e-324"), ("arm_acceleration", "1e-320"),
                                        ("wrist_speed", "5e-324"),
                                        ("wrist_acceleration", "1e-320")])
def test_arm_and_wrist_motions_whose_time_overflows(key, value):
    refused(scenario(**{key: value}), key, "overflow")


def test_a_lift_so_slow_that_the_durations_overflow():
    # Every scan reports its simulated durations (JSON has no infinity).
    text = scenario(jab="0.0", sweep="0.0").replace('mode = "slow"',
                                                    'mode = "slow"\nscan_speed = 5e-324')
    refused(text, "scan_speed", "overflow")


def test_a_read_at_rest_so_long_that_the_durations_overflow():
    # scan_speed × sensor_response (50 km) is within the latch's limit, but 10^8 reads of 5e299 s
    # are not a finite time.
    text = scenario(jab="0.0", sweep="0.0").replace(
        'mode = "slow"', 'mode = "slow"\nscan_speed = 1e-295\nsensor_response = 5e299')
    refused(text, "sensor_response", "must be smaller", "overflow")


def test_parameters_txt_is_checked_the_same_way():
    layout = parse_scenario(scenario(jab="0.0", sweep="0.0"), "s.toml")
    with pytest.raises(InputError, match=r"^parameters.txt:2: jab: 40 mm would drive the fork's "
                                         r"tines .* after 33\.114 mm$"):
        apply_parameters(layout, parse_parameters("mode = slow\njab = 40\n"))
    vertical = parse_scenario(scenario(direction="[0.0, 0.0, 1.0]", jab="0.0", sweep="0.0"),
                              "s.toml")
    with pytest.raises(InputError, match=r"^parameters.txt:1: sweep: 10 degrees needs a beam "
                                         r"that crosses the pocket.*vertical"):
        apply_parameters(vertical, parse_parameters("sweep = 10\n"))


def test_the_command_line_says_it_in_one_line_with_exit_status_2(tmp_path):
    text = scenario(direction="[0.0, 0.0, 1.0]")
    (tmp_path / "vertical.toml").write_text(text)
    done = waferscan("scan", "vertical.toml", "--mode", "slow", cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""
    assert done.stderr.count("\n") == 1
    assert done.stderr.startswith(f"waferscan: error: vertical.toml:{line_of(text, 'jab')}: "
                                  f"[scan] jab: 20 mm needs a beam that crosses the pocket")
    # A fast scenario with the jab, made slow on the command line: refused the same way (the
    # jab is checked whatever the mode), not met by the slow scan's arithmetic.
    (tmp_path / "fast.toml").write_text(text.replace('mode = "slow"', 'mode = "fast"'))
    done = waferscan("scan", "fast.toml", "--mode", "slow", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert done.stderr.startswith(f"waferscan: error: fast.toml:{line_of(text, 'jab')}: ")

