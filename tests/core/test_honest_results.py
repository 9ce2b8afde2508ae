"""Honest results (SPEC §3, §4, issue 9): every state reported is true, or a warning says why it
cannot be known. Layouts are built from scenario text; the expected figures come from the
layout's own geometry (seats, steps, thicknesses), not from a run of the code."""

from dataclasses import replace

import pytest
from scenarios import free_wafer, one_carrier

from waferscan.core.files.mcs import format_results
from waferscan.core.files.report import result_dict
from waferscan.core.files.scenario import parse_scenario
from waferscan.core.geometry.beam import beam_hits_wafer, paper_beam_hits_wafer
from waferscan.core.mapping import E87, UNSCANNED, SlotPlan, map_slots
from waferscan.core.model import Beam, ScanParameters, Wafer
from waferscan.core.scan.engines import ENGINES
from waferscan.core.scan.layout_scan import scan_layout

SEAT1 = 100.0
PITCH = 10.0


def scenario(load="1111111111", start=90.0, final=200.0, step=0.05, thickness=0.7, extra=""):
    return parse_scenario(one_carrier(load, start=start, final=final, step=step,
                                      first_slot_z=SEAT1, pitch=PITCH, thickness=thickness,
                                      extra=extra))


def seat(slot):
    return SEAT1 + (slot - 1) * PITCH


# --- 1. Protrusion: judged on the front edge alone, 6 outranks everything --------------------

@pytest.mark.parametrize("rise", [1.0, -0.8, 3.0, 4.9])
def test_a_protruding_wafer_off_its_seat_is_6_in_the_slot_nearest_its_bottom(rise):
    # 4 mm out of the opening (the carrier's front is -Y), seated `rise` mm off slot 4's seat.
    layout = scenario(load="1110111111", extra=free_wafer("P", 396.0, seat(4) + rise))
    result = scan_layout(layout)
    assert dict(result.protrusions)["P"] == pytest.approx(4.0, abs=1e-9)
    assert result.code == "1116111111"
    assert result.e87[3] == str(E87[6])


def test_protrusion_outranks_a_thick_run_and_a_position_error_in_its_slot():
    # A seated wafer in slot 3 and a protruding one lying on it 0.7 mm higher: one thick run.
    layout = scenario(load="1111111111", extra=free_wafer("P", 396.0, seat(3) + 0.7))
    assert scan_layout(layout).code == "1161111111"


def test_a_protruding_cross_slotted_wafer_is_6_in_both_of_its_slots():
    layout = scenario(load="0220000000")
    (cross,) = layout.wafers
    x, y, z = cross.center
    pushed = replace(layout, wafers=(replace(cross, center=(x, y - 4.0, z)),))
    assert scan_layout(layout).code == "0220000000"
    result = scan_layout(pushed)
    assert dict(result.protrusions)[cross.name] > 3.9
    assert result.code == "0660000000"


def _frontmost_by_sampling(wafer, front, points=2_000_000):
    """How far the solid reaches along ``front`` (a horizontal unit vector), from its two rim
    circles sampled densely (a disc's support point lies on a rim): independent of the code's
    closed form, to about R·(2π/points)²/2 = 1e-9 mm."""
    import numpy as np

    n = np.array(wafer.normal)
    u = np.cross(n, [1.0, 0.0, 0.0])
    u = u / np.linalg.norm(u)
    v = np.cross(n, u)
    phi = np.linspace(0.0, 2.0 * np.pi, points, endpoint=False)
    f = np.array([front[0], front[1], 0.0])
    c = np.array(wafer.center)
    rim = wafer.radius * (np.cos(phi) * (u @ f) + np.sin(phi) * (v @ f))
    return float(c @ f + rim.max() + max(0.0, wafer.thickness * (n @ f)))


def test_protrusion_is_the_solids_frontmost_point_not_the_mid_planes():
    """Issue 24, item 6: a wafer tilted 0.5 deg with its front edge up reaches (t/2)·sin(0.5°)
    = 0.00338 mm further out at its top rim than at its mid-plane. Placed so that its frontmost
    point is 1.00238 mm out (limit 1 mm), it protrudes: the mid-plane's 0.99900 read 5 (the
    beam meets it 1.16 mm above the seat, 132.4 mm in front of its centre)."""
    import math

    t, theta = 0.775, math.radians(0.5)
    out = 1.00238
    # The closed form by hand: the front rim's bottom point is R·cos θ ahead of the centre, its
    # top point t·sin θ further; the centre stands d ahead of the carrier's (front is -Y).
    d = out - 150.0 * (math.cos(theta) - 1.0) - t * math.sin(theta)
    tilted = f"""
[[wafer]]
name = "T"
center = [0.0, {400.0 - d!r}, {seat(4)!r}]
normal = [0.0, {-math.sin(theta)!r}, {math.cos(theta)!r}]
diameter = 300.0
thickness = {t!r}
"""
    layout = scenario(load="1110111111", thickness=t, extra=tilted)
    wafer = next(w for w in layout.wafers if w.name == "T")
    carrier = layout.carriers[0]
    opening = carrier.center[0] * carrier.front[0] + carrier.center[1] * carrier.front[1] + 150.0
    assert _frontmost_by_sampling(wafer, carrier.front) - opening == pytest.approx(out, abs=1e-8)
    result = scan_layout(layout)
    assert dict(result.protrusions)["T"] == pytest.approx(out, abs=1e-9)
    assert result.code == "1116111111"
    # Tilted the other way (front edge down), the bottom rim is the frontmost: the same
    # protrusion for the same placement of that rim.
    down = layout.wafers[-1]
    assert down.name == "T"
    flipped = replace(down, normal=(0.0, math.sin(theta), math.cos(theta)),
                      center=(0.0, 400.0 - (out - 150.0 * (math.cos(theta) - 1.0)), seat(4)))
    result = scan_layout(replace(layout, wafers=layout.wafers[:-1] + (flipped,)))
    assert dict(result.protrusions)["T"] == pytest.approx(out, abs=1e-9)
    assert _frontmost_by_sampling(flipped, carrier.front) - opening == pytest.approx(out, abs=1e-8)


