"""The command line as a user meets it: bad input gives exit status 2 and one line naming the
file and line; options are honoured; files already there are never half-written or lost."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from waferscan.core.mcs import apply_parameters, read_parameters
from waferscan.core.scenario import read_scenario

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "resources" / "examples" / "paper.toml"
CODE = "1101221001220001010000010"


def waferscan(*args):
    return subprocess.run([sys.executable, "-m", "waferscan.cli", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def assert_input_error(done, prefix):
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"waferscan: error: {prefix}"), done.stderr
    assert "Traceback" not in done.stderr


@pytest.fixture
def bad_params(tmp_path):
    path = tmp_path / "parameters.txt"
    path.write_text("# MCS values\nz_step = 0.05\nspead = 100\n")
    return path


def test_bad_scenario_value(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(PAPER.read_text().replace("z_step = 0.05", "z_step = -1"))
    line = next(i for i, l in enumerate(bad.read_text().splitlines(), 1) if "z_step" in l)
    assert_input_error(waferscan("scan", bad), f"{bad}:{line}: [scan] z_step: must not be negative")


def test_unknown_parameter_key(bad_params):
    assert_input_error(waferscan("scan", PAPER, "--params", bad_params),
                       f"{bad_params}:3: unknown key 'spead'")


@pytest.mark.parametrize("args, prefix", [
    (["scan", "/no/such.toml"], "/no/such.toml: cannot read the scenario"),
    (["scan", "layout.step"], "layout.step: expected a scenario .toml or a FreeCAD layout"),
    (["crosscheck", "/no/such.FCStd"], "/no/such.FCStd: no such file"),
])
def test_missing_files_and_unknown_suffixes(args, prefix):
    assert_input_error(waferscan(*args), prefix)


def test_exact_mode_needs_the_analytic_engine(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("z_step = 0\n")
    assert_input_error(waferscan("scan", PAPER, "--params", params, "--engine", "loop"),
                       f"{PAPER}: z_step = 0 asks for exact edges")
    done = waferscan("scan", PAPER, "--params", params, "--json")
    assert done.returncode == 0
    runs = json.loads(done.stdout)["runs"]
    assert runs[0]["in"] == pytest.approx(293.94, abs=1e-8)


def test_usage_errors_exit_2():
    for args in (["scan"], ["bogus"], ["scan", str(PAPER), "--engine", "magic"], []):
        done = waferscan(*args)
        assert done.returncode == 2
        assert "waferscan: error:" in done.stderr and "Traceback" not in done.stderr


def test_params_are_honoured(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("z_step = 0.1\ndirection = down\n")
    data = json.loads(waferscan("scan", PAPER, "--params", params, "--json").stdout)
    assert (data["params"]["z_step"], data["params"]["direction"]) == (0.1, "down")
    assert data["code"] == CODE
    first = data["runs"][0]
    assert first["in"] > first["out"]  # a down stroke meets the top first
    assert data["params"]["start_z"] == 280.0  # what the file leaves out keeps the layout's


def test_out_is_written_and_a_failed_scan_leaves_it_untouched(tmp_path, bad_params):
    out = tmp_path / "results.txt"
    assert waferscan("scan", PAPER, "--out", out).returncode == 0
    text = out.read_text()
    assert "status = ok" in text and f"code = {CODE}" in text
    assert waferscan("scan", PAPER, "--params", bad_params, "--out", out).returncode == 2
    assert out.read_text() == text


def test_demo_writes_the_three_mcs_files(tmp_path):
    done = waferscan("demo", "--out", tmp_path)
    assert done.returncode == 0 and CODE in done.stdout
    assert done.stdout.count("[ok]") == 4
    layout = apply_parameters(read_scenario(PAPER), read_parameters(tmp_path / "parameters.txt"))
    assert layout.scan == read_scenario(PAPER).scan
    assert (tmp_path / "commands.txt").read_text() == "1 SCF\n"
    results = (tmp_path / "results.txt").read_text()
    assert results.startswith("seq = 1\ncommand = SCF\nstatus = ok\n")
    assert f"code = {CODE}\n" in results and "engine = document\n" in results


def test_demo_json():
    data = json.loads(waferscan("demo", "--json").stdout)
    assert set(data) >= {"code", "e87", "slots", "runs", "wafers", "params", "engine"}
    assert data["code"] == CODE and len(data["slots"]) == 25 and data["engine"] == "document"
    assert len(data["runs"]) == 10 and len(data["wafers"]) == 10
