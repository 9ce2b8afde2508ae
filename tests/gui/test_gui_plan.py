"""Each probed pocket of a slow scan seen from above, in the slot-code dialog (SPEC §13, issue
17: "a plan view of each pocket showing where the beam met the wafer"). The probe reads back
what the canvas drew and the colour of the rendered pixels at plan points worked out by hand
for resources/examples/slow_jab.toml at the paper's depth, scanned by the core's closed forms
alone (the whole ±40°, the tines' strikes drawn: scenarios.SLOW_JAB_DEEP_TEXT; carrier centre at
the origin, v into the carrier)."""

import json
import math
from pathlib import Path

import pytest
from scenarios import SLOW_JAB_DEEP_TEXT, slow_jab_deep

from waferscan.core.scan.layout_scan import scan_layout

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("plan_probe.py")
ARTIFACTS = REPO / "test-artifacts"
RESULT = scan_layout(slow_jab_deep())
DEEPEST_V = 240.0 + 26.6 - 400.0
WRIST = (0.0, DEEPEST_V - 260.0)
WHITE = [255, 255, 255]


def _tine_on_rim(slot, angle, center):
    """The end of the deepest beam, turned about the wrist by ``angle``, that lies on the rim."""
    a = math.radians(angle)
    for u in (-80.0, 80.0):
        dx, dy = u - WRIST[0], DEEPEST_V - WRIST[1]
        p = (WRIST[0] + math.cos(a) * dx - math.sin(a) * dy,
             WRIST[1] + math.sin(a) * dx + math.cos(a) * dy)
        if abs(math.dist(p, center) - 150.0) < 1e-6:
            return p
    raise AssertionError(f"slot {slot}: no tine on the rim at {angle}")


def _turned_tine(u, angle):
    """The deepest beam's end at u (-80: the emitter's tine), turned about the wrist."""
    a = math.radians(angle)
    dx, dy = u - WRIST[0], DEEPEST_V - WRIST[1]
    return (WRIST[0] + math.cos(a) * dx - math.sin(a) * dy,
            WRIST[1] + math.sin(a) * dx + math.cos(a) * dy)


def _points():
    points = {}
    for slot, center in ((8, (0.0, -5.0)), (3, (3.0, 0.0))):
        probe = next(p for p in RESULT.pockets if p.slot == slot)
        points[slot] = {
            # Midway along the emitter's tine's path inside the wafer (its strike range).
            "strike": _turned_tine(-80.0, 0.5 * sum(probe.strike[0])),
            "front": (center[0], center[1] - 150.0),  # the rim's front point
            "sweep first": _tine_on_rim(slot, probe.sweep[0], center),
            "sweep last": _tine_on_rim(slot, probe.sweep[1], center),
            "rim back": (center[0], center[1] + 150.0),
            "inside": (center[0] + 40.0, center[1] + 40.0),
            "outside": (center[0] + 175.0, center[1] + 120.0),
        }
    points[5] = {"inside": (40.0, 40.0)}
    return points


@pytest.fixture(scope="module")
def gui(run_gui_probe, tmp_path_factory):
    (ARTIFACTS / "gui-pocket-plan.png").unlink(missing_ok=True)
    example = tmp_path_factory.mktemp("plan") / "slow_jab_deep.toml"
    example.write_text(SLOW_JAB_DEEP_TEXT)
    return run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(example),
                         WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS),
                         WAFERSCAN_GUI_POINTS=json.dumps(_points()))


def _near(rgb, expected, tolerance=40):
    return all(abs(a - b) <= tolerance for a, b in zip(rgb, expected))


def test_the_dialog_offers_each_probed_pocket_judged_ones_first(gui):
    assert gui["tabs"] == ["Side view", "Pockets from above"]
    assert len(gui["chooser"]) == 25 and gui["chooser"][7] == "slot 8  (6)"
    assert gui["first_shown"] == 3  # off position by its sweep (5), then slot 8 (6)
    assert gui["slots"]["8"]["chosen"] == "slot 8  (6)"


def test_it_draws_the_wafer_the_seated_outline_the_beams_and_where_they_met(gui):
    drawn = [tuple(d) for d in gui["slots"]["8"]["drawn"]]
    probe = next(p for p in RESULT.pockets if p.slot == 8)
    for item in [("seated", "seated_8"), ("wafer", "LP1_W06"), ("start", "start pose"),
                 ("front", "front 5.000 mm"), ("deepest", "jab 26.6 mm"),
                 ("sweep first", f"{probe.sweep[0]:+.3f}°"),
                 ("sweep last", f"{probe.sweep[1]:+.3f}°"),
                 ("contact", "front 5.000 mm"), ("contact", f"{probe.sweep[0]:+.3f}°"),
                 ("contact", f"{probe.sweep[1]:+.3f}°"), ("wrist", "inside")]:
        assert item in drawn
    title = dict((k, v) for k, v in drawn if k == "title")["title"]
    assert title == ("slot 8 at Z 364.290 mm: front 5.000 mm (seated 10.000); sweep -33.845° to "
                     "+33.845°, shift +0.000 mm")


