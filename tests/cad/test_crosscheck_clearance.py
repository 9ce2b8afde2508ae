"""SPEC §15 / issue 29: ``waferscan crosscheck`` confirms every motion's least distance (coal's)
with FreeCAD's B-rep: the robot's collision boxes placed as Part solids where Pinocchio puts
them, ``distToShape`` to the wafer's solid from the document, |B-rep - coal| <= 1e-3 mm; an
overlap confirmed by a common volume; a bowed wafer's conservative hull within its stated bound.

Hand numbers (tests/robot/test_clearance.py): in the paper's layout the tines' inner tip corners
(±70, 266.6) pass sqrt(70² + 133.4²) - 150 = 0.650 mm from the wafers' rims (centre line
(0, 400)); a wafer pushed 12 mm out overlaps the tines in plan, so the stroke runs them through
it; coal's hull of a 300 mm bowed wafer reaches up to 300/2 (1/cos(pi/128) - 1) = 0.045 mm
beyond its rim."""

import json
import math
from dataclasses import replace

import FreeCAD as App
import pytest
from commands import waferscan
from scenarios import PAPER, SLOW_JAB

from waferscan.cad import clearance_brep
from waferscan.cad.builder import build_document
from waferscan.cad.clearance_brep import TOLERANCE, check_closest, format_clearance, hull_bound
from waferscan.cad.crosscheck import crosscheck
from waferscan.core.files.scenario import read_scenario
from waferscan.core.model import Wafer
from waferscan.core.scan import clearance as core

TINE_CORNER = math.hypot(70.0, 133.4) - 150.0  # 0.650456 mm
PAPER_LAYOUT = read_scenario(PAPER)
SLOW_LAYOUT = read_scenario(SLOW_JAB)
SEAT = PAPER_LAYOUT.scanned_carrier.seat_z


def _wafer(name, center, bow=0.0):
    return Wafer(name, center, (0.0, 0.0, 1.0), 300.0, 0.7, bow=bow)


def _checked(layout, name):
    """crosscheck() of a fresh document of the layout (closed after)."""
    doc = build_document(layout, name)
    try:
        return crosscheck(doc)
    finally:
        App.closeDocument(doc.Name)


def _slow(wafers, jab=20.0, sweep=0.0):
    """A slow scan of the paper's carrier built here (slow_jab.toml's pose; its sweep's rules
    are another issue's): our wafers, our jab and sweep, clearance_min 0.5 mm, slots 1 to 10
    (the fork stays clear of the carrier's floor and roof)."""
    layout = replace(SLOW_LAYOUT, wafers=tuple(wafers)).with_scan(
        jab=jab, sweep=sweep, start_z=SEAT(1) - 5.0, final_z=SEAT(10) + 5.0)
    return replace(layout, mapping=replace(layout.mapping, clearance_min=0.5))


def _stroke(wafers):
    """The paper's fast stroke up over slots 1 to 10 (clear of the carrier's floor and roof,
    whose solids the clearance check may measure too), past our wafers."""
    return replace(PAPER_LAYOUT, wafers=tuple(wafers)).with_scan(start_z=SEAT(1) - 5.0,
                                                                 final_z=SEAT(10) + 5.0)


def _row(text, phase):
    """The clearance line of ``phase`` in the cross-check's text."""
    (line,) = [ln for ln in text.splitlines() if ln.startswith(phase + " ")]
    return line


def _figures(line):
    """(coal, B-rep, difference) of a clearance line: the three columns before the verdict."""
    head = line.split("  OK")[0].split("  FAIL")[0]
    coal, brep, diff = head.split()[-3:]
    return float(coal), float(brep), float(diff)


def test_the_paper_least_clearance_is_confirmed_through_the_command_line():
    done = waferscan("crosscheck", PAPER)
    assert done.returncode == 0, done.stderr
    line = _row(done.stdout, "fast stroke up")
    assert "tine_" in line and "LP1_W" in line and line.endswith("OK: |B-rep - coal| <= 0.001 mm")
    coal, brep, diff = _figures(line)
    assert coal == pytest.approx(TINE_CORNER, abs=1e-6)
    assert brep == pytest.approx(TINE_CORNER, abs=1e-6)  # the hand number, by OpenCASCADE
    assert abs(diff) <= TOLERANCE and diff == pytest.approx(brep - coal, abs=2e-6)
    assert "every motion confirmed by FreeCAD's B-rep geometry" in done.stdout
    data = json.loads(waferscan("crosscheck", PAPER, "--json").stdout)
    assert data["ok"] is True and data["clearance"]["ok"] is True
    (motion,) = data["clearance"]["motions"]
    assert motion["phase"] == "fast stroke up" and motion["unit"] == "z"
    assert motion["part"] in ("tine_left", "tine_right") and motion["bound"] is None
    assert motion["brep"] == pytest.approx(TINE_CORNER, abs=1e-6)
    assert abs(motion["difference"]) <= TOLERANCE and motion["ok"] is True
    assert data["clearance"]["largest_difference"] == pytest.approx(abs(motion["difference"]))


