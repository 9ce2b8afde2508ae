"""The command that starts a program under a virtual X server of its own (``xvfb-run``).

``xvfb-run -a`` takes the first display number whose lock file is not in ``/tmp``, counting from
``-n`` (99 by default). Two X servers that cannot see each other's ``/tmp`` (this machine and a
chroot, such as the FreeCAD 1.0 test root) both pick ``:99``, while their listening sockets live
in the network namespace they share: the second server fails to start, and Debian's xvfb-run
tries the next number (up to ten times). ``WAFERSCAN_XVFB_FIRST`` sets where the count starts,
so that such a pair does not meet at all (``scripts/freecad1-run.sh`` starts its root's displays
at :200). No FreeCAD import here.
"""

import os

from ..core.errors import InputError

__all__ = ["first_display", "xvfb_run"]

DEFAULT_FIRST = 99  # xvfb-run's own
# X display numbers above this collide with nothing real but are past what a run would use.
LAST_FIRST = 60000


def first_display(environ=None):
    """The display number ``xvfb-run -a`` counts from: ``$WAFERSCAN_XVFB_FIRST``, else 99. A
    value that is not a whole number from 1 to 60000 raises InputError naming it."""
    text = (os.environ if environ is None else environ).get("WAFERSCAN_XVFB_FIRST", "").strip()
    if not text:
        return DEFAULT_FIRST
    if not (text.isascii() and text.isdecimal()) or not 1 <= int(text) <= LAST_FIRST:
        raise InputError("WAFERSCAN_XVFB_FIRST", None, f"{text!r}: a display number from 1 "
                         f"to {LAST_FIRST} is expected")
    return int(text)


def xvfb_run(screen, environ=None):
    """The ``xvfb-run`` prefix for a program on a fresh ``screen`` ("WIDTHxHEIGHT", 24-bit)."""
    return ["xvfb-run", "-a", "-n", str(first_display(environ)), "-s",
            f"-screen 0 {screen}x24"]
