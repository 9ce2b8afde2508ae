"""The addon installed as FreeCAD's Addon Manager installs it: a git clone in the Mod folder of
a fresh FreeCAD user folder, no `make setup`, so no venv and no pinocchio. FreeCAD must say
once, at start-up, that pinocchio is missing and how to install it; a scenario without a robot
must scan and cross-check; a scenario with one must fail with that message in one line."""

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from commands import waferscan
from processes import RUN_VARIABLE, run_in_own_group
from scenarios import PAPER
from scenarios import ROOT as REPO

from waferscan.bench.xvfb import xvfb_run

FREECADCMD = shutil.which("freecadcmd")
FREECAD = shutil.which("freecad")
GIT = shutil.which("git")
GUI_PROBE = Path(__file__).resolve().with_name("addon_manager_gui_probe.py")

pytestmark = pytest.mark.skipif(FREECADCMD is None or GIT is None,
                                reason="needs FreeCAD (freecadcmd) and git")

# What a clone of the repository holds: the working tree without what .gitignore keeps out
# (the venv, build output, caches) and without .git. Copied rather than cloned from REPO, so
# that the test sees the working tree (uncommitted changes too) and also works where REPO's
# git folder is out of reach (a worktree seen from the FreeCAD 1.0 root).
NOT_IN_A_CLONE = shutil.ignore_patterns(".git", ".venv", ".fchome", "build", "test-artifacts",
                                        "__pycache__", ".pytest_cache", ".hypothesis",
                                        "*.egg-info", ".benchmarks")

# Runs in freecadcmd, where FreeCAD has run the clone's Init.py. The command line's main(),
# called here, runs the clone's code on FreeCAD's Python, as the workbench's commands do.
PROBE = r"""
import contextlib, io, json, os, sys
import FreeCAD
import waferscan, waferscan.addon, waferscan.cli

def run(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = waferscan.cli.main(list(args))
        except SystemExit as exc:
            status = exc.code
    return {"status": status, "stdout": out.getvalue(), "stderr": err.getvalue()}

result = {
    "user_data": FreeCAD.getUserAppDataDir(),
    "waferscan_file": os.path.realpath(waferscan.__file__),
    "venv_site_packages": waferscan.addon.venv_site_packages(),
    "scan": run("scan", ROBOTLESS, "--json"),
    "crosscheck": run("crosscheck", ROBOTLESS, "--json"),
    "robot_scan": run("scan", PAPER),
}
print("WS_RESULT=" + json.dumps(result))
"""


def _freecad_env(home):
    """A FreeCAD with a fresh user folder and nothing of the project's set-up: no venv (not
    WAFERSCAN_VENV either), no PYTHONPATH; only the test run's mark (tests/processes.py)."""
    return {"PATH": "/usr/bin:/bin", "HOME": str(home), "FREECAD_USER_HOME": str(home),
            "LANG": "C.UTF-8", RUN_VARIABLE: os.environ[RUN_VARIABLE]}


def _user_data_dir(home):
    proc = subprocess.run([FREECADCMD, "-c", "import FreeCAD; print('WS_USER=' + "
                           "FreeCAD.getUserAppDataDir())"], capture_output=True, text=True,
                          timeout=120, stdin=subprocess.DEVNULL, cwd=home, env=_freecad_env(home))
    found = re.findall(r"^WS_USER=(.*)$", proc.stdout, re.MULTILINE)
    assert found, f"{proc.stdout}\n{proc.stderr}"
    return Path(found[-1])


def _robotless(scenario_text):
    """The scenario without its [robot] table (the table runs up to the next header)."""
    return re.sub(r"^\[robot\]\n(?:(?!\[).*\n)*", "", scenario_text, flags=re.MULTILINE)


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("addon-manager")
    home = tmp / "home"
    home.mkdir()
    # A repository of the working tree, cloned into the Mod folder as the Addon Manager does.
    source = tmp / "source"
    shutil.copytree(REPO, source, ignore=NOT_IN_A_CLONE, symlinks=True)
    git_env = dict(os.environ, GIT_AUTHOR_NAME="t", GIT_AUTHOR_EMAIL="t@example.invalid",
                   GIT_COMMITTER_NAME="t", GIT_COMMITTER_EMAIL="t@example.invalid")
    for command in (["init", "-q"], ["add", "-A"], ["commit", "-q", "-m", "snapshot"]):
        subprocess.run([GIT, *command], cwd=source, env=git_env, check=True,
                       capture_output=True)
    mod = _user_data_dir(home) / "Mod"
    mod.mkdir(parents=True)
    clone = mod / "WaferScan"
    subprocess.run([GIT, "clone", "-q", str(source), str(clone)], check=True, capture_output=True)

    robotless = tmp / "robotless.toml"
    robotless.write_text(_robotless(PAPER.read_text(encoding="utf-8")), encoding="utf-8")
    probe = PROBE.replace("ROBOTLESS", repr(str(robotless))).replace("PAPER", repr(str(PAPER)))
    proc = subprocess.run([FREECADCMD, "-c", probe], capture_output=True, text=True,
                          timeout=300, stdin=subprocess.DEVNULL, cwd=tmp, env=_freecad_env(home))
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("WS_RESULT=")]
    assert proc.returncode == 0 and lines, f"freecadcmd failed:\n{proc.stdout}\n{proc.stderr}"
    return {"clone": clone, "robotless": robotless, "output": proc.stdout + proc.stderr,
            **json.loads(lines[-1][len("WS_RESULT="):])}


