"""`waferscan calibrate` and the MCS link's CAL (SPEC §11) as a user and an MCS meet them: the
recipe printed and written (atomically, accepted as-is by `waferscan scan --params` and the
link), the exit status of each failure, and results.txt of a CAL."""

import pytest
from commands import waferscan as run
from scenarios import ROOT, drifted_paper

from waferscan.core.files.mcs import parse_parameters

LOAD = "1100100001000010000100011"
TAUGHT = "first_slot_z = 293.94\nslot_pitch = 10.0\n"


def scenario(folder, load=LOAD, name="drifted.toml"):
    """The paper's carrier with its slot 1 0.3 mm above the taught seat and a 10.02 mm pitch."""
    path = folder / name
    path.write_text(drifted_paper(load))
    return path


def header(text):
    """results.txt's header as a dict."""
    lines = text.split("\n\n")[0].splitlines()
    return {line.partition(" =")[0]: line.partition(" =")[2].strip() for line in lines}


def test_calibrate_prints_and_writes_a_recipe_that_scan_accepts_as_is(tmp_path):
    drifted = scenario(tmp_path)
    taught = tmp_path / "taught.txt"
    taught.write_text(TAUGHT)
    before = run("scan", drifted, "--params", taught)
    assert before.returncode == 0 and f"code {LOAD}" not in before.stdout  # misread: 5s
    recipe = tmp_path / "recipe.txt"
    done = run("calibrate", drifted, "--params", taught, "--out", recipe)
    assert done.returncode == 0, done.stderr
    assert f"check scan code {LOAD}" in done.stdout
    assert "first_slot_z                 293.940         294.240" in done.stdout
    values = parse_parameters(recipe.read_text(), str(recipe)).values
    assert values["first_slot_z"] == pytest.approx(294.24, abs=0.05)
    assert values["slot_pitch"] == pytest.approx(10.02, abs=0.05 / 24)
    assert values["thickness_correction"] == pytest.approx(0.675 / 0.7)
    after = run("scan", drifted, "--params", recipe)
    assert after.returncode == 0, after.stderr
    assert f"code {LOAD}" in after.stdout and not after.stderr  # no warning: all scanned
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temp left


@pytest.mark.parametrize("load, recipe, status, words", [
    ("0100100001000010000100011", TAUGHT, 3, "no-bottom-wafer: no wafer in the bottom slot"),
    ("1100100001000010000100010", TAUGHT, 4, "no-top-wafer: no wafer in the top slot"),
    (LOAD, TAUGHT + "thickness_min = 0.64\nthickness_max = 0.71\n", 5,
     "check-failed: check scan failed: slot 1 read 3 (double) (code 3"),
])
def test_each_failure_has_its_exit_status_and_leaves_the_recipe_file_alone(tmp_path, load,
                                                                          recipe, status, words):
    drifted = scenario(tmp_path, load)
    taught = tmp_path / "taught.txt"
    taught.write_text(recipe)
    out = tmp_path / "recipe.txt"
    out.write_text("# the recipe in use\n")
    done = run("calibrate", drifted, "--params", taught, "--out", out)
    assert done.returncode == status
    assert done.stderr.startswith(f"waferscan: calibration failed: {words}")
    assert done.stdout == "" and "Traceback" not in done.stderr
    assert out.read_text() == "# the recipe in use\n"


def test_bad_input_is_status_2(tmp_path):
    drifted = scenario(tmp_path)
    taught = tmp_path / "taught.txt"
    taught.write_text("thickness_min = 0.9\nthickness_max = 0.8\n")
    done = run("calibrate", drifted, "--params", taught)
    assert done.returncode == 2
    assert done.stderr == (f"waferscan: error: {taught}:1: thickness_min: thickness_min 0.9 "
                           "must be less than thickness_max 0.8\n")
    done = run("calibrate", tmp_path / "missing.toml")
    assert done.returncode == 2 and done.stderr.startswith("waferscan: error: ")


def test_an_engine_that_cannot_scan_the_layout_is_refused_as_scan_refuses_it(tmp_path):
    """calibrate with exact edges or a beam spot on a stepped engine was an EngineError or a
    ValueError traceback (exit 1); it is the same one-line refusal as waferscan scan's."""
    drifted = scenario(tmp_path)
    exact = tmp_path / "exact.txt"
    exact.write_text("# exact edges\nz_step = 0\n")
    for command in ("calibrate", "scan"):
        done = run(command, drifted, "--params", exact, "--engine", "loop")
        assert done.returncode == 2, done.stderr
        assert done.stderr == (f"waferscan: error: {exact}:2: z_step = 0 asks for exact edges, "
                               "which only the analytic engine gives (not loop)\n")
    spot = tmp_path / "spot.toml"
    spot.write_text(drifted.read_text().replace("[sensor]\n", "[sensor]\nspot_diameter = 2.0\n",
                                                1))
    done = run("calibrate", spot, "--engine", "loop")
    assert done.returncode == 2, done.stderr
    assert done.stderr == (f"waferscan: error: {spot}: a beam spot or latch = step is computed "
                           "by the analytic engine only (not loop)\n")