# --- 4. Warnings and the unscanned state -----------------------------------------------------

def test_the_paper_like_scan_has_no_warnings():
    result = scan_layout(scenario())
    assert result.warnings == ()
    assert result.code == "1111111111"


@pytest.mark.parametrize("step, thickness, warned", [
    (2.0, 0.775, True), (0.4, 0.775, True), (0.3875, 0.775, False), (0.35, 0.7, False),
    (0.36, 0.7, True), (0.05, 0.7, False)])
def test_a_step_coarser_than_half_the_thinnest_wafer_warns(step, thickness, warned):
    result = scan_layout(scenario(step=step, thickness=thickness))
    coarse = [w for w in result.warnings if "coarser than half the thinnest wafer" in w]
    assert bool(coarse) == warned
    if warned:
        assert f"{thickness:g} mm" in coarse[0]


def test_a_thin_wafer_makes_the_thinnest_one():
    # A thin wafer (0.25 t = 0.175 mm): 0.1 mm steps are coarser than half of it.
    result = scan_layout(scenario(load="1111411111", step=0.1))
    assert any("0.175 mm" in w for w in result.warnings)


def test_coarse_steps_on_seated_wafers_are_wrong_but_warned():
    # 2 mm steps on 0.775 mm wafers: the states are not to be trusted, and the result says so.
    result = scan_layout(scenario(step=2.0, thickness=0.775))
    assert result.code != "1111111111"
    assert result.warnings


@pytest.mark.parametrize("final, step, first_unscanned", [
    (200.0, 0.05, None), (195.0, 0.05, None), (195.0, 0.08, None), (194.99, 0.05, 10),
    (160.0, 0.05, 7), (152.0, 0.05, 6)])
def test_slots_whose_window_is_not_wholly_scanned_are_unscanned(final, step, first_unscanned):
    # The scanned range is start_z..final_z: the grid's last position may lie up to a step
    # below final_z (194.96 at 0.08 mm steps), as any point of the range lies within a step.
    result = scan_layout(scenario(final=final, step=step))
    if first_unscanned is None:
        assert result.code == "1111111111"
        return
    n = first_unscanned - 1
    # Window of slot s: seat +- pitch/2; slot 10's is 185..195.
    assert result.code == "1" * n + UNSCANNED * (10 - n)
    assert result.e87 == "3" * n + "0" * (10 - n)
    assert any("not wholly inside the scanned range" in w for w in result.warnings)
    data = result_dict(result)
    assert [s["state"] for s in data["slots"]][n:] == [UNSCANNED] * (10 - n)
    assert data["slots"][n]["state_name"] == "unscanned"
    text = format_results(1, "SCF", result, timestamp="T")
    rows = [line.split("\t") for line in text.split("\n\n", 1)[1].splitlines()[1:]]
    assert [r[-1] for r in rows if int(r[0]) > n] == ["unscanned"] * (10 - n)
    assert "code = " + "1" * n + "?" * (10 - n) in text.splitlines()


def test_a_start_above_the_bottom_slots_makes_them_unscanned_not_empty():
    result = scan_layout(scenario(start=126.0))
    # Windows of slots 1-3 reach below 126 (slot 3's: 115..125 is wholly below, slot 4's from
    # 125): slots 1..4 are unscanned.
    assert result.code == "????111111"
    assert result.e87.startswith("0000")


def test_the_start_and_end_of_the_scan_inside_wafers_warn_of_cut_off_runs():
    result = scan_layout(scenario(start=seat(2) + 0.3, final=seat(9) + 0.35))
    cut = [w for w in result.warnings if "cut off" in w]
    assert len(cut) == 2
    assert "by the start" in cut[0] and "by the end" in cut[1]
    assert f"{seat(2) + 0.3:.3f}" in cut[0] and f"{seat(9) + 0.35:.3f}" in cut[1]


