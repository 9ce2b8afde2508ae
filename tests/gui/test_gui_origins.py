"""A layout saved headless opens in the GUI with its Parts' origins hidden, as FreeCAD's GUI
makes a Part: before, the robot's axes and planes (with their 3D labels) covered the scene and
were resized at every frame of an animated scan."""

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("layout_probe.py")


def test_saved_layout_opens_with_the_origins_hidden(run_gui_probe, tmp_path):
    layout = tmp_path / "paper.FCStd"
    subprocess.run([sys.executable, "-m", "waferscan.cli", "layout",
                    str(REPO / "resources" / "examples" / "paper.toml"), "-o", str(layout)],
                   check=True, cwd=REPO, capture_output=True, timeout=300)
    result = run_gui_probe(PROBE, WAFERSCAN_GUI_LAYOUT=str(layout),
                           WAFERSCAN_GUI_SCREENSHOT=str(tmp_path / "view.png"))
    origins = result["origins_shown"]
    # The paper has two Parts (the carrier's assembly and the robot): two origins, six
    # features each.
    assert len(origins) == 14, origins
    assert not any(origins.values()), [name for name, shown in origins.items() if shown]
    # Everything else is still shown.
    assert result["shown"]["Robot"] and result["shown"]["LP1"] and result["shown"]["Scanner"]
