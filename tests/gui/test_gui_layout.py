"""A layout built headless (`waferscan layout`) opens in the FreeCAD GUI with everything shown."""

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("layout_probe.py")
SCREENSHOT = REPO / "test-artifacts" / "layout-paper-robot.png"


def test_headless_layout_opens_visible_in_the_gui(run_gui_probe, tmp_path):
    layout = tmp_path / "paper.FCStd"
    subprocess.run([sys.executable, "-m", "waferscan.cli", "layout",
                    str(REPO / "resources" / "examples" / "paper.toml"), "-o", str(layout)],
                   check=True, cwd=REPO, capture_output=True, timeout=300)
    SCREENSHOT.parent.mkdir(exist_ok=True)
    if SCREENSHOT.exists():
        SCREENSHOT.unlink()
    result = run_gui_probe(PROBE, WAFERSCAN_GUI_LAYOUT=str(layout),
                           WAFERSCAN_GUI_SCREENSHOT=str(SCREENSHOT))
    # Opened without a word in the report view: the view data written headless once lacked the
    # camera FreeCAD reads after it ("Reading failed from embedded file: GuiDocument.xml").
    assert result["report"] == ""
    shown = result["shown"]
    for label in ["LP1", "LP1 assembly", "Robot", "robot fork", "Scanner"] + \
            [f"LP1_W{i:02d}" for i in range(1, 11)]:
        assert shown[label], f"{label} is hidden"
    # The rendered view is not blank: the robot and the carrier cover a good part of it.
    assert result["drawn_fraction"] > 0.05
