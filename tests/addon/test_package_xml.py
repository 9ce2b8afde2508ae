"""package.xml as FreeCAD reads it: its own metadata reader (App.Metadata) and the Addon
Manager's dependency walk, both from the FreeCAD that runs the tests (0.20.2 on bookworm,
1.0 in the trixie root of `make test-freecad1`)."""

import ast
import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest
from processes import RUN_VARIABLE

REPO = Path(__file__).resolve().parents[2]
PACKAGE_XML = REPO / "package.xml"
FREECAD_LIB = "/usr/lib/freecad-python3/lib"
FREECADCMD = shutil.which("freecadcmd")


@pytest.fixture(scope="module")
def metadata():
    if FREECAD_LIB not in sys.path:
        sys.path.append(FREECAD_LIB)
    import FreeCAD

    return FreeCAD.Metadata(str(PACKAGE_XML))


def _is_svg(path):
    return ElementTree.parse(path).getroot().tag in {"svg", "{http://www.w3.org/2000/svg}svg"}


def _workbench_class_in_initgui():
    """The name of the class InitGui.py registers (a FreeCADGui.Workbench subclass)."""
    tree = ast.parse((REPO / "InitGui.py").read_text(encoding="utf-8"))
    return [node.name for node in tree.body if isinstance(node, ast.ClassDef)
            and any(ast.unparse(base).endswith("Workbench") for base in node.bases)]


def test_freecad_reads_name_version_and_icon(metadata):
    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert metadata.Name == "WaferScan"
    assert metadata.Version == project["version"]
    if hasattr(metadata, "Date"):  # FreeCAD 1.0 reads the date too
        assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", metadata.Date)
    assert metadata.Icon and _is_svg(REPO / metadata.Icon)


def test_the_workbench_entry_matches_initgui(metadata):
    (workbench,) = metadata.Content["workbench"]
    assert [workbench.Classname] == _workbench_class_in_initgui()
    assert _is_svg(REPO / workbench.Subdirectory / workbench.Icon)
    assert workbench.FreeCADMin == "0.20.0"


def test_python_dependencies_are_declared(metadata):
    depends = {d["package"]: d for d in metadata.Depend}
    assert set(depends) == {"numpy", "pinocchio"}
    # FreeCAD 1.0's reader also reports a dependency's type and whether it is optional.
    if "type" in depends["numpy"]:
        assert {d["type"] for d in depends.values()} == {"python"}
    if "optional" in depends["numpy"]:
        assert not depends["numpy"]["optional"] and depends["pinocchio"]["optional"]


def test_pin_requirement_matches_pyproject():
    from waferscan.addon import PIN_REQUIREMENT

    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert PIN_REQUIREMENT in project["dependencies"]


# Runs in freecadcmd: the Addon Manager's own Addon class reads package.xml and walks its
# dependencies as it does before an install. Its attribute for required Python packages is
# python_required in 0.20 and python_requires in 1.0.
ADDON_MANAGER_PROBE = r"""
import json, os, sys
import FreeCAD
sys.path.insert(0, os.path.join(FreeCAD.getHomePath(), "Mod", "AddonManager"))
from Addon import Addon
addon = Addon("WaferScan", "https://example.invalid/WaferScan.git", Addon.Status.NOT_INSTALLED, "main")
addon.load_metadata_file(PACKAGE_XML)
deps = Addon.Dependencies()
addon.walk_dependency_tree({}, deps)
required = deps.python_requires if hasattr(deps, "python_requires") else deps.python_required
print("WS_RESULT=" + json.dumps({"name": addon.display_name, "required": sorted(required),
                                 "optional": sorted(deps.python_optional),
                                 "workbenches": sorted(deps.internal_workbenches)}))
"""


@pytest.mark.skipif(FREECADCMD is None, reason="FreeCAD (freecadcmd) is not installed")
def test_the_addon_manager_reads_the_dependencies(metadata, tmp_path):
    probe = ADDON_MANAGER_PROBE.replace("PACKAGE_XML", repr(str(PACKAGE_XML)))
    proc = subprocess.run([FREECADCMD, "-c", probe], capture_output=True, text=True,
                          timeout=120, stdin=subprocess.DEVNULL, cwd=tmp_path,
                          env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path),
                               "FREECAD_USER_HOME": str(tmp_path), "LANG": "C.UTF-8",
                               RUN_VARIABLE: os.environ[RUN_VARIABLE]})
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("WS_RESULT=")]
    assert proc.returncode == 0 and lines, f"{proc.stdout}\n{proc.stderr}"
    result = json.loads(lines[-1][len("WS_RESULT="):])
    assert result["name"] == "WaferScan"
    assert result["workbenches"] == []
    assert "numpy" in result["required"]
    if "optional" in metadata.Depend[0]:
        # An Addon Manager that knows optional dependencies (1.0) installs without pinocchio.
        assert result["optional"] == ["pinocchio"] and result["required"] == ["numpy"]
    else:
        # 0.20's lists it among the required ones, which it cannot install: it says so
        # ("must install the following Python packages manually") and installs on OK.
        assert result["required"] == ["numpy", "pinocchio"] and result["optional"] == []


def test_the_licence_file_is_the_lgpl_and_every_metadata_names_it(metadata):
    (licence,) = metadata.License
    assert licence == {"name": "LGPL-2.1-or-later", "file": "LICENSE"}
    text = (REPO / licence["file"]).read_text(encoding="utf-8")
    assert "GNU LESSER GENERAL PUBLIC LICENSE" in text and "Version 2.1, February 1999" in text
    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["license"] == licence["name"]
    assert project["license-files"] == [licence["file"]]
