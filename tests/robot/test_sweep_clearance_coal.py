"""The sweep's [clearance] report (SPEC §12, §15) against coal: the robot's collision geometry
reduced to prisms (waferscan.robot.sweep_clearance) and the closed form over drawn layouts
(core/sweep/clearance.py) give the least distance ``clearance_for`` gives, layout by layout, and
the same contact yes or no; protrusions drawn so that the rate is known; the same report on
Dask workers as in this process."""

import math
from dataclasses import replace

import numpy as np
import pytest
import scenarios
from scenarios import normal, uniform

from waferscan import cli, sweep
from waferscan.core.errors import InputError
from waferscan.core.files.scenario import read_scenario
from waferscan.core.sweep import draw_block, sample_layout, sweep_base
from waferscan.core.sweep.clearance import clearance_check, least_distances
from waferscan.core.sweep.distributions import parse_tolerances
from waferscan.robot.clearance import clearance_for
from waferscan.robot.sweep_clearance import stroke_body

PAPER = read_scenario(scenarios.PAPER)
NOMINAL = math.hypot(70.0, 133.4) - 150.0  # the tines' tips to every rim: 0.650 mm


def fixed(quantity, value):
    return f'[{quantity}]\ndist = "fixed"\nvalue = {value!r}\n'


def closed_and_coal(text, n, seed, block=0):
    """(closed-form least distances, coal's, the check) of ``n`` layouts drawn by ``text``."""
    tol = parse_tolerances(text + "[clearance]\n", "tol.toml")
    check = clearance_check(PAPER, tol, stroke_body(PAPER))
    base = sweep_base(PAPER, clearance=check)
    draws = draw_block(base, tol, seed, block, n)
    closed, _, _ = least_distances(check, draws)
    coal = []
    for i in range(n):
        # A drawn beam_tilt turns the sensor's beam, not the robot: the pose is the INPUT's.
        layout = replace(sample_layout(base, draws, i), beam=PAPER.beam)
        coal.append(clearance_for(layout).least.distance)
    return closed, np.array(coal), check


def test_the_robots_fork_reduces_to_the_prisms_the_core_tests_use():
    body = stroke_body(PAPER)
    parts = {p.name: p for p in body.parts}
    assert body.body == "robot" and body.motions == ("fast stroke up",)
    assert set(parts) == {"column", "carriage", "upper_arm", "forearm", "palm", "tine_left",
                          "tine_right", "wrist_hub"}
    left = parts["tine_left"]
    assert left.center == pytest.approx((-80.0, 176.6), abs=1e-9)
    assert abs(left.axis[1]) == pytest.approx(1.0) and left.half == pytest.approx((90.0, 10.0))
    assert left.z == pytest.approx((280.0, 554.0)) and not left.ball and left.radius == 0.0
    assert parts["wrist_hub"].radius == pytest.approx(30.0)
    assert parts["column"].z == pytest.approx((0.0, 500.0))  # it does not ride the lift


FLAT = (uniform("protrusion", 0.0, 0.18) + uniform("seat_offset", -0.5, 0.5)
        + normal("tilt", 0.0, 0.2) + normal("beam_z", 0.0, 0.3) + normal("beam_tilt", 0.0, 0.05)
        + "[states]\npresent = 0.8\nempty = 0.1\ncross = 0.05\ndouble = 0.05\n")


def test_flat_wafers_agree_with_coal_layout_by_layout():
    # 300 layouts with drawn tilts, cross-slotted and double wafers, protrusions, seats and
    # teach errors: coal's least distance to within 1.1e-5 mm (the closed form is exact for a
    # level wafer and never more than the true distance for a tilted one).
    closed, coal, check = closed_and_coal(FLAT, 300, seed=3)
    assert np.all(closed <= coal + 1e-6)
    assert np.max(coal - closed) < 2e-5
    contact = closed < check.clearance_min
    assert np.array_equal(contact, coal < check.clearance_min)
    assert 0.1 < contact.mean() < 0.95  # both answers drawn


