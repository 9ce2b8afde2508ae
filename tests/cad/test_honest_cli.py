"""Honest results through the command line and FreeCAD (issue 9): crosscheck with sensor lag and
with grazing edges, a [robot] that contradicts [sensor], warnings on stderr, in JSON and in
results.txt, JSON wafers in the input's order, and demo --engine paper."""

import json

import pytest
from commands import waferscan
from scenarios import PAPER, paper_with
from scenarios import PAPER_CODE as CODE


def line_of(path, start):
    return next(i for i, line in enumerate(path.read_text().splitlines(), start=1)
                if line.startswith(start))


# --- crosscheck -------------------------------------------------------------------------------

def test_crosscheck_confirms_a_scan_with_sensor_lag(tmp_path):
    # 100 mm/s x 2 ms: every IN and OUT latched 0.2 mm above where the beam was blocked.
    lagged = paper_with(tmp_path, 'direction = "up"',
                        'direction = "up"\nscan_speed = 100.0\nsensor_response = 0.002', "lag.toml")
    scan = json.loads(waferscan("scan", lagged, "--json").stdout)
    exact = json.loads(waferscan("scan", PAPER, "--json").stdout)
    for mine, theirs in zip(scan["runs"], exact["runs"]):
        assert mine["in"] == pytest.approx(theirs["in"] + 0.2, abs=1e-9)
    done = waferscan("crosscheck", lagged, "--json")
    assert done.returncode == 0, done.stdout + done.stderr
    data = json.loads(done.stdout)
    assert data["ok"] is True and data["code"] == CODE
    assert all(r["blocked_at_edges"] and r["clear_outside"] for r in data["runs"])
    assert [r["in"] for r in data["runs"]] == [r["in"] for r in scan["runs"]]


GRAZING = """
# A beam tilted 45 degrees that passes 149.88 mm from a level wafer's axis (R = 150 mm): where
# it first and last meets the wafer it grazes the rim, whose chord there is 2*sqrt(150^2 -
# 149.88^2) = 12.0 mm; the distance to the solid then grows only ~0.04 mm per mm of travel.
[scan]
start_z = 180.0
final_z = 220.0
z_step = 0.05
[sensor]
emitter = [-100.0, 250.12, 180.0]
direction = [1.0, 0.0, 1.0]
length = 200.0
[[carrier]]
name = "A"
slots = 1
pitch = 10.0
first_slot_z = 300.0
center = [0.0, 400.0]
wafer_diameter = 300.0
wafer_thickness = 0.775
load = "0"
[[wafer]]
name = "G"
center = [0.0, 400.0, 300.0]
normal = [0.0, 0.0, 1.0]
diameter = 300.0
thickness = 0.775
"""


def test_crosscheck_allows_grazing_edges_what_the_touching_tolerance_explains(tmp_path):
    path = tmp_path / "graze.toml"
    path.write_text(GRAZING)
    done = waferscan("crosscheck", path, "--json")
    assert done.returncode == 0, done.stdout
    data = json.loads(done.stdout)
    (wafer,) = data["wafers"]
    # OpenCASCADE (1e-7 mm touching) finds each edge about 1e-7 / slope outside the geometric
    # one: more than the 1e-6 mm that would fail it, less than what is allowed.
    assert 1e-6 < wafer["deviation"] <= wafer["allowed"]
    assert wafer["allowed"] == pytest.approx(2 * max(wafer["touch_shift"]))
    assert 1e-6 < max(wafer["touch_shift"]) < 1e-5
    # The geometric edges, independently: the beam's line is y = 250.12, z = zs + (x + 100),
    # and inside the rim where |x| <= chord; it meets the wafer (300 <= z <= 300.775) for
    # zs in [200 - chord, 200.775 + chord].
    chord = (150.0 ** 2 - 149.88 ** 2) ** 0.5
    assert wafer["edges"][0] == pytest.approx(200.0 - chord, abs=1e-9)
    assert wafer["edges"][1] == pytest.approx(200.775 + chord, abs=1e-9)
    assert data["allowed_deviation"] == wafer["allowed"]
    text = waferscan("crosscheck", path).stdout
    assert "allowed" in text and "confirmed by FreeCAD's B-rep geometry" in text


