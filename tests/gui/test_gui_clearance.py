"""SPEC §15's clearance in the GUI (issue 29): the scan panel says the least clearance at the
frame shown, from the body that measured the scan's report; the fork turns red while a frame is
closer than clearance_min and gets its own colour back after; the slot-code dialog gives the
least clearance and lists each contact; the pocket plan draws where the fork's tines went in the
jab and the sweep. Checked against ``waferscan.robot.clearance`` run here, without FreeCAD, and
against the tine boxes turned by hand."""

import json
import math
from dataclasses import replace
from pathlib import Path

import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import clearance as core

pytest.importorskip("pinocchio")
from waferscan.robot.clearance import body_for, clearance_for  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO / "resources" / "examples" / "paper.toml"
SLOW = REPO / "resources" / "examples" / "slow_jab.toml"
PROBE = Path(__file__).resolve().with_name("clearance_probe.py")
ARTIFACTS = REPO / "test-artifacts"
PAPER_LAYOUT = read_scenario(PAPER)
SLOW_LAYOUT = read_scenario(SLOW)
RED = [0.9, 0.1, 0.1]
WHITE = [255, 255, 255]

# slow_jab.toml, slot 8 in the plan's (u, v): the carrier's centre at the origin, v into it. The
# beam in the start pose at v = 240 - 400 = -160; the fork's tines 20 mm wide, centred at u = -80
# (tine_left, the emitter's) and +80 (tine_right), from 80 to 260 mm ahead of the wrist, the
# wrist 260 mm behind the beam.
JAB = SLOW_LAYOUT.scan.jab
TINES = {"tine_left": (-90.0, -70.0), "tine_right": (70.0, 90.0)}
POINTS = {"tine_right_tip": (80.0, -160.0 + JAB - 10.0),  # in tine_right at the deepest jab
          "outside": (175.0, 115.0)}


def tine_box(part, advance, angle):
    """The tine's four corners (u, v) with the fork advanced and turned, by hand."""
    u0, u1 = TINES[part]
    beam = -160.0 + advance
    wx, wy = 0.0, beam - 260.0
    corners = [(u, v) for u in (u0, u1) for v in (beam - 180.0, beam)]
    a = math.radians(angle)
    c, s = math.cos(a), math.sin(a)
    return [(wx + c * (u - wx) - s * (v - wy), wy + s * (u - wx) + c * (v - wy)) for u, v in corners]


def same_polygon(found, expected, tol=1e-6):
    return len(found) == len(expected) and all(
        min(math.dist(p, q) for q in found) < tol for p in expected)


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    # The screenshots go to test-artifacts (docs/gui-clearance*.png are copies of them).
    for name in ("gui-clearance.png", "gui-clearance-plan.png"):
        (ARTIFACTS / name).unlink(missing_ok=True)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_PAPER=str(PAPER), WAFERSCAN_GUI_SLOW=str(SLOW),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS),
                         WAFERSCAN_GUI_POINTS=json.dumps(POINTS))


def _words(text):
    """'0.650 mm (tine_left – LP1_W10)' -> (0.65, 'tine_left', 'LP1_W10')."""
    distance, rest = text.split(" mm (")
    part, obstacle = rest.rstrip(")").split(" – ")
    return float(distance), part, obstacle


WAFERS = {w.name for w in PAPER_LAYOUT.wafers} | {w.name for w in SLOW_LAYOUT.wafers}


def check_shown(text, wafers_only):
    """The clearance shown against the wafers-only body's answer: the same when a wafer is the
    nearest, no further otherwise (the scan's body also has the carrier's solids)."""
    shown = _words(text)
    if shown[2] in WAFERS:
        assert shown[0] == pytest.approx(wafers_only[0], abs=0.0006), (text, wafers_only)
        assert shown[1:] == tuple(wafers_only[1:3]), (text, wafers_only)
    else:
        assert shown[0] <= wafers_only[0] + 0.0006, (text, wafers_only)
    return shown


def test_the_scan_panel_shows_the_clearance_at_each_frame(gui):
    body = body_for(PAPER_LAYOUT)
    report = clearance_for(PAPER_LAYOUT, body)
    up = report.closest[0].motion
    least = gui["paper_report"]["least"]
    for frame in gui["paper_frames"]:
        check_shown(frame["clearance"], body.nearest(up, frame["z"]))
        assert frame["style"] == ""  # paper.toml accepts 0.5 mm: no contact at these frames
        assert frame["fork"] == gui["fork_before"]
        assert frame["least"] == f"{least['distance']:.3f} mm, min 0.5 mm"
    closest = gui["paper_frames"][-1]
    assert closest["z"] == pytest.approx(522.0)
    # The report's least against the wafers (clearance_for), seen at its frame.
    assert closest["clearance"] == "0.650 mm (tine_left – LP1_W10)"
    assert (report.least.part, report.least.obstacle) == ("tine_left", "LP1_W10")
    assert report.least.distance == pytest.approx(0.650, abs=5e-4)
    assert least["distance"] <= report.least.distance + 1e-6


