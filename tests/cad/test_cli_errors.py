"""The command line as a user meets it (SPEC §7): bad input gives exit status 2 and one line
naming the file and line; options are honoured; files already there are never half-written."""

import json

import pytest
from commands import waferscan
from scenarios import PAPER
from scenarios import PAPER_CODE as CODE
from scenarios import PAPER_E87 as E87

from waferscan.core.files.mcs import apply_parameters, read_parameters, used_parameters
from waferscan.core.files.scenario import read_scenario


def assert_input_error(done, prefix):
    assert done.returncode == 2, done.stderr
    assert done.stderr.endswith("\n") and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"waferscan: error: {prefix}"), done.stderr
    assert "Traceback" not in done.stderr
    assert done.stdout == ""


def header(text):
    """The key = value lines of a results.txt, as a dict."""
    head = text.split("\n\n", 1)[0]
    return dict((line.split(" =", 1)[0], line.split(" =", 1)[1].strip())
                for line in head.splitlines())


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
    assert_input_error(waferscan("scan", bad, "--json"), f"{bad}:{line}: ")
    assert_input_error(waferscan("crosscheck", bad), f"{bad}:{line}: ")
    assert_input_error(waferscan("layout", bad, "-o", tmp_path / "x.FCStd"), f"{bad}:{line}: ")
    assert not (tmp_path / "x.FCStd").exists()


def test_bad_scenario_syntax(tmp_path):
    bad = tmp_path / "syntax.toml"
    text = PAPER.read_text().replace("length = 160.0", "length = = 160.0")
    bad.write_text(text)
    line = next(i for i, l in enumerate(text.splitlines(), 1) if "length = =" in l)
    assert_input_error(waferscan("scan", bad), f"{bad}:{line}: not valid TOML")


def test_unknown_parameter_key(bad_params):
    assert_input_error(waferscan("scan", PAPER, "--params", bad_params),
                       f"{bad_params}:3: unknown key 'spead'")


