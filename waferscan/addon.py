"""Where the addon lives on disk, and how FreeCAD finds the packages of the project's venv.

FreeCAD 0.20 runs an addon's Init.py and InitGui.py with ``exec``: they have no ``__file__``,
so they cannot locate the addon folder themselves. They import this module, whose ``__file__``
is inside the addon, and ask it. No FreeCAD import here: this module also runs in plain Python.
"""

import os
import site
import sys
from pathlib import Path

from .core.errors import InputError

# realpath: FreeCAD may import the package through the Mod folder's link to the checkout; the
# addon has one canonical location either way.
ADDON_ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))


def addon_root():
    """The addon's top folder (the one holding Init.py, InitGui.py and package.xml)."""
    return ADDON_ROOT


def icon_path(name="WaferScan.svg"):
    """Absolute path of an icon in ``resources/icons``."""
    return os.path.join(ADDON_ROOT, "resources", "icons", name)


def paper_scenario():
    """The paper's experiment as a scenario file (resources/examples/paper.toml), a Path."""
    return Path(ADDON_ROOT) / "resources" / "examples" / "paper.toml"


def venv_dir():
    """The project's venv: ``$WAFERSCAN_VENV`` if set, else ``<addon root>/.venv``.

    WAFERSCAN_VENV lets one checkout serve two FreeCADs: the FreeCAD 1.0 test root keeps a venv
    of its own for its Python (scripts/freecad1-run.sh), next to the checkout's bookworm one.
    """
    return os.environ.get("WAFERSCAN_VENV") or os.path.join(ADDON_ROOT, ".venv")


def venv_site_packages():
    """The site-packages folder of the project's venv (``venv_dir``) for this Python version,
    or None.

    Only a venv made for the running Python's major.minor version counts: its compiled
    packages (pinocchio) would not load in another one.
    """
    version = "python%d.%d" % sys.version_info[:2]
    path = os.path.join(venv_dir(), "lib", version, "site-packages")
    return path if os.path.isdir(path) else None


def add_venv_site_packages():
    """Make the venv's packages (pinocchio) importable inside freecad / freecadcmd.

    FreeCAD ignores PYTHONPATH, and pin installs its modules behind ``.pth`` files, so the
    folder is added with ``site.addsitedir``, which reads them. It appends to ``sys.path``:
    Debian's numpy 1.24, which FreeCAD's own modules are built against, stays ahead of the
    venv's numpy 2.x. Does nothing when there is no venv or it is already on the path (as
    in the venv's own Python). Returns the folder added, or None.
    """
    path = venv_site_packages()
    if path is None or os.path.realpath(path) in {os.path.realpath(p) for p in sys.path}:
        return None
    site.addsitedir(path)
    return path


# --- pinocchio, which only the robot needs -------------------------------------------------

# The pip distribution that provides ``import pinocchio``; the version pyproject.toml pins
# (a test keeps the two equal).
PIN_REQUIREMENT = "pin==4.1.0"


def pinocchio_available():
    """True when ``import pinocchio`` would find the module (without importing it: the import
    costs a second, and FreeCAD's start-up should not pay it)."""
    import importlib.util

    return importlib.util.find_spec("pinocchio") is not None


def missing_pinocchio_message():
    """One sentence: pinocchio is missing, what still works, and the command that fixes it.

    Installed by the Addon Manager, the addon is a plain clone: no venv, so no pinocchio
    (the Addon Manager installs only packages on FreeCAD's allow-list; pin is not on it).
    """
    return ("pinocchio (pip package %s) is not installed for FreeCAD's Python %d.%d, so "
            "layouts with a robot cannot be built or scanned (all else works); to install it, "
            "run: make -C '%s' setup  (then restart FreeCAD)"
            % (PIN_REQUIREMENT, sys.version_info[0], sys.version_info[1], ADDON_ROOT))


def require_pinocchio():
    """Raise ``MissingPinocchio`` (one clear line, no traceback in the CLI or the GUI) when
    pinocchio cannot be imported; called where the robot's kinematics are first needed."""
    if not pinocchio_available():
        raise MissingPinocchio()


class MissingPinocchio(InputError):
    """The robot needs pinocchio and it is missing. An InputError, so that the command line
    (one line on stderr, exit status 2) and the GUI's commands (a message, no traceback)
    report it the way they report a layout they cannot use."""

    def __init__(self):
        super().__init__("robot", None, missing_pinocchio_message())
