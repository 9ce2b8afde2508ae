"""Where `xvfb-run -a` starts counting display numbers (waferscan/bench/xvfb.py):
$WAFERSCAN_XVFB_FIRST keeps the FreeCAD 1.0 root's X servers apart from the host's when both
suites run at once."""

import re
import shutil
import subprocess

import pytest

from waferscan.core.errors import InputError
from waferscan.bench.xvfb import first_display, xvfb_run


def test_the_count_starts_at_xvfb_runs_own_99_unless_told():
    assert first_display({}) == 99
    assert first_display({"WAFERSCAN_XVFB_FIRST": " 200 "}) == 200
    assert xvfb_run("640x480", {"WAFERSCAN_XVFB_FIRST": "200"}) == [
        "xvfb-run", "-a", "-n", "200", "-s", "-screen 0 640x480x24"]


@pytest.mark.parametrize("value", ["0", "-5", "2e2", "abc", "60001", ":200"])
def test_a_display_number_that_is_not_one_is_refused_by_name(value):
    with pytest.raises(InputError, match=re.escape(f"WAFERSCAN_XVFB_FIRST: '{value}': a display")):
        first_display({"WAFERSCAN_XVFB_FIRST": value})


def test_a_program_under_it_gets_a_display_from_the_first_number_on(tmp_path):
    if shutil.which("xvfb-run") is None:
        pytest.skip("xvfb-run is not installed")
    # A number nothing else here uses; -a moves on past it only if its lock file exists.
    first = 4321
    done = subprocess.run([*xvfb_run("320x240", {"WAFERSCAN_XVFB_FIRST": str(first)}), "sh",
                           "-c", 'echo "$DISPLAY"'], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    display = int(done.stdout.strip().lstrip(":"))
    assert first <= display < first + 10
