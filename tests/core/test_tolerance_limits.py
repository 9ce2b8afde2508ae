"""TOL.toml values are range-checked as the other readers' are (issue 25): a uniform from
-1e308 to 1e308 gave an OverflowError traceback, `[beam_z] value = 1e308` a summary of empty
slots with RuntimeWarnings. Each is now one error line naming the file, the line and the key
(exit 2), before anything is drawn. Each case failed before the fix."""

import pytest
from commands import waferscan
from scenarios import PAPER, normal, uniform

from waferscan.core.errors import InputError
from waferscan.core.sweep.distributions import parse_tolerances


@pytest.mark.parametrize("text, line, start", [
    ('[seat_offset]\ndist = "uniform"\nlo = -1e308\nhi = 1e308\n', 3,
     "[seat_offset] lo: must stay within ±1,000 mm"),
    ('[beam_z]\ndist = "fixed"\nvalue = 1e308\n', 3, "[beam_z] value: must stay within ±1,000 mm"),
    ('[beam_z]\ndist = "normal"\nmean = 0\nsigma = 1e307\n', 4,
     "[beam_z] sigma: must stay within ±1,000 mm"),
    ('[thickness]\ndist = "uniform"\nlo = 0.7\nhi = 1e9\n', 4,
     "[thickness] hi: must stay within ±100 mm"),
    ('[bow]\ndist = "fixed"\nvalue = -1e300\n', 3, "[bow] value: must stay within ±100 mm"),
    ('[protrusion]\ndist = "uniform"\nlo = 0\nhi = 5000\n', 4,
     "[protrusion] hi: must stay within ±1,000 mm"),
    ('[sensor_response]\ndist = "fixed"\nvalue = 1e200\n', 3,
     "[sensor_response] value: must stay within ±10 s"),
    ('[beam_tilt]\ndist = "fixed"\nvalue = 1e10\n', 3,
     "[beam_tilt] value: must stay within ±90 deg"),
])
def test_values_beyond_a_quantitys_limits_are_refused_with_file_and_line(text, line, start):
    with pytest.raises(InputError) as caught:
        parse_tolerances(text, "TOL.toml")
    assert caught.value.line == line
    assert str(caught.value).startswith(f"TOL.toml:{line}: {start}"), str(caught.value)


def test_values_within_the_limits_still_pass():
    tolerances = parse_tolerances(normal("beam_z", 0, 0.2) + uniform("seat_offset", -0.5, 0.5),
                                  "T")
    assert set(tolerances.quantities) == {"beam_z", "seat_offset"}


@pytest.mark.parametrize("table", ['[seat_offset]\ndist = "uniform"\nlo = -1e308\nhi = 1e308\n',
                                   '[beam_z]\ndist = "fixed"\nvalue = 1e308\n'])
def test_the_sweep_command_says_it_in_one_line(tmp_path, table):
    tol = tmp_path / "TOL.toml"
    tol.write_text(table)
    done = waferscan("sweep", PAPER, "--tolerances", tol, "-n", "20", "--workers", "0",
                     timeout=600)
    assert done.returncode == 2, (done.stdout[-500:], done.stderr[-2000:])
    assert done.stderr.count("\n") == 1 and done.stderr.startswith(f"waferscan: error: {tol}:")
    assert "must stay within" in done.stderr and done.stdout == ""
