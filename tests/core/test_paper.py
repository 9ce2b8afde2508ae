"""The paper's experiment (SPEC §8): Fig. 6's load scanned as in Table 1."""

import math
from pathlib import Path

import pytest

from waferscan.cli import demo_checks, paper_scenario
from waferscan.core.files.report import PAPER_CODE, PAPER_TABLE_1
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

LAYOUT = read_scenario(paper_scenario())
STEP = 0.05


@pytest.fixture(scope="module", params=["analytic", "vector", "loop"])
def result(request):
    return scan_layout(LAYOUT, request.param)


def test_the_scenario_is_the_papers():
    assert paper_scenario() == Path(__file__).resolve().parents[2] / "resources/examples/paper.toml"
    scan = LAYOUT.scan
    assert (scan.final_z - scan.start_z, scan.z_step, scan.position_count) == (270.0, 0.05, 5401)
    carrier = LAYOUT.scanned_carrier
    assert (carrier.slot_count, carrier.pitch, carrier.first_slot_z) == (25, 10.0, 293.94)
    assert len(LAYOUT.wafers) == 10
    assert {w.thickness for w in LAYOUT.wafers} == {0.7}


def test_code(result):
    assert result.code == PAPER_CODE == "1101221001220001010000010"
    assert result.e87 == "3313553113551113131111131"


def test_normal_wafers_in_within_one_step_above_the_seat_and_diff_within_one_step(result):
    normal = [r for r in result.runs if r.diff < 1.0]
    assert len(normal) == 8
    seats = {round(LAYOUT.scanned_carrier.seat_z(s), 6) for s in range(1, 26)}
    for run in normal:
        seat = max(z for z in seats if z <= run.z_in + 1e-9)
        assert 0.0 <= run.z_in - seat <= STEP
        assert abs(run.diff - 0.7) <= STEP + 1e-9


def test_cross_slotted_wafers_reproduce_5_38(result):
    cross = [r for r in result.runs if r.diff > 1.0]
    assert [r.wafers for r in cross] == [("LP1_W04",), ("LP1_W07",)]
    for run in cross:
        assert abs(run.diff - 5.38) <= 0.25


def test_every_run_is_close_to_the_papers_table_1(result):
    rows = [row for row in result.table_rows() if row[3] is not None]
    assert [row[0] for row in rows] == sorted(PAPER_TABLE_1)
    for slot, _, _, z_in, z_out, diff, _ in rows:
        _, paper_in, paper_out, paper_diff = PAPER_TABLE_1[slot]
        assert abs(z_in - paper_in) < 0.1
        assert abs(z_out - paper_out) < 0.1
        assert abs(diff - paper_diff) < 0.1


def test_exact_edges_of_a_cross_slotted_wafer_from_the_documented_geometry():
    """The beam is 133.4 mm in front of the centre (16.6 mm deep); supports 292.5 mm apart. The
    slice of the tilted wafer in the beam's vertical plane is a 2h x t rectangle tilted by
    atan(pitch/span), centred on the mid-height between the two seats."""
    exact = scan_layout(LAYOUT.with_scan(z_step=0.0))
    h = math.sqrt(150.0 ** 2 - 133.4 ** 2)
    tilt = math.atan(10.0 / 292.5)
    middle = 0.5 * (333.94 + 343.94)
    bottom = middle - h * math.sin(tilt)
    top = middle + h * math.sin(tilt) + 0.7 * math.cos(tilt)
    run = next(r for r in exact.runs if r.wafers == ("LP1_W04",))
    assert run.z_in == pytest.approx(bottom, abs=2e-9)
    assert run.z_out == pytest.approx(top, abs=2e-9)
    assert run.diff == pytest.approx(5.3867, abs=1e-4)


def test_the_papers_own_test_gives_the_same_code():
    result = scan_layout(LAYOUT, "paper")
    assert result.code == PAPER_CODE
    exact = scan_layout(LAYOUT)
    for mine, theirs in zip(exact.runs, result.runs):
        assert abs(mine.z_in - theirs.z_in) <= 0.4  # the mid-plane test ignores thickness
        assert abs(mine.z_out - theirs.z_out) <= 0.4


def test_demo_checks_pass(result):
    assert all(ok for ok, _ in demo_checks(result))
