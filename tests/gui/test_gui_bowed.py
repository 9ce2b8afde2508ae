"""Bowed wafers drawn bowed in the 3D view (SPEC §10, issue 14): a layout with bowed wafers
built headless (`waferscan layout`) opens in the GUI with each bowed wafer drawn as its
paraboloid (what Coin draws spans t + |bow| along the normal, a flat one t) and the front view
rendered to docs/gui-bowed-wafers.png (bows exaggerated to 4 mm to be seen at 300 mm)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("bowed_probe.py")
SCREENSHOT = REPO / "test-artifacts" / "gui-bowed-wafers.png"
BOW = 4.0  # mm: a real wafer bows 0.1 mm at most (SEMI M1); 4 mm shows at a carrier's scale


def bowed_scenario(folder):
    """The paper's layout without its robot, every wafer bowed BOW (centre up) and slot 2's
    by -BOW (centre down)."""
    text = (REPO / "resources" / "examples" / "paper.toml").read_text(encoding="utf-8")
    text = re.sub(r"\[robot\]\n(?:.*\n)*?\n", "", text)
    text = text.replace('load = "1101221001220001010000010"\n',
                        f'load = "1101221001220001010000010"\nwafer_bow = {BOW}\n')
    text += f'\n[[wafer]]\ncarrier = "LP1"\nslot = 2\nstate = "present"\nbow = {-BOW}\n'
    path = folder / "bowed.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def gui(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("bowed")
    layout = folder / "bowed.FCStd"
    subprocess.run([sys.executable, "-m", "waferscan.cli", "layout", str(bowed_scenario(folder)),
                    "-o", str(layout)], check=True, cwd=REPO, capture_output=True, timeout=300)
    SCREENSHOT.parent.mkdir(exist_ok=True)
    if SCREENSHOT.exists():
        SCREENSHOT.unlink()
    return run_gui_probe(PROBE, WAFERSCAN_GUI_LAYOUT=str(layout),
                         WAFERSCAN_GUI_SCREENSHOT=str(SCREENSHOT))


def test_each_bowed_wafer_is_drawn_bowed(gui):
    wafers = gui["wafers"]
    assert len(wafers) == 10
    assert wafers["LP1_W02"]["bow"] == -BOW
    for label, wafer in wafers.items():
        assert wafer["shown"], label
        assert wafer["type"] == "Part::FeaturePython" and wafer["icon"] == "ViewProviderRole"
        bow, z = wafer["bow"], wafer["z"]
        assert abs(bow) == BOW
        zmin, zmax, xmin, xmax = wafer["drawn"]
        # Level wafers: the rim's bottom at the placement's Z, the centre bow off it.
        if label not in ("LP1_W04", "LP1_W07"):  # cross-slotted: tilted
            assert zmin == pytest.approx(z + min(0.0, bow), abs=1e-3)
            assert zmax == pytest.approx(z + 0.7 + max(0.0, bow), abs=1e-3)
        assert xmax - xmin == pytest.approx(300.0, abs=0.5)


def test_the_front_view_is_saved():
    assert SCREENSHOT.stat().st_size > 5000
