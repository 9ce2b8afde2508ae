"""The sweep's [clearance] report (SPEC §12, §15), its core part (no coal, no Pinocchio): the
[clearance] table, the closed form of the least distance between prisms and drawn wafers
against hand computations and a brute-force projection, the rate and its interval, partitions,
the outputs, and a sweep without [clearance] left as it was. Agreement with coal's
``clearance_for`` on drawn layouts: tests/robot/test_sweep_clearance_coal.py."""

import csv
import json
import math

import numpy as np
import pytest
import scenarios
from scenarios import uniform

from waferscan import cli
from waferscan.core.errors import InputError
from waferscan.core.files.scenario import parse_scenario, read_scenario
from waferscan.core.sweep import draw_block, run_sweep, sweep_base
from waferscan.core.sweep.clearance import (
    ClearanceCheck,
    PrismPart,
    StrokeBody,
    clearance_check,
    least_distances,
    scanner_body,
)
from waferscan.core.sweep.distributions import parse_tolerances
from waferscan.core.sweep.summary import layout_interval, wilson

PAPER = read_scenario(scenarios.PAPER)
NO_ROBOT = parse_scenario(scenarios.PAPER_WITHOUT_ROBOT, "paper-without-robot.toml")

# The bundled robot's fork at paper.toml's taught pose (resources/robots/wafer_robot.urdf: two
# 180 x 20 x 4 mm tines 160 mm apart, their tips at the beam; the palm and the wrist's hub
# behind), over the stroke 280 -> 550 mm: what waferscan.robot.sweep_clearance.stroke_body
# gives (tests/robot checks it does).
FORK = StrokeBody("robot", ("fast stroke up",), (
    PrismPart("palm", (0.0, 36.6), (0.0, 1.0), (50.0, 100.0), 0.0, False, (280.0, 558.0)),
    PrismPart("tine_left", (-80.0, 176.6), (0.0, 1.0), (90.0, 10.0), 0.0, False,
              (280.0, 554.0)),
    PrismPart("tine_right", (80.0, 176.6), (0.0, 1.0), (90.0, 10.0), 0.0, False,
              (280.0, 554.0)),
    PrismPart("wrist_hub", (0.0, 36.6), (1.0, 0.0), (0.0, 0.0), 30.0, False, (280.0, 580.0)),
))
# A wafer centred at (0, 400 - p) (p: its protrusion) is nearest the tines' inner tip corners
# (±70, 266.6): hypot(70, 133.4 - p) - 150 mm.
NOMINAL = math.hypot(70.0, 133.4) - 150.0  # 0.650 mm


def threshold(clearance_min):
    """The protrusion (mm) that brings a level wafer's rim to ``clearance_min`` of the tips."""
    return 133.4 - math.sqrt((150.0 + clearance_min) ** 2 - 70.0 ** 2)


def fixed(quantity, value):
    return f'[{quantity}]\ndist = "fixed"\nvalue = {value!r}\n'


def tolerances(text, clearance="[clearance]\n"):
    return parse_tolerances(text + clearance, "tol.toml")


def report(text, n=600, seed=3, layout=PAPER, body=FORK, **kw):
    return run_sweep(layout, tolerances(text, **kw), n, seed=seed, clearance_body=body)


# --- the tolerance file's [clearance] table ---------------------------------------------------

def test_a_clearance_table_asks_for_the_report_and_may_set_clearance_min():
    assert parse_tolerances(fixed("bow", 0.0)).clearance is None
    assert parse_tolerances("[clearance]\n").clearance.clearance_min is None
    assert parse_tolerances("[clearance]\nclearance_min = 0.8\n").clearance.clearance_min == 0.8


@pytest.mark.parametrize("text, line, words", [
    ("[bow]\ndist = 'fixed'\nvalue = 0.0\n[clearance]\nclearance_max = 1.0\n", 5,
     "unknown key"),
    ("[clearance]\nclearance_min = -1\n", 2, "above 0"),
    ("[clearance]\nclearance_min = 'one'\n", 2, "finite number"),
    ("clearance = 1\n", 1, "[clearance] table"),
])
def test_a_bad_clearance_table_names_its_line(text, line, words):
    with pytest.raises(InputError) as caught:
        parse_tolerances(text, "tol.toml")
    assert caught.value.line == line and words in str(caught.value)


