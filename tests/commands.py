"""The command line run as a user runs it: ``python -m waferscan.cli`` from the repository
root in a process of its own, and FreeCAD's ``freecadcmd -c`` running code or the same
command line inside FreeCAD."""

import subprocess
import sys

from scenarios import ROOT

__all__ = ["CLI", "waferscan", "freecadcmd", "cli_in_freecad"]

CLI = [sys.executable, "-m", "waferscan.cli"]


def waferscan(*args, cwd=ROOT, timeout=300, env=None):
    """``waferscan ARGS…`` (each argument str()-ed) run to its end, its output captured as
    text; the ``CompletedProcess``."""
    return subprocess.run([*CLI, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def freecadcmd(code, timeout=300, env=None):
    """``freecadcmd -c CODE`` from the repository root, its output captured as text."""
    return subprocess.run(["freecadcmd", "-c", code], cwd=ROOT, capture_output=True, text=True,
                          timeout=timeout, env=env)


def cli_in_freecad(*args):
    """Code for ``freecadcmd -c`` that runs ``waferscan ARGS…`` in FreeCAD's own Python, this
    checkout's package first on its path."""
    return (f"import sys; sys.path.insert(0, {str(ROOT)!r}); import waferscan.cli as c; "
            f"c.main({[str(a) for a in args]!r})")