@pytest.mark.parametrize("slot", ["8", "3"])
def test_the_contact_points_are_painted_where_the_hand_computation_puts_them(gui, slot):
    seen = gui["slots"][slot]["points"]
    colours = gui["beam_colours"]  # the canvas's own, each role its own colour
    assert len({tuple(colours[r]) for r in ("front", "sweep first", "sweep last")}) == 3
    for role in ("front", "sweep first", "sweep last"):
        assert _near(seen[role]["rgb"], colours[role]), (role, seen[role])
    # The wafer's outline at its back point, its fill inside it, nothing outside.
    assert seen["rim back"]["rgb"] != WHITE
    assert seen["inside"]["rgb"] != WHITE and seen["inside"]["rgb"] != seen["rim back"]["rgb"]
    assert seen["outside"]["rgb"] == WHITE


@pytest.mark.parametrize("slot", ["8", "3"])
def test_the_tines_path_inside_the_wafer_is_marked(gui, slot):
    probe = next(p for p in RESULT.pockets if p.slot == int(slot))
    drawn = [tuple(d) for d in gui["slots"][slot]["drawn"]]
    (low, high), (low2, high2) = probe.strike
    assert ("strike", f"emitter tine in the wafer {low:+.3f}° to {high:+.3f}°") in drawn
    assert ("strike", f"receiver tine in the wafer {low2:+.3f}° to {high2:+.3f}°") in drawn
    assert _near(gui["slots"][slot]["points"]["strike"]["rgb"], gui["strike_colour"])


def test_a_protrusion_is_drawn_at_its_size(gui):
    # 5 mm between the wafer's front point and a seated one's at the canvas's scale.
    front = gui["slots"]["8"]["points"]["front"]["pixel"]
    back = gui["slots"]["8"]["points"]["rim back"]["pixel"]
    scale = gui["slots"]["8"]["scale"]
    assert back[1] - front[1] == pytest.approx(-300.0 * scale)
    assert scale > 0.5  # a 5 mm protrusion is a few pixels at least
    # The scale bar: the first of 10, 20, 50, 100… mm that is at least 40 px long.
    bar = dict((k, v) for k, v in map(tuple, gui["slots"]["8"]["drawn"]))["scale bar"]
    lengths = [m * 10 ** e for e in range(1, 5) for m in (1, 2, 5)]
    assert bar == f"{next(n for n in lengths if n * scale >= 40.0)} mm"


def test_a_pocket_the_probes_never_blocked_shows_its_wafer_and_no_contact(gui):
    drawn = [tuple(d) for d in gui["slots"]["5"]["drawn"]]
    assert not [d for d in drawn if d[0] in ("front", "contact", "sweep first")]
    assert ("title", "slot 5 at Z 334.290 mm: jab met nothing (seated 10.000); sweep met "
                     "nothing") in drawn


def test_the_dialog_shows_the_fast_and_slow_durations_side_by_side(gui):
    from waferscan.core.scan import slow_scan

    layout = RESULT.layout
    fast = slow_scan.fast_duration(layout.scan)
    assert fast == pytest.approx((550.0 - 280.0) / 100.0)  # one stroke at scan_speed
    slow = slow_scan.slow_duration(layout.scan, RESULT.plan, RESULT.pockets)
    # slow_jab.toml sets no lift acceleration: the label says so (issue 27 item 15).
    assert gui["duration_label"] == (f"Simulated duration:\nfast {fast:.2f} s, slow {slow:.2f} s"
                                     "\n(lift acceleration not set)")


def test_a_picture_of_the_dialog_is_left(gui):
    assert (ARTIFACTS / "gui-pocket-plan.png").stat().st_size > 10_000


def test_the_legend_wraps_at_the_size_the_dialog_opens_at(gui):
    """Issue 27 item 15: at the dialog's default size the legend ran off both sides of the
    canvas, on one line; now it wraps onto lines inside it, whole."""
    width, height = gui["default_canvas"]
    legend = gui["default_legend"]
    assert legend["one_line_width"] > width - 8  # one line would be clipped here
    x, y, box_width, box_height = legend["box"]
    assert x >= 0 and x + box_width <= width and y >= 0 and y + box_height <= height
    assert box_height >= 2 * legend["line_height"] - 1e-6
    assert "crimson: a tine inside the wafer" in legend["drawn"][0][1]
    # The title (slot, Z, front, sweep) wraps as well, above the legend.
    assert legend["title_width"] > width - 8
    x, y, box_width, box_height = legend["title"]
    assert x >= 0 and x + box_width <= width and box_height >= 2 * legend["line_height"] - 1e-6
    assert y + box_height < legend["box"][1]