def test_impossible_parameter_value(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("\ufeffstart_z = 280\r\nfinal_z = 100\r\n")
    assert_input_error(waferscan("scan", PAPER, "--params", params),
                       f"{params}:2: final_z: final_z (100) is below start_z (280)")


@pytest.mark.parametrize("args, prefix", [
    (["scan", "/no/such.toml"], "/no/such.toml: cannot read the scenario"),
    (["scan", "/no/such.FCStd"], "/no/such.FCStd: no such file"),
    (["scan", "layout.step"], "layout.step: expected a scenario .toml or a FreeCAD layout"),
    (["scan", "resources/examples"], "resources/examples: expected a scenario .toml"),
    (["crosscheck", "/no/such.FCStd"], "/no/such.FCStd: no such file"),
    (["layout", "/no/such.toml", "-o", "/tmp/never.FCStd"], "/no/such.toml: cannot read"),
    (["scan", str(PAPER), "--params", "/no/parameters.txt"], "/no/parameters.txt: cannot read"),
    (["scan", str(PAPER), "--out", "/no/such/folder/results.txt"],
     "/no/such/folder/results.txt: cannot write"),
])
def test_missing_files_and_unknown_suffixes(args, prefix):
    assert_input_error(waferscan(*args), prefix)


def test_layout_output_errors(tmp_path):
    assert_input_error(waferscan("layout", PAPER, "-o", tmp_path / "x.step"),
                       f"{tmp_path / 'x.step'}: a FreeCAD layout is saved as .FCStd")
    assert_input_error(waferscan("layout", PAPER, "-o", tmp_path / "no" / "x.FCStd"),
                       f"{tmp_path / 'no' / 'x.FCStd'}: no folder")


def test_a_file_that_is_not_utf8(tmp_path):
    bad = tmp_path / "latin.toml"
    bad.write_bytes(PAPER.read_bytes().replace(b'"LP1"', b'"LP\xe91"', 1))
    assert_input_error(waferscan("scan", bad), f"{bad}:14: not UTF-8 text")


def test_exact_mode_needs_the_analytic_engine(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("z_step = 0\n")
    done = waferscan("scan", PAPER, "--params", params, "--engine", "loop")
    assert_input_error(done, "")
    assert "z_step = 0 asks for exact edges" in done.stderr and "(not loop)" in done.stderr
    done = waferscan("scan", PAPER, "--params", params, "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["params"]["z_step"] == 0.0 and data["code"] == CODE
    assert data["runs"][0]["in"] == pytest.approx(293.94, abs=1e-8)
    assert data["runs"][0]["diff"] == pytest.approx(0.7, abs=1e-8)


def test_exact_mode_error_names_the_parameters_line(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("z_step = 0\n")
    assert_input_error(waferscan("scan", PAPER, "--params", params, "--engine", "loop"),
                       f"{params}:1: ")


def test_an_overflowing_scan_range_is_bad_input(tmp_path):
    bad = tmp_path / "tiny.toml"
    bad.write_text(PAPER.read_text().replace("z_step = 0.05", "z_step = 1e-320"))
    assert_input_error(waferscan("scan", bad), f"{bad}:17: ")


@pytest.mark.parametrize("args", [["scan"], ["bogus"], [], ["scan", str(PAPER), "--engine", "magic"],
                                  ["scan", str(PAPER), "--mode", "medium"],
                                  ["layout", str(PAPER)], ["demo", "--frobnicate"]])
def test_usage_errors_exit_2(args):
    done = waferscan(*args)
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines()[-1].startswith("waferscan: error: ")
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_params_are_honoured(tmp_path):
    params = tmp_path / "parameters.txt"
    params.write_text("# from the MCS\nz_step = 0.1\ndirection = down\n")
    done = waferscan("scan", PAPER, "--params", params, "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert (data["params"]["z_step"], data["params"]["direction"]) == (0.1, "down")
    assert data["code"] == CODE
    first = data["runs"][0]
    assert first["in"] > first["out"]  # a down stroke meets a wafer's top first
    assert (first["in"] * 10) == pytest.approx(round(first["in"] * 10))  # on the 0.1 mm grid
    assert data["params"]["start_z"] == 280.0  # what the file leaves out keeps the layout's
    # --direction on the command line beats the file
    data = json.loads(waferscan("scan", PAPER, "--params", params, "--direction", "up",
                                "--json").stdout)
    assert data["params"]["direction"] == "up" and data["params"]["z_step"] == 0.1
    assert data["runs"][0]["in"] < data["runs"][0]["out"]


def test_out_is_written_and_a_failed_scan_leaves_it_untouched(tmp_path, bad_params):
    out = tmp_path / "results.txt"
    done = waferscan("scan", PAPER, "--out", out)
    assert done.returncode == 0, done.stderr
    text = out.read_text()
    head = header(text)
    assert (head["seq"], head["command"], head["status"], head["message"]) == ("", "SCF", "ok", "")
    assert (head["code"], head["e87"], head["engine"]) == (CODE, E87, "analytic")
    assert set(used_parameters(read_scenario(PAPER))) <= set(head)
    table = text.split("\n\n", 1)[1].splitlines()
    assert table[0] == "slot\tslot_z\twafer\tin\tout\tdiff\tstate"
    assert len(table) == 26 and all(row.count("\t") == 6 for row in table)
    assert table[1] == "1\t293.940\tLP1_W01\t293.950\t294.600\t0.650\tpresent"
    assert text.endswith("\n") and not text.endswith("\n\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["parameters.txt", "results.txt"]

    assert_input_error(waferscan("scan", PAPER, "--params", bad_params, "--out", out),
                       f"{bad_params}:3: ")
    assert out.read_text() == text
    bad = tmp_path / "bad.toml"
    bad.write_text(PAPER.read_text().replace("length = 160.0", "length = 0"))
    assert_input_error(waferscan("scan", bad, "--out", out), f"{bad}:")
    assert out.read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "parameters.txt",
                                                           "results.txt"]


def test_slow_mode_out_says_scs(tmp_path):
    out = tmp_path / "results.txt"
    assert waferscan("scan", PAPER, "--mode", "slow", "--out", out).returncode == 0
    head = header(out.read_text())
    assert (head["command"], head["mode"], head["code"]) == ("SCS", "slow", CODE)


def test_demo_writes_the_three_mcs_files(tmp_path):
    folder = tmp_path / "mcs"  # made by the demo
    done = waferscan("demo", "--out", folder)
    assert done.returncode == 0, done.stderr
    assert CODE in done.stdout and done.stdout.count("[ok]") == 4 and "FAIL" not in done.stdout
    assert sorted(p.name for p in folder.iterdir()) == ["commands.txt", "parameters.txt",
                                                        "results.txt"]
    paper = read_scenario(PAPER)
    layout = apply_parameters(paper, read_parameters(folder / "parameters.txt"))
    assert layout.scan == paper.scan and layout.scanned_carrier == paper.scanned_carrier
    assert used_parameters(layout) == used_parameters(paper)
    assert (folder / "commands.txt").read_bytes() == b"1 SCF\n"
    results = (folder / "results.txt").read_text()
    head = header(results)
    assert (head["seq"], head["command"], head["status"], head["code"], head["e87"],
            head["engine"]) == ("1", "SCF", "ok", CODE, E87, "document")
    assert results.startswith("seq = 1\ncommand = SCF\nstatus = ok\nmessage =\n")
    rows = results.split("\n\n", 1)[1].splitlines()[1:]
    states = "".join({"empty": "0", "present": "1", "cross-slotted": "2"}[r.split("\t")[6]]
                     for r in rows)
    assert states == CODE
    assert rows[4] == "5\t333.940\tLP1_W04\t336.600\t341.950\t5.350\tcross-slotted"
    assert rows[10] == "11\t393.940\tLP1_W07\t396.600\t401.950\t5.350\tcross-slotted"


def test_demo_out_onto_a_file_is_bad_input(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("keep\n")
    assert_input_error(waferscan("demo", "--out", blocker), f"{blocker}: cannot make the folder")
    assert blocker.read_text() == "keep\n"


def test_demo_json():
    done = waferscan("demo", "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)  # one JSON object and nothing else on stdout
    assert {"code", "e87", "slots", "runs", "wafers", "params", "engine"} <= set(data)
    assert (data["code"], data["e87"], data["engine"]) == (CODE, E87, "document")
    assert [s["slot"] for s in data["slots"]] == list(range(1, 26))
    assert [s["state"] for s in data["slots"]] == [int(c) for c in CODE]
    assert data["slots"][0]["z"] == pytest.approx(293.94)
    assert len(data["runs"]) == 10
    assert [w["name"] for w in data["wafers"]] == [f"LP1_W{i:02d}" for i in range(1, 11)]
    assert data["params"] == used_parameters(read_scenario(PAPER))