@pytest.fixture(scope="module")
def pinocchio_missing(installed):
    if installed["robot_scan"]["status"] == 0:
        pytest.skip("this FreeCAD's Python has pinocchio of its own (installed system-wide)")


def test_freecad_runs_the_clone_without_a_venv(installed):
    assert Path(installed["waferscan_file"]) == installed["clone"] / "waferscan" / "__init__.py"
    assert (installed["clone"] / ".git").is_dir() and not (installed["clone"] / ".venv").exists()
    assert installed["venv_site_packages"] is None


def test_startup_says_once_that_pinocchio_is_missing(installed, pinocchio_missing):
    warnings = [ln for ln in installed["output"].splitlines() if "WaferScan: pinocchio" in ln]
    assert len(warnings) == 1, installed["output"]
    assert f"make -C '{installed['clone']}' setup" in warnings[0]


def test_a_robot_scenario_fails_with_the_fix_in_one_line(installed, pinocchio_missing):
    robot_scan = installed["robot_scan"]
    assert robot_scan["status"] == 2
    assert robot_scan["stdout"] == ""
    (line,) = robot_scan["stderr"].splitlines()
    assert line.startswith("waferscan: error: robot: pinocchio (pip package pin==")
    assert f"run: make -C '{installed['clone']}' setup" in line
    assert "Traceback" not in installed["output"]


def _load_string():
    import tomllib

    return tomllib.loads(PAPER.read_text(encoding="utf-8"))["carrier"][0]["load"]


def test_a_robotless_scenario_scans_as_in_the_venv(installed):
    scan = installed["scan"]
    assert scan["status"] == 0, scan["stderr"]
    ours = json.loads(scan["stdout"])
    # The slot code is the carrier's load string: what was built is what is mapped.
    assert ours["code"] == _load_string()
    # The same scan by the project's own set-up (the venv, with pinocchio): the same runs.
    reference = waferscan("scan", installed["robotless"], "--json")
    reference.check_returncode()
    assert ours["runs"] == json.loads(reference.stdout)["runs"]


def test_a_robotless_scenario_crosschecks(installed):
    crosscheck = installed["crosscheck"]
    assert crosscheck["status"] == 0, crosscheck["stderr"]
    report = json.loads(crosscheck["stdout"])
    assert report["ok"] is True and report["code"] == _load_string()


def test_in_the_gui_a_robot_layout_gives_the_message_and_a_robotless_one_builds(
        installed, pinocchio_missing):
    if FREECAD is None or shutil.which("xvfb-run") is None:
        pytest.skip("needs the FreeCAD GUI (freecad) and xvfb-run")
    result_file = installed["robotless"].with_name("gui-result.json")
    env = dict(_freecad_env(installed["clone"].parents[1]), QTWEBENGINE_DISABLE_SANDBOX="1",
               WAFERSCAN_GUI_RESULT=str(result_file),
               WAFERSCAN_GUI_PROBES=str(REPO / "tests" / "gui"),
               WAFERSCAN_ROBOTLESS=str(installed["robotless"]))
    command = [*xvfb_run("1400x1000"), FREECAD, "-u", str(result_file.with_name("user.cfg")),
               str(GUI_PROBE)]
    _, output, timed_out = run_in_own_group(command, timeout=180, env=env)
    if timed_out:
        pytest.fail(f"FreeCAD GUI did not quit within 180 s:\n{output}")
    assert result_file.exists(), f"the probe wrote no result:\n{output}"
    result = json.loads(result_file.read_text(encoding="utf-8"))
    assert result["ok"], result.get("error")
    assert Path(result["waferscan_file"]) == installed["clone"] / "waferscan" / "__init__.py"
    (message,) = result["messages"]
    assert message.startswith("robot: pinocchio (pip package pin==")
    assert f"make -C '{installed['clone']}' setup" in message
    assert result["documents_after_robot"] == []  # no half-built layout left open
    load = _load_string()
    assert result["wafers"] == load.count("1") + load.count("22")  # "22": one wafer, two slots
    assert result["robots"] == 0
    assert "Traceback" not in output