def test_the_layouts_clearance_min_unless_the_table_sets_one():
    assert clearance_check(PAPER, tolerances(""), FORK).clearance_min == 0.5
    assert clearance_check(PAPER, tolerances("", "[clearance]\nclearance_min = 2.0\n"),
                           FORK).clearance_min == 2.0
    assert clearance_check(PAPER, parse_tolerances(""), FORK) is None


def test_a_robot_needs_its_reduced_body_and_a_slow_scan_is_refused():
    with pytest.raises(ValueError, match="stroke_body"):
        clearance_check(PAPER, tolerances(""))
    slow = parse_scenario(scenarios.PAPER_WITHOUT_ROBOT.replace('mode = "fast"',
                                                                'mode = "slow"'), "slow.toml")
    with pytest.raises(ValueError, match="slow scan"):
        clearance_check(slow, tolerances(""))


# --- the closed form ------------------------------------------------------------------------

def test_protrusion_fixed_at_0_gives_no_contact_and_the_paper_least_clearance():
    summary = report(fixed("protrusion", 0.0))
    c = summary["clearance"]
    assert (c["contacts"], c["layouts"], c["contact_rate"]) == (0, 600, 0.0)
    assert c["least_distance"]["min"] == pytest.approx(NOMINAL, abs=1e-9)  # 0.650 mm
    assert round(c["least_distance"]["min"], 3) == 0.650
    assert c["contact_rate_95"] == list(wilson(0, 600))


def test_protrusion_fixed_at_12_mm_is_a_contact_in_every_layout():
    c = report(fixed("protrusion", 12.0))["clearance"]
    assert (c["contacts"], c["contact_rate"]) == (600, 1.0)
    assert c["least_distance"]["max"] == 0.0  # the tines cut into the wafers
    assert c["contact_rate_95"] == list(wilson(600, 600))
    assert set(c["contacts_by_part"]) <= {"tine_left", "tine_right"}
    assert sum(c["contacts_by_slot"].values()) == 600


def test_a_uniform_protrusion_gives_the_hand_computed_rate_within_its_interval():
    # 25 present wafers a layout, each protruding U(0, hi): a layout has a contact unless
    # every wafer stays below the threshold, (p*/hi)^25.
    hi = 0.175
    p_star = threshold(0.5)
    expected = 1.0 - (p_star / hi) ** 25
    c = report(uniform("protrusion", 0.0, hi) + "[states]\npresent = 1.0\n", n=3000,
               seed=11)["clearance"]
    low, high = c["contact_rate_95"]
    assert 0.3 < expected < 0.7
    assert low <= expected <= high, (expected, c["contact_rate"], low, high)
    # Each layout's least distance is its most protruding wafer's, exactly:
    assert c["least_distance"]["max"] <= NOMINAL
    assert c["least_distance"]["min"] >= math.hypot(70.0, 133.4 - hi) - 150.0 - 1e-9


def test_the_least_distance_of_each_layout_is_its_most_protruding_wafers():
    tol = tolerances(uniform("protrusion", 0.0, 0.6) + uniform("seat_offset", -0.5, 0.5)
                     + uniform("beam_z", -0.3, 0.3) + "[states]\npresent = 0.8\nempty = 0.2\n")
    check = clearance_check(PAPER, tol, FORK)
    base = sweep_base(PAPER, clearance=check)
    draws = draw_block(base, tol, 5, 0, 200)
    distance, part, slot = least_distances(check, draws)
    y = np.where(draws.exists[..., 0], draws.center[..., 0, 1], np.inf)
    p = 400.0 - y.min(axis=1)  # the most protruding wafer's protrusion
    expected = np.maximum(np.hypot(70.0, 133.4 - p) - 150.0, 0.0)
    assert np.allclose(distance, expected, atol=1e-9, rtol=0)
    names = [q.name for q in FORK.parts]
    assert {names[i] for i in part} <= {"tine_left", "tine_right"}
    assert np.array_equal(slot, np.argmin(y, axis=1) + 1)