def test_results_txt_and_json_carry_the_warnings():
    result = scan_layout(scenario(step=2.0, final=160.0))
    assert len(result.warnings) >= 2
    text = format_results(3, "SCF", result, timestamp="T")
    header = text.split("\n\n", 1)[0].splitlines()
    assert [line for line in header if line.startswith("warning = ")] == \
        [f"warning = {w}" for w in result.warnings]
    assert result_dict(result)["warnings"] == list(result.warnings)


def test_slow_mode_judges_the_same_slots_unscanned():
    layout = scenario(final=160.0)
    layout = layout.with_scan(mode="slow")
    assert scan_layout(layout).code == "111111????"


def test_map_slots_unscanned_yields_to_protrusion():
    plan = SlotPlan(3, 10.0, 100.0, 0.7, 0.35, 0.5)
    assert map_slots(plan, [(100.0, 100.7)], [3], [2, 3]).code == "1?6"
    assert map_slots(plan, [(100.0, 100.7)], [3], [2, 3]).e87 == "302"


# --- 5. The smaller ones ----------------------------------------------------------------------

def test_the_step_count_tolerance_is_relative():
    # 270 mm at 1e-5 mm: x = 26999999.999999996 in binary; final_z is step 27,000,000.
    scan = ScanParameters(start_z=280.0, final_z=550.0, z_step=1e-5)
    assert scan.last_step == 27_000_000
    assert scan.position(scan.last_step) == pytest.approx(550.0, abs=1e-7)
    # Not pulled up where final_z is really off the grid.
    assert ScanParameters(280.0, 550.0 - 0.3e-5, 1e-5).last_step == 26_999_999
    assert ScanParameters(280.0, 550.0, 0.05).last_step == 5400


def test_exact_edges_are_the_geometric_ones():
    layout = scenario(load="0000000000", start=280.0, final=320.0, step=0.0,
                      extra=free_wafer("W", 400.0, 300.0))
    result = scan_layout(layout)
    (wafer,) = result.wafers
    assert wafer.z_in == 300.0
    assert wafer.z_out == pytest.approx(300.7, abs=1e-12)
    assert result.runs[0].z_in == 300.0


def test_the_paper_engine_keeps_a_top_face_exactly_on_a_step():
    # A level wafer whose top face lies on a grid step: z - seat rounds to 0.7 + 4.5e-14.
    beam = Beam((-80.0, 266.6, 280.0), (1.0, 0.0, 0.0), 160.0)
    seat_z = 280.0 + 1003 * 0.05
    wafer = Wafer("W", (0.0, 400.0, seat_z), (0.0, 0.0, 1.0), 300.0, 0.7)
    top = 280.0 + 1017 * 0.05
    assert top - seat_z > 0.7
    assert beam_hits_wafer((-80.0, 266.6, top), beam, wafer)
    assert paper_beam_hits_wafer((-80.0, 266.6, top), beam, wafer)


def test_the_paper_and_exact_engines_agree_on_level_wafers_at_every_seat_on_the_grid():
    # Level wafers, beam well inside the rim: the mid-plane test and the exact one are the same.
    for first in (330.15, 330.4, 380.8, 402.35):
        layout = parse_scenario(one_carrier(
            "1111111111", start=280.0, final=600.0, name=None,
            first_slot_z=280.0 + round((first - 280.0) / 0.05) * 0.05))
        exact = scan_layout(layout, "loop")
        paper = scan_layout(layout, "paper")
        assert [(r.z_in, r.z_out) for r in paper.runs] == [(r.z_in, r.z_out) for r in exact.runs]


def test_the_analytic_engine_scans_to_final_z_at_27_million_steps():
    layout = scenario(step=1e-5, final=360.0)
    assert (360.0 - 90.0) / 1e-5 < 27_000_000  # binary rounding: final_z a hair below its k
    hits = ENGINES["analytic"](layout)
    assert hits.count == 27_000_001
    assert scan_layout(layout).code == "1111111111"


@pytest.mark.parametrize("tilt_deg, bow", [(0.5, 0.1), (-0.5, 0.1), (30.0, -0.3), (80.0, 40.0),
                                           (89.0, 5.0), (-80.0, -40.0), (70.0, -40.0)])
def test_front_reach_is_the_bowed_solids_frontmost_point(tilt_deg, bow):
    """scan_result.front_reach against the bowed solid (SPEC §10) sampled over its bottom and
    top surfaces and its rim: the vertex branch (bow·sin(tilt) > 0 beyond atan(R / 2 bow)) is
    reached by the steep, strongly bowed cases."""
    import math

    import numpy as np

    from waferscan.core.scan.scan_result import front_reach

    radius, t = 150.0, 0.775
    along = math.sin(math.radians(tilt_deg))
    across = math.cos(math.radians(tilt_deg))
    # along the direction f: a point r u + (w(r) + s) n reaches r (u·f) + (w(r) + s) along,
    # u·f at most sqrt(1 - along²) = across (u in the wafer's plane)
    r = np.linspace(0.0, radius, 2_000_001)
    w = bow * (1.0 - r * r / (radius * radius))
    sampled = max(float(np.max(r * across + (w + s) * along)) for s in (0.0, t))
    assert front_reach(radius, t, bow, along) == pytest.approx(sampled, abs=1e-8)