def test_crosscheck_keeps_a_micrometre_where_the_beam_meets_wafers_squarely():
    data = json.loads(waferscan("crosscheck", PAPER, "--json").stdout)
    assert data["ok"] is True
    assert all(w["allowed"] == 1e-6 for w in data["wafers"])
    assert all(w["deviation"] <= 1e-6 for w in data["wafers"])


def test_a_square_edge_off_by_two_micrometres_is_not_confirmed():
    from waferscan.cad.crosscheck import EdgeCheck

    assert not EdgeCheck("W", (300.0, 300.7), (300.0 - 2e-6, 300.7), (1e-7, 1e-7)).ok
    assert EdgeCheck("W", (300.0, 300.7), (300.0 - 2e-6, 300.7), (2.5e-6, 1e-7)).ok


# --- a [robot] that contradicts [sensor] ----------------------------------------------------

def test_a_robot_refuses_a_different_beam_length(tmp_path):
    path = paper_with(tmp_path, "length = 160.0", "length = 180.0", "long.toml")
    done = waferscan("scan", path)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith(f"waferscan: error: {path}:{line_of(path, 'length')}: ")
    assert "180 mm" in done.stderr and "160 mm" in done.stderr


def test_a_robot_refuses_a_lift_axis_it_does_not_have(tmp_path):
    path = paper_with(tmp_path, "length = 160.0",
                      "length = 160.0\nlift_axis = [0, 0.05, 1]", "tilted.toml")
    done = waferscan("scan", path)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith(f"waferscan: error: {path}:{line_of(path, 'lift_axis')}: ")
    assert "[0, 0.0499376, 0.998752]" in done.stderr and "[0, 0, 1]" in done.stderr


def test_without_a_robot_the_lift_axis_is_used(tmp_path):
    text = PAPER.read_text()
    text = text[:text.index("[robot]")] + text[text.index("[[carrier]]"):]
    plain = tmp_path / "plain.toml"
    plain.write_text(text)
    tilted = tmp_path / "tilted.toml"
    tilted.write_text(text.replace("length = 160.0", "length = 160.0\nlift_axis = [0, 0.05, 1]"))
    straight = json.loads(waferscan("scan", plain, "--json").stdout)
    leaning = json.loads(waferscan("scan", tilted, "--json").stdout)
    assert straight["code"] == leaning["code"] == CODE
    # The beam drifts towards the wafers' centre as it rises: the cross-slotted wafer's run,
    # whose length is the chord's rise, grows.
    assert leaning["runs"][3]["diff"] > straight["runs"][3]["diff"]


# --- warnings and unscanned slots through the command line ------------------------------------

def test_a_short_coarse_scan_warns_on_stderr_in_json_and_in_results_txt(tmp_path):
    path = paper_with(tmp_path, "final_z = 550.0", "final_z = 450.0", "short.toml")
    path.write_text(path.read_text().replace("z_step = 0.05", "z_step = 2.0"))
    out = tmp_path / "results.txt"
    done = waferscan("scan", path, "--json", "--out", out)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    # Slot 16's window is 438.94..448.94: wholly inside 280..450; slot 17's is not.
    assert data["code"][16:] == "?" * 9
    assert data["e87"][16:] == "0" * 9
    assert len(data["warnings"]) >= 2
    assert done.stderr.splitlines() == [f"waferscan: warning: {w}" for w in data["warnings"]]
    header = out.read_text().split("\n\n", 1)[0].splitlines()
    assert [h for h in header if h.startswith("warning = ")] == \
        [f"warning = {w}" for w in data["warnings"]]
    assert f"code = {data['code']}" in header