def test_the_slot_code_dialog_gives_the_least_clearance(gui):
    dialog, report = gui["paper_dialog"], gui["paper_report"]
    assert dialog["label"].startswith(f"Least clearance {report['least']['words']}; "
                                      "clearance_min 0.5 mm")
    assert dialog["table"] is bool(report["contacts"])
    if not report["contacts"]:  # nothing more than the line
        assert dialog["label"].endswith("clearance_min 0.5 mm")
    assert gui["fork_after_paper"] == gui["fork_before"]


def test_a_contact_turns_the_fork_red_and_back(gui):
    assert gui["contact_min"] == 1.0
    clear, contact, clear_again, contact_again = gui["contact_frames"]
    assert clear["fork"] == gui["fork_before"] and clear["style"] == ""
    assert contact["fork"][0] == pytest.approx(RED, abs=1e-3)
    assert contact["clearance"] == "0.650 mm (tine_left – LP1_W10)"
    assert "#c01010" in contact["style"]
    least = gui["contact_report"]["least"]
    assert contact["least"] == f"{least['distance']:.3f} mm, min 1 mm"
    assert clear_again["fork"] == gui["fork_before"]
    assert contact_again["fork"][0] == pytest.approx(RED, abs=1e-3)
    # The animation ended on a red frame: the fork has its own colour again.
    assert gui["fork_after_contact"] == gui["fork_before"]
    assert (ARTIFACTS / "gui-clearance.png").stat().st_size > 10_000


def test_the_slot_code_dialog_lists_the_contacts(gui):
    contacts = gui["contact_report"]["contacts"]
    assert contacts, "clearance_min 1.0 mm: the paper's scan has a contact"
    dialog = gui["contact_dialog"]
    assert dialog["headers"] == ["Distance [mm]", "Robot", "Obstacle", "Slot", "Motion",
                                 "Position"]
    assert dialog["rows"] == [[f"{c['distance']:.3f}", c["part"], c["obstacle"],
                               "" if c["slot"] is None else str(c["slot"]), c["phase"],
                               f"at scan position {c['position']:.3f} mm"] for c in contacts]
    assert dialog["tooltips"] == [c["words"] for c in contacts]
    n = len(contacts)
    assert dialog["label"].endswith(f"{n} contact{'s' if n > 1 else ''} closer than "
                                    "clearance_min: the robot must not run this scan")
    # A contact with a wafer is clearance_for's, the layout held to 1.0 mm.
    strict = replace(PAPER_LAYOUT, mapping=replace(PAPER_LAYOUT.mapping, clearance_min=1.0))
    expected = {core.describe(c) for c in clearance_for(strict).contacts}
    assert expected == {"0.650 mm between tine_left and LP1_W10 (slot 24), fast stroke up at "
                        "scan position 522.017 mm"}
    for c in contacts:
        if c["obstacle"] in WAFERS:
            assert c["words"] in expected


def test_the_pocket_panel_shows_the_clearance_of_the_jab_and_the_sweep(gui):
    body = body_for(SLOW_LAYOUT)
    clearance_min = gui["slow_report"]["clearance_min"]
    for seen in gui["pocket_frames"]:
        slot, phase, z, advance, turn = seen["frame"]
        if phase == "sweep":
            motion = core.Motion(core.SWEEP, "sweep", slot, -1.0, 1.0, z, advance)
            wafers_only = body.nearest(motion, turn)
        else:
            wafers_only = body.nearest(core.Motion(core.JAB, "jab", slot, 0.0, JAB, z), advance)
        shown = check_shown(seen["clearance"], wafers_only)
        red = shown[0] < clearance_min
        assert (seen["fork"][0] == pytest.approx(RED, abs=1e-3)) is red, seen
        assert ("#c01010" in seen["style"]) is red
    assert gui["fork_after_pockets"][0] != pytest.approx(RED, abs=1e-3)


def test_the_plan_draws_where_the_fork_went(gui):
    drawn = [tuple(d) for d in gui["plan_drawn"]]
    assert ("fork", "tine_left") in drawn and ("fork", "tine_right") in drawn
    swept = {s["part"]: s for s in gui["swept"]}
    _, depth, reached = gui["slow_pockets"]["8"]
    low, high = reached or (-SLOW_LAYOUT.scan.sweep, SLOW_LAYOUT.scan.sweep)
    assert depth == pytest.approx(JAB)
    for part in TINES:
        s = swept[part]
        assert s["advance"] == pytest.approx(depth)
        assert s["angles"] == pytest.approx([low, high])
        outlines = s["outlines"]
        assert same_polygon(outlines["start"], tine_box(part, 0.0, 0.0))
        assert same_polygon(outlines["deepest"], tine_box(part, depth, 0.0))
        assert same_polygon(outlines["sweep low"], tine_box(part, depth, low))
        assert same_polygon(outlines["sweep high"], tine_box(part, depth, high))
        assert s["pieces"] == 1 + math.ceil(high - low)  # the jab's, then one a degree
    colour, alpha = gui["fork_colour"]
    tint = [round(255 - alpha / 255 * (255 - c)) for c in colour]
    seen = gui["plan_points"]
    assert all(abs(a - b) <= 25 for a, b in zip(seen["tine_right_tip"], tint)), seen
    assert seen["outside"] == WHITE
    assert "violet: where the fork went" in gui["plan_legend"]
    assert (ARTIFACTS / "gui-clearance-plan.png").stat().st_size > 10_000
