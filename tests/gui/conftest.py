"""Running a probe script in a real FreeCAD GUI under Xvfb; the probe reports through a JSON
file whose path it gets in WAFERSCAN_GUI_RESULT."""

import json
import os
import shutil
from pathlib import Path

import pytest
from processes import run_in_own_group

from waferscan.bench.xvfb import xvfb_run

FREECAD = shutil.which("freecad")
PROBES = Path(__file__).resolve().parent  # probes import probe_steps from here
TIMEOUT_S = 180


@pytest.fixture(scope="module")
def run_gui_probe(tmp_path_factory):
    """run_gui_probe(probe_path, screen="WxH", **env) -> the probe's JSON result (asserted ok)."""

    def run(probe, screen="1400x1000", **extra_env):
        if FREECAD is None:
            pytest.skip("FreeCAD (freecad) is not installed")
        result_file = tmp_path_factory.mktemp("gui") / "result.json"
        env = dict(os.environ, QTWEBENGINE_DISABLE_SANDBOX="1",
                   WAFERSCAN_GUI_RESULT=str(result_file), WAFERSCAN_GUI_PROBES=str(PROBES),
                   **extra_env)
        # A user config of its own: preferences a probe sets stay out of the user's FreeCAD.
        user_cfg = result_file.with_name("user.cfg")
        command = [*xvfb_run(screen), FREECAD, "-u", str(user_cfg), str(probe)]
        # Own process group: however the probe ends (done, timeout, Ctrl-C), xvfb-run, Xvfb and
        # FreeCAD all go with it.
        returncode, output, timed_out = run_in_own_group(command, timeout=TIMEOUT_S, env=env)
        if timed_out:
            pytest.fail(f"FreeCAD GUI did not quit within {TIMEOUT_S} s:\n{output}")
        assert result_file.exists(), f"the probe wrote no result (rc {returncode}):\n{output}"
        result = json.loads(result_file.read_text(encoding="utf-8"))
        assert result["ok"], result.get("error")
        return result

    return run