def test_the_mcs_link_calibrates_on_cal_and_lists_the_recipe(tmp_path):
    drifted = scenario(tmp_path)
    folder = tmp_path / "mcs"
    folder.mkdir()
    (folder / "parameters.txt").write_text(TAUGHT)
    (folder / "commands.txt").write_text("1 CAL\n")
    done = run("watch", folder, "--layout", drifted, "--once")
    assert done.returncode == 0, done.stderr
    answer = header((folder / "results.txt").read_text())
    assert (answer["seq"], answer["command"], answer["status"], answer["code"]) == \
        ("1", "CAL", "ok", LOAD)
    assert answer["message"] == "calibrated from the reference wafers in slots 1 and 25"
    assert float(answer["first_slot_z"]) == pytest.approx(294.24, abs=0.05)
    assert float(answer["slot_pitch"]) == pytest.approx(10.02, abs=0.05 / 24)
    assert float(answer["thickness_correction"]) == pytest.approx(0.675 / 0.7)
    for key in ("start_z", "final_z", "thickness_min", "thickness_max", "double_threshold",
                "position_below", "position_above", "rules"):
        assert answer[key], key
    assert (answer["thickness_min"], answer["double_threshold"], answer["rules"]) == \
        ("0.35", "1.75", "waferscan")
    # issue 24, item 6: at the encoder's 1 µm, without float noise (t + Δt is
    # 1.0499999999999998 in binary; the pitch measured 240.5 / 24 = 10.0208333…)
    assert (answer["thickness_max"], answer["slot_pitch"], answer["first_slot_z"],
            answer["start_z"], answer["final_z"], answer["thickness_correction"]) == \
        ("1.05", "10.021", "294.24", "284.19", "544.79", "0.964286")
    # the table is the check scan's, slot by slot
    table = (folder / "results.txt").read_text().split("\n\n")[1].splitlines()
    assert [row.split("\t")[-1] for row in table[1:]] == \
        ["present" if c == "1" else "empty" for c in LOAD]


def test_a_failed_cal_is_an_error_answer_in_the_failures_words(tmp_path):
    drifted = scenario(tmp_path, "0100100001000010000100011")
    folder = tmp_path / "mcs"
    folder.mkdir()
    (folder / "parameters.txt").write_text(TAUGHT)
    (folder / "commands.txt").write_text("1 CAL\n")
    done = run("watch", folder, "--layout", drifted, "--once")
    assert done.returncode == 0, done.stderr
    text = (folder / "results.txt").read_text()
    answer = header(text)
    assert (answer["command"], answer["status"], answer["code"]) == ("CAL", "error", "")
    assert answer["message"] == ("no-bottom-wafer: no wafer in the bottom slot (slot 1): the "
                                 "lowest run, 0.650 mm at z = 304.290, is nearest slot 2's seat")
    assert "\n\n" not in text  # no table


def test_json_gives_both_recipes_and_the_check_scan_or_the_failure(tmp_path):
    import json

    drifted = scenario(tmp_path)
    taught = tmp_path / "taught.txt"
    taught.write_text(TAUGHT)
    done = run("calibrate", drifted, "--params", taught, "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["status"] == "ok" and data["check"]["code"] == LOAD
    assert data["recipe"]["first_slot_z"]["current"] == 293.94
    assert data["recipe"]["first_slot_z"]["calibrated"] == pytest.approx(294.24, abs=0.05)
    assert data["recipe"]["rules"] == {"current": "waferscan", "calibrated": "waferscan"}
    assert data["check"]["params"]["slot_pitch"] == data["recipe"]["slot_pitch"]["calibrated"]
    # issue 24, item 6: the recipe at 1 µm, the measurement at full precision beside it
    assert data["recipe"]["slot_pitch"]["calibrated"] == 10.021
    assert data["recipe"]["slot_pitch"]["measured"] == pytest.approx(240.5 / 24, abs=1e-12)
    taught.write_text(TAUGHT + "thickness_min = 0.64\nthickness_max = 0.71\n")
    done = run("calibrate", drifted, "--params", taught, "--json")
    assert done.returncode == 5
    failure = json.loads(done.stdout)
    assert (failure["status"], failure["failure"]) == ("error", "check-failed")
    assert failure["message"].startswith("check scan failed: slot 1 read 3 (double)")
    assert failure["code"][0] == "3" and failure["code"][-1] == "1"


CASES = ROOT / "tests" / "data" / "calibration"


@pytest.mark.parametrize("name, status, words", [
    ("double_reference", 3, "no-bottom-wafer: no single wafer in the bottom slot (slot 1): its "
                            "run, 1.550 mm at z = 100.000, is longer than thickness_max 1.1625 mm "
                            "(double or thick)\n"),
    ("thin_references", 3, "no-bottom-wafer: no single wafer in the bottom slot (slot 1): its "
                           "run, "),
    ("high_bottom_reference", 5, "check-failed: check scan failed: slot 2 read 5 (position error) "
                                 "(code 15001)\n"),
    ("stray_below", 3, "no-bottom-wafer: no wafer in the bottom slot (slot 1) can be told: the "
                       "lowest run, 0.750 mm at z = 93.000, lies below slot 1's window (95.000 to "
                       "105.000 mm), in no slot\n"),
    ("double_in_carrier", 5, "check-failed: check scan failed: slot 3 read 3 (double) (code "
                             "10301)\n"),
])
def test_references_that_are_not_references_fail_with_their_status(tmp_path, name, status, words):
    """Issue 24, item 2: each of these calibrated with exit 0 (or named a slot 0)."""
    out = tmp_path / "recipe.txt"
    done = run("calibrate", CASES / f"{name}.toml", "--out", out)
    assert (done.returncode, done.stdout) == (status, "")
    assert done.stderr.startswith(f"waferscan: calibration failed: {words}")
    assert "Traceback" not in done.stderr and not out.exists()