def test_bowed_wafers_agree_with_coals_hull_within_its_growth():
    # coal holds a bowed wafer in a hull grown to contain it (robot/clearance.py): its
    # distance is up to ~0.05 mm short of the true one, which the closed form gives for a
    # level bowed wafer. The same contacts wherever coal is not within that of the limit.
    text = (uniform("protrusion", 0.0, 0.3) + uniform("bow", -0.1, 0.1)
            + uniform("seat_offset", -0.5, 0.5) + "[states]\npresent = 0.9\nempty = 0.1\n")
    closed, coal, check = closed_and_coal(text, 12, seed=5)
    assert np.all(closed >= coal - 1e-6) and np.all(closed - coal < 0.05)
    clear = np.abs(coal - check.clearance_min) > 0.05
    assert np.array_equal((closed < 0.5)[clear], (coal < 0.5)[clear])


def test_protrusion_fixed_at_0_and_at_12_mm_as_coal_says():
    closed, coal, _ = closed_and_coal(fixed("protrusion", 0.0), 5, seed=1)
    assert round(float(coal.min()), 3) == 0.650 == round(float(closed.min()), 3)
    closed, coal, _ = closed_and_coal(fixed("protrusion", 12.0), 2, seed=1)
    assert np.all(closed == 0.0) and np.all(coal < 0.0)  # the tines cut into the wafers


@pytest.fixture
def tol_file(tmp_path):
    def write(text):
        path = tmp_path / "tol.toml"
        path.write_text(text + "[clearance]\n")
        return path
    return write


def test_the_command_reports_rate_1_at_12_mm_and_0_at_0(tol_file):
    summary, _ = sweep.run(str(scenarios.PAPER), tol_file(fixed("protrusion", 12.0)), 700,
                           seed=1, workers=0, clearance_body=stroke_body)
    c = summary["clearance"]
    assert (c["contacts"], c["contact_rate"], c["body"]) == (700, 1.0, "robot")
    summary, _ = sweep.run(str(scenarios.PAPER), tol_file(fixed("protrusion", 0.0)), 700,
                           seed=1, workers=0, clearance_body=stroke_body)
    c = summary["clearance"]
    assert (c["contacts"], c["contact_rate"], c["clearance_min"]) == (0, 0.0, 0.5)
    assert round(c["least_distance"]["min"], 3) == 0.650


def test_a_uniform_protrusion_gives_the_hand_computed_rate(tol_file):
    # 25 present wafers, each U(0, 0.175) out: no contact only when all stay under p*, where
    # the tips come to clearance_min = 0.5 of the rim.
    p_star = 133.4 - math.sqrt(150.5 ** 2 - 70.0 ** 2)
    expected = 1.0 - (p_star / 0.175) ** 25
    summary, _ = sweep.run(str(scenarios.PAPER),
                           tol_file(uniform("protrusion", 0.0, 0.175)
                                    + "[states]\npresent = 1.0\n"), 3000, seed=11, workers=0, clearance_body=stroke_body)
    low, high = summary["clearance"]["contact_rate_95"]
    assert low <= expected <= high


def test_dask_workers_give_the_report_of_this_process(tol_file):
    path = tol_file(FLAT)
    alone, _ = sweep.run(str(scenarios.PAPER), path, 1300, seed=4, workers=0, clearance_body=stroke_body)
    on_dask, _ = sweep.run(str(scenarios.PAPER), path, 1300, seed=4, workers=2,
                           partition_count=3, clearance_body=stroke_body)
    assert on_dask == alone
    assert 0 < alone["clearance"]["contacts"] < 1300


def test_the_command_reduces_the_robot_and_a_library_call_must_pass_it(tol_file, capsys):
    path = tol_file(fixed("protrusion", 0.0))
    assert cli.main(["sweep", str(scenarios.PAPER), "--tolerances", str(path), "-n", "20",
                     "--workers", "0"]) == 0
    assert ("clearance (robot, fast stroke up): 0 of 20 layouts with a contact under 0.5 mm"
            in capsys.readouterr().out)
    with pytest.raises(InputError, match="stroke_body"):
        sweep.run(str(scenarios.PAPER), path, 20, workers=0)