def test_the_paper_experiment_has_no_warnings():
    done = waferscan("scan", PAPER, "--json")
    assert done.stderr == ""
    assert json.loads(done.stdout)["warnings"] == []


def test_json_wafers_keep_the_scenarios_order(tmp_path):
    path = tmp_path / "order.toml"
    path.write_text("""
[scan]
carrier = "A"
start_z = 90.0
final_z = 200.0
[sensor]
emitter = [-80.0, 266.6, 90.0]
direction = [1.0, 0.0, 0.0]
length = 160.0
[[carrier]]
name = "A"
slots = 10
first_slot_z = 100.0
center = [0.0, 400.0]
load = "1100000000"
[[carrier]]
name = "B"
slots = 10
first_slot_z = 100.0
center = [0.0, 1400.0]
load = "1000000000"
[[wafer]]
name = "FREE_B"
carrier = "B"
center = [0.0, 1400.0, 150.0]
normal = [0.0, 0.0, 1.0]
diameter = 300.0
thickness = 0.775
[[wafer]]
name = "FREE_A"
carrier = "A"
center = [0.0, 400.0, 160.0]
normal = [0.0, 0.0, 1.0]
diameter = 300.0
thickness = 0.775
[[wafer]]
name = "LOOSE"
center = [0.0, 400.0, 170.0]
normal = [0.0, 0.0, 1.0]
diameter = 300.0
thickness = 0.775
""")
    from waferscan.core.files.scenario import read_scenario

    expected = [w.name for w in read_scenario(path).wafers]
    assert expected == ["A_W01", "A_W02", "B_W01", "FREE_B", "FREE_A", "LOOSE"]
    data = json.loads(waferscan("scan", path, "--json").stdout)
    assert [w["name"] for w in data["wafers"]] == expected
    assert data["code"] == "1100001100"
    saved = tmp_path / "order.FCStd"
    assert waferscan("layout", path, "-o", saved).returncode == 0
    data = json.loads(waferscan("scan", saved, "--json").stdout)
    assert [w["name"] for w in data["wafers"]] == expected


# --- demo --engine paper -----------------------------------------------------------------------

def test_demo_with_the_papers_engine_shows_where_and_why_it_differs():
    done = waferscan("demo", "--engine", "paper")
    assert done.returncode == 0, done.stdout
    lines = done.stdout.splitlines()
    assert f"code {CODE}" in lines
    differ = [line for line in lines if "tilted wafer" in line]
    assert [line.split()[0] for line in differ] == ["LP1_W04", "LP1_W07"]
    assert "ignores its 0.7 mm thickness" in differ[0]
    assert sum(line.startswith("[ok]") for line in lines) == 4
    assert not any(line.startswith("[FAIL]") for line in lines)
    assert any(line.startswith("[paper differs]") and "cross-slotted" in line for line in lines)


def test_crosscheck_confirms_random_layouts_with_grazing_edges():
    # Random layouts (tilted wafers and beams, tilted lifts); some of their edges graze a rim,
    # where OpenCASCADE finds the edge more than 1e-6 mm away from the exact one.
    import random

    import FreeCAD as App

    from random_layouts import random_layout

    from waferscan.cad.builder import build_document
    from waferscan.cad.crosscheck import crosscheck

    checks = {}
    for seed in range(80, 101):
        layout = random_layout(random.Random(seed), max_steps=600)
        doc = build_document(layout, name=f"Random{seed}")
        try:
            checks[seed] = crosscheck(doc)
        finally:
            App.closeDocument(doc.Name)
    assert [seed for seed, check in checks.items() if not check.ok] == []
    wafers = [w for check in checks.values() for w in check.wafers]
    assert sum(w.deviation > 1e-6 for w in wafers) >= 2
    # More than 1e-6 mm is allowed only where the touching tolerance moves the edge far.
    assert all(w.allowed == 1e-6 or max(w.touch_shift) > 5e-7 for w in wafers)
