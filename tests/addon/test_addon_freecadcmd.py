"""The addon as headless FreeCAD loads it: through the Mod link that `make setup` makes."""

import json
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
FREECADCMD = shutil.which("freecadcmd")

pytestmark = pytest.mark.skipif(FREECADCMD is None, reason="FreeCAD (freecadcmd) is not installed")

# Runs inside freecadcmd, where Init.py of every addon has already run. A one-joint URDF checks
# that pinocchio works on the numpy FreeCAD runs with, not only that it imports.
PROBE = r"""
import json, os, sys
import FreeCAD, Part, numpy, pinocchio, waferscan, waferscan.addon
urdf = '''<robot name="lift">
  <link name="base"/><link name="carriage"/>
  <joint name="z" type="prismatic"><parent link="base"/><child link="carriage"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/><limit lower="0" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>'''
model = pinocchio.buildModelFromXML(urdf)
data = model.createData()
pinocchio.framesForwardKinematics(model, data, numpy.array([0.25]))
tip = data.oMf[model.getFrameId("carriage")].translation
print("WS_RESULT=" + json.dumps({
    "mod_link": os.path.realpath(os.path.join(FreeCAD.getUserAppDataDir(), "Mod", "WaferScan")),
    "waferscan_file": os.path.realpath(waferscan.__file__),
    "addon_root": os.path.realpath(waferscan.addon.addon_root()),
    "venv_site_packages": waferscan.addon.venv_site_packages(),
    "sys_path": sys.path,
    "numpy_file": numpy.__file__,
    "numpy_version": numpy.__version__,
    "pinocchio_version": pinocchio.__version__,
    "tip": [float(x) for x in tip],
    "cylinder_volume": Part.makeCylinder(150, 0.7).Volume,
}))
"""


@pytest.fixture(scope="module")
def probe():
    proc = subprocess.run(
        [FREECADCMD, "-c", PROBE],
        capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL,
    )
    assert proc.returncode == 0, f"freecadcmd failed:\n{proc.stdout}\n{proc.stderr}"
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("WS_RESULT=")]
    assert lines, f"no result from freecadcmd:\n{proc.stdout}\n{proc.stderr}"
    return json.loads(lines[-1][len("WS_RESULT="):])


def test_mod_link_points_to_this_checkout(probe):
    assert probe["mod_link"] == str(REPO)
    assert probe["addon_root"] == str(REPO)
    assert probe["waferscan_file"] == str(REPO / "waferscan" / "__init__.py")


def test_pinocchio_works_inside_freecadcmd(probe):
    assert probe["pinocchio_version"].startswith("4.")
    assert probe["tip"] == pytest.approx([0.1, 0.0, 0.25])


def test_venv_comes_after_debians_numpy(probe):
    # FreeCAD's compiled modules are built against Debian's numpy: the venv's numpy 2.x must
    # not shadow it inside FreeCAD (Init.py appends the venv, never prepends it).
    assert probe["venv_site_packages"] is not None
    assert probe["venv_site_packages"] in probe["sys_path"]
    assert not probe["numpy_file"].startswith(str(REPO / ".venv")), probe["numpy_file"]
    assert probe["cylinder_volume"] == pytest.approx(3.141592653589793 * 150**2 * 0.7)
