"""Run scan's animation moves the robot (or a scanner no robot carries) in the 3D view only
(gui/animation.ViewPose): the view draws each moved object where the document path would have
placed it, the document is left as it was, and stopping puts the view back on the document."""

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("view_pose_probe.py")
PAPER = REPO / "resources" / "examples" / "paper.toml"


def without_robot(text):
    """The scenario's text without its [robot] table: the scanner alone, moved by placement."""
    lines, skipping = [], False
    for line in text.splitlines():
        if line.startswith("["):
            skipping = line.strip() == "[robot]"
        if not skipping:
            lines.append(line)
    return "\n".join(lines) + "\n"


def layout_of(scenario, folder):
    layout = folder / f"{scenario.stem}.FCStd"
    subprocess.run([sys.executable, "-m", "waferscan.cli", "layout", str(scenario), "-o",
                    str(layout)], check=True, cwd=REPO, capture_output=True, timeout=300)
    return layout


def close(a, b, tolerance):
    # The view's fields are single precision; a quaternion and its negation are one rotation.
    if all(abs(x - y) <= tolerance for x, y in zip(a[:3], b[:3])):
        q, r = a[3:], b[3:]
        return abs(abs(sum(x * y for x, y in zip(q, r))) - 1.0) < 1e-6
    return False


@pytest.mark.parametrize("robot", [True, False], ids=["robot", "scanner"])
def test_the_animation_moves_the_view_not_the_document(run_gui_probe, tmp_path, robot):
    scenario = PAPER
    if not robot:
        scenario = tmp_path / "paper-no-robot.toml"
        scenario.write_text(without_robot(PAPER.read_text()))
    gui = run_gui_probe(PROBE, WAFERSCAN_GUI_LAYOUT=str(layout_of(scenario, tmp_path)))
    assert gui["view_pose"] is True
    # Its frames are timed precisely (Qt's coarse timer may fire 5 % late: 63.5 frames a second
    # at most instead of 66.7 for Run scan's 15 ms frames).
    assert gui["timer_precise"] is True
    assert len(gui["moved"]) == (6 if robot else 1)  # five links and the scanner, or the scanner
    assert gui["fault"] is None
    lift = gui["z"] - gui["start_z"]
    assert lift > 40.0  # paused well into the scan
    for name in gui["moved"]:
        # The document is where it was; the view draws where the document path places it.
        assert gui["document_during"][name] == gui["document_start"][name], name
        assert close(gui["drawn_during"][name], gui["document_path"][name], 1e-3), name
        assert close(gui["drawn_start"][name], gui["document_start"][name], 1e-3), name
        # After the stop, the view is back on the document, which never moved.
        assert close(gui["drawn_after"][name], gui["document_start"][name], 1e-3), name
        # (The probe's own pass through the document path put it back to within rounding.)
        assert gui["document_after"][name] == pytest.approx(gui["document_start"][name],
                                                            abs=1e-9), name
    # The scanner is drawn lifted by the scan's travel so far (a lift along Z).
    scanner = gui["moved"][-1]
    assert gui["drawn_during"][scanner][2] - gui["drawn_start"][scanner][2] == \
        pytest.approx(lift, abs=1e-3)
    # Nothing in the document was touched by the animation.
    assert gui["touched_during"] == gui["touched_before"]
