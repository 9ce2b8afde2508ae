"""Where the addon lives on disk, and how FreeCAD finds the packages of the project's venv.

FreeCAD 0.20 runs an addon's Init.py and InitGui.py with ``exec``: they have no ``__file__``,
so they cannot locate the addon folder themselves. They import this module, whose ``__file__``
is inside the addon, and ask it. No FreeCAD import here: this module also runs in plain Python.
"""

import os
import site
import sys

# realpath: FreeCAD may import the package through the Mod folder's link to the checkout; the
# addon has one canonical location either way.
ADDON_ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))


def addon_root():
    """The addon's top folder (the one holding Init.py, InitGui.py and package.xml)."""
    return ADDON_ROOT


def icon_path(name="WaferScan.svg"):
    """Absolute path of an icon in ``resources/icons``."""
    return os.path.join(ADDON_ROOT, "resources", "icons", name)


def venv_site_packages():
    """The site-packages folder of ``<addon root>/.venv`` for this Python version, or None.

    Only a venv made for the running Python's major.minor version counts: its compiled
    packages (pinocchio) would not load in another one.
    """
    version = "python%d.%d" % sys.version_info[:2]
    path = os.path.join(ADDON_ROOT, ".venv", "lib", version, "site-packages")
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