def _saved(layout, path):
    """The layout's document saved as ``path`` (a .FCStd for the command line)."""
    doc = build_document(layout, "CrossSaved")
    try:
        doc.saveAs(str(path))
    finally:
        App.closeDocument(doc.Name)
    return path


def test_a_difference_beyond_the_tolerance_fails_with_exit_status_1(monkeypatch, capsys,
                                                                     tmp_path):
    # One seated wafer in slot 3: the tine corners pass it by the paper's 0.650 mm (hand), and
    # coal and OpenCASCADE agree to ~4e-7 mm: confirmed; held to 1e-9 mm, a FAIL (exit 1).
    import waferscan.cli as cli

    path = _saved(_stroke([_wafer("w3", (0.0, 400.0, SEAT(3)))]), tmp_path / "one.FCStd")
    assert cli.main(["crosscheck", str(path)]) == 0
    coal, brep, diff = _figures(_row(capsys.readouterr().out, "fast stroke up"))
    assert brep == pytest.approx(TINE_CORNER, abs=1e-6) and abs(diff) <= TOLERANCE
    monkeypatch.setattr(clearance_brep, "TOLERANCE", 1e-9)
    assert cli.main(["crosscheck", str(path)]) == 1
    out = capsys.readouterr().out
    assert "FAIL: |B-rep - coal| > 1e-09 mm" in _row(out, "fast stroke up")
    assert "1 motion(s) NOT confirmed by FreeCAD's B-rep geometry" in out


def test_a_wafer_protruding_12_mm_is_confirmed_as_overlapping(tmp_path):
    # Hand: its rim passes X = 70 at Y = 388 - sqrt(150² - 70²) = 255.34, inside the tines'
    # tips (266.6): the stroke runs the tines through it. coal's depth is searched to half its
    # margin (core/scan/clearance.py), at most the hand's 2.35 mm (0.35 + 2: wafer and tine
    # halves); OpenCASCADE says 0 apart and the tine has a volume in common with the wafer.
    layout = _stroke([_wafer("out12", (0.0, 388.0, SEAT(3)))])
    path = _saved(layout, tmp_path / "contact.FCStd")
    done = waferscan("crosscheck", path, "--json")
    assert done.returncode == 0, done.stderr
    assert "contact:" in done.stderr  # the scan's own warning, as before
    (motion,) = json.loads(done.stdout)["clearance"]["motions"]
    assert motion["obstacle"] == "out12" and motion["ok"] is True
    assert -2.35 - 1e-6 <= motion["coal"] < 0.0
    assert motion["overlapping"] is True and motion["brep"] == pytest.approx(0.0, abs=1e-6)
    assert motion["overlap_volume"] > 1.0 and motion["difference"] is None
    text = waferscan("crosscheck", path).stdout
    assert "OK: overlapping, " in _row(text, "fast stroke up")
    assert f"coal's depth {-motion['coal']:.3f} mm" in text


def test_a_slow_scan_with_a_jab_confirms_every_motion():
    # Seated wafers in slots 1 and 2 (the tine corners 0.650 mm from their rims when the jab
    # ends, hand), one 20 mm out in slot 3 (the jab drives the tines into it), one 5 mm out in
    # slot 5.
    wafers = [_wafer("w1", (0.0, 400.0, SEAT(1))), _wafer("w2", (0.0, 400.0, SEAT(2))),
              _wafer("p3", (0.0, 380.0, SEAT(3))), _wafer("p5", (0.0, 395.0, SEAT(5)))]
    check = _checked(_slow(wafers, jab=26.6), "CrossSlow")
    clearance = check.clearance
    assert clearance.ok, format_clearance(clearance)
    kinds = {c.closest.motion.kind for c in clearance.checks}
    assert {core.JAB, core.STEPS} <= kinds
    jabs = {c.closest.motion.slot: c for c in clearance.checks if c.closest.motion.kind == core.JAB}
    assert jabs[1].brep == pytest.approx(TINE_CORNER, abs=1e-6)  # the jab's end, hand
    assert jabs[1].closest.position == pytest.approx(26.6, abs=0.5)
    assert jabs[3].overlapping and jabs[3].overlap > 0.0 and jabs[3].closest.obstacle == "p3"
    exact = [c for c in clearance.checks if c.difference is not None]
    assert exact and all(abs(c.difference) <= TOLERANCE and c.bound is None for c in exact)
    assert clearance.largest_difference <= TOLERANCE
    text = format_clearance(clearance)
    assert len([ln for ln in text.splitlines() if ln.startswith("slot ")]) == \
        len(clearance.checks)
    assert "advance 26.600 mm" in _row(text, "slot 1 jab")