def test_a_gap_in_z_adds_in_quadrature_and_overlap_is_zero():
    one = parse_tolerances("[states]\npresent = 1.0\n" + fixed("protrusion", 0.0))
    base = sweep_base(PAPER)
    draws = draw_block(base, one, 0, 0, 1)
    low = float(draws.center[0, 0, 0, 2])  # slot 1's bottom face
    # A 10 x 10 mm block over the wafers' centre, its bottom 2 mm above the top wafer's top:
    top = float(draws.center[0, -1, 0, 2] + draws.thickness[0, -1, 0])
    above = PrismPart("block", (0.0, 400.0), (1.0, 0.0), (5.0, 5.0), 0.0, False,
                      (top + 2.0, top + 50.0))
    # A ball-rounded segment 1 mm outside the rim in plan, below slot 1 by 3 mm in Z:
    beside = PrismPart("pin", (0.0, 400.0 - 151.0 - 0.25), (1.0, 0.0), (0.0, 0.0), 0.25, True,
                       (low - 100.0, low - 3.0))
    through = PrismPart("post", (0.0, 400.0 - 149.0), (1.0, 0.0), (0.0, 0.0), 5.0, False,
                        (0.0, 1000.0))
    for part, expected in ((above, 2.0), (beside, math.hypot(1.0, 3.0) - 0.0),
                           (through, 0.0)):
        body = StrokeBody("robot", ("fast stroke up",), (part,))
        d, _, _ = least_distances(ClearanceCheck(body, 0.5, 150.0), draws)
        # the ball's rounding: hypot(plan gap to its axis, z gap) - radius
        want = math.hypot(1.25, 3.0) - 0.25 if part is beside else expected
        assert d[0] == pytest.approx(want, abs=1e-9), part.name


def _projection_distance(point, centre, normal, radius, half):
    """Brute force: the plan distance from ``point`` to the plan view of a cylinder (radius,
    half-height ``half``) along ``normal`` about ``centre`` (its rim circles sampled finely)."""
    n = np.asarray(normal, float)
    u = np.cross(n, [0.0, 0.0, 1.0]) if abs(n[2]) < 1 else np.array([1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    phi = np.linspace(0.0, 2 * math.pi, 400_001)
    ring = radius * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v)
    pts = np.concatenate([centre + ring + s * half * n for s in (-1.0, 1.0)])
    d = np.hypot(pts[:, 0] - point[0], pts[:, 1] - point[1])
    return d.min()


@pytest.mark.parametrize("tilt_deg, axis_deg", [(1.958, 90.0), (1.958, 0.0), (0.5, 37.0),
                                                  (3.0, 200.0)])
def test_a_tilted_wafer_is_never_nearer_than_it_is_and_off_by_microns_at_most(tilt_deg,
                                                                            axis_deg):
    # A thin vertical post (the prism spans the wafer's Z) outside the rim: the 3-D distance
    # is the plan distance to the tilted cylinder's plan view.
    t, R = 0.7, 150.0
    th, ph = math.radians(tilt_deg), math.radians(axis_deg)
    normal = (math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th))
    bottom = np.array([0.0, 400.0, 300.0])
    mid = bottom + 0.5 * t * np.asarray(normal)
    post = (70.0, 266.6)
    true = _projection_distance(post, mid, normal, R, 0.5 * t)
    body = StrokeBody("robot", ("x",), (PrismPart("post", post, (1.0, 0.0), (0.0, 0.0), 0.0,
                                                  False, (0.0, 1000.0)),))

    class OneWafer:
        exists = np.ones((1, 1, 1), bool)
        center = bottom.reshape(1, 1, 1, 3)
        normal_ = None
        thickness = np.full((1, 1, 1), t)
        bow = np.zeros((1, 1, 1))

    OneWafer.normal = np.asarray(normal).reshape(1, 1, 1, 3)
    d, _, _ = least_distances(ClearanceCheck(body, 0.5, R), OneWafer)
    assert d[0] <= true + 1e-9
    assert true - d[0] < 2e-4, (true, d[0])