def test_a_bowed_wafer_is_confirmed_within_its_hull_bound():
    # The paper's stroke past a wafer bowed 0.5 mm: OpenCASCADE's distance is still the rim's
    # 0.650 mm (the rim circle is the bowed solid's too), coal's hull reaches out up to
    # 150 (1/cos(pi/128) - 1) = 0.0452 mm more (plus the sampling's sagitta, 2e-4 mm).
    layout = _stroke([_wafer("b3", (0.0, 400.0, SEAT(3)), bow=0.5),
                      _wafer("w5", (0.0, 400.0, SEAT(5)))])
    check = _checked(layout, "CrossBowed")
    (only,) = check.clearance.checks
    assert only.closest.obstacle == "b3" and only.ok
    assert only.bound == pytest.approx(150.0 * (1.0 / math.cos(math.pi / 128) - 1.0)
                                       + 0.5 / 24 ** 2 / 4.0, abs=1e-9)
    assert hull_bound(layout.wafers[0]) == only.bound and 0.045 < only.bound < 0.05
    assert only.brep == pytest.approx(TINE_CORNER, abs=1e-6)
    assert 0.0 <= only.difference <= only.bound  # conservative: coal is never the further
    assert "coal conservative (a bowed wafer's grown convex hull)" in only.verdict()
    assert check.ok


def test_a_bowed_wafer_pushed_out_overlaps_the_jab():
    # A bowl (0.5 mm) 20 mm out of slot 3: the jab and the steps run the tines into it.
    wafers = [_wafer("w2", (0.0, 400.0, SEAT(2))),
              _wafer("b3", (0.0, 380.0, SEAT(3)), bow=-0.5)]
    clearance = _checked(_slow(wafers), "CrossBowedSlow").clearance
    assert clearance.ok, format_clearance(clearance)
    into = [c for c in clearance.checks if c.closest.obstacle == "b3" and c.overlapping]
    assert {c.closest.motion.kind for c in into} == {core.JAB, core.STEPS}
    assert all(c.overlap > 0.0 for c in into)


def test_under_a_dome_the_bound_takes_the_bow():
    # Without a robot the scanner's heads (spheres of 3 mm) stand in. A 150 mm jab puts the
    # emitter's head at (-80, 390), under a wafer in slot 3 domed 2 mm (r = 80.6 mm from its
    # centre, wholly inside the rim). coal's hull fills the dome's underside, flat at the rim:
    # the head's top at the end of pocket 2's steps (seat3 - 2) is 2 mm below it; the solid's
    # underside is 2 (1 - 80.6²/150²) = 1.42 mm higher there. The check allows the bow.
    from waferscan.robot.clearance import ScannerBody, clearance_for

    dome = _wafer("dome", (0.0, 400.0, SEAT(3)), bow=2.0)
    layout = replace(SLOW_LAYOUT, wafers=(dome,), robot=None).with_scan(jab=150.0, sweep=0.0)
    body = ScannerBody(layout)
    report = clearance_for(layout, body, pockets=[2])
    (steps,) = [c for c in report.closest if c.motion.kind == core.STEPS]
    check = check_closest(body, clearance_brep._Obstacles(None, layout), steps)
    assert steps.distance == pytest.approx(2.0, abs=0.01)  # the hull's flat underside
    assert check.brep > steps.distance + 1.0  # the true underside, well above
    assert check.bound == pytest.approx(hull_bound(dome) + 2.0)
    assert "filling the dome's underside (bow 2 mm)" in check.verdict() and check.ok


def test_a_slow_scan_sweep_is_confirmed():
    # The wrist's turn (a Lipschitz search in coal's check): each sweep's least distance, where
    # the search put it, confirmed like the rest. Seated wafers only: the fork clears them.
    wafers = [_wafer(f"w{k}", (0.0, 400.0, SEAT(k))) for k in (1, 2, 4)]
    clearance = _checked(_slow(wafers, jab=20.0, sweep=10.0), "CrossSweep").clearance
    assert clearance.ok, format_clearance(clearance)
    sweeps = [c for c in clearance.checks if c.closest.motion.kind == core.SWEEP]
    assert sweeps and all(abs(c.difference) <= TOLERANCE for c in sweeps)
    assert "angle " in _row(format_clearance(clearance), sweeps[0].closest.motion.phase)