# --- without a robot: the scanner's heads, reduced by the core itself -------------------------

def test_without_a_robot_the_scanner_heads_sweep_vertical_capsules():
    body = scanner_body(NO_ROBOT)
    assert [p.name for p in body.parts] == ["emitter head", "receiver head"]
    assert body.parts[0].center == pytest.approx((-80.0, 266.6))
    assert body.parts[0].z == pytest.approx((280.0, 550.0)) and body.parts[0].ball
    c = run_sweep(NO_ROBOT, tolerances(fixed("protrusion", 0.0)), 100, seed=1)["clearance"]
    # the heads (3 mm spheres at x = ±80, y = 266.6) pass hypot(80, 133.4) - 150 - 3 mm away
    assert c["body"] == "scanner"
    assert c["least_distance"]["min"] == pytest.approx(math.hypot(80.0, 133.4) - 153.0,
                                                       abs=1e-9)
    assert c["contacts"] == 0


# --- the rate, its interval, partitions and the other results ------------------------------

def test_the_interval_is_the_sweeps_layout_interval_with_one_trial_a_layout():
    c = report(uniform("protrusion", 0.0, 0.172), n=1000)["clearance"]
    k, n = c["contacts"], c["layouts"]
    assert 0 < k < n
    assert c["contact_rate"] == k / n
    assert c["contact_rate_95"] == list(layout_interval(k, n, k, k, n, n))


TOL = (uniform("protrusion", 0.0, 0.2) + uniform("seat_offset", -0.5, 0.5)
       + uniform("tilt", 0.0, 0.3) + uniform("beam_z", -0.2, 0.2)
       + "[states]\npresent = 0.8\nempty = 0.1\ncross = 0.05\ndouble = 0.05\n")


def test_the_same_report_for_any_partitions():
    one = report(TOL, n=1700, seed=9)
    assert 0 < one["clearance"]["contacts"] < 1700
    for count in (2, 4):
        assert run_sweep(PAPER, tolerances(TOL), 1700, seed=9, partition_count=count,
                         clearance_body=FORK) == one


def test_the_report_changes_nothing_else_in_the_summary():
    with_report = report(TOL, n=700, seed=2)
    without = run_sweep(PAPER, parse_tolerances(TOL, "tol.toml"), 700, seed=2)
    assert "clearance" not in without
    assert {k: v for k, v in with_report.items() if k != "clearance"} == without


def test_the_command_prints_and_writes_the_report(tmp_path, capsys):
    tol = tmp_path / "tol.toml"
    tol.write_text(TOL + "[clearance]\n")
    out = tmp_path / "out"
    scenario = tmp_path / "paper-without-robot.toml"
    scenario.write_text(scenarios.PAPER_WITHOUT_ROBOT)
    assert cli.main(["sweep", str(scenario), "--tolerances", str(tol), "-n", "600",
                     "--seed", "1", "--workers", "0", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    c = summary["clearance"]
    assert f"clearance (scanner, fast stroke up): {c['contacts']:,} of 600 layouts" in text
    assert "least distance (mm): min" in text
    rows = list(csv.reader((out / "clearance.csv").open()))
    assert rows[0][:7] == ["body", "clearance_min", "layouts", "contacts", "contact_rate",
                           "low95", "high95"]
    assert rows[1][:4] == ["scanner", "0.5", "600", str(c["contacts"])]
    assert float(rows[1][5]) == c["contact_rate_95"][0]
    assert "clearance" not in summary["margins"]


def test_without_the_table_no_report_and_no_clearance_csv(tmp_path, capsys):
    tol = tmp_path / "tol.toml"
    tol.write_text(TOL)
    out = tmp_path / "out"
    assert cli.main(["sweep", str(scenarios.PAPER), "--tolerances", str(tol), "-n", "50",
                     "--workers", "0", "--out", str(out)]) == 0
    assert "clearance" not in capsys.readouterr().out
    assert "clearance" not in json.loads((out / "summary.json").read_text())
    assert not (out / "clearance.csv").exists()
