"""The GUI's scan animation measured in a real FreeCAD GUI (under Xvfb when there is no
display): ``waferscan/gui/animation_bench.py`` plays Run scan and counts the frames shown; this
module starts it in a session of its own and reads its result.

Exports ``gui_animation``."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import tempfile
from pathlib import Path

from ..addon import addon_root
from .xvfb import xvfb_run

__all__ = ["gui_animation"]

# The script the FreeCAD GUI runs (it imports FreeCADGui, so it lives with the GUI's code).
ANIMATION_SCRIPT = Path(addon_root()) / "waferscan" / "gui" / "animation_bench.py"


def gui_animation(layout_path, seconds=3.0):
    """Placement updates a second (set, and shown by the 3D view), and the longest stall, of
    the GUI's scan animation with its task panel (as Run scan plays it) on the layout in a real
    FreeCAD GUI (under Xvfb when there is no display). None without FreeCAD's GUI or Xvfb."""
    freecad = shutil.which("freecad")
    if freecad is None:
        return None
    command = [freecad, str(ANIMATION_SCRIPT)]
    if not os.environ.get("DISPLAY"):
        if shutil.which("xvfb-run") is None:
            return None
        command = xvfb_run("1280x800") + command
    with tempfile.TemporaryDirectory() as folder:
        result_path = Path(folder) / "result.json"
        env = dict(os.environ, WAFERSCAN_BENCH_LAYOUT=str(layout_path),
                   WAFERSCAN_BENCH_RESULT=str(result_path), WAFERSCAN_BENCH_SECONDS=str(seconds),
                   QTWEBENGINE_DISABLE_SANDBOX="1")
        _run_session(command, env, timeout=180)
        result = json.loads(result_path.read_text())
    if not result.get("ok"):
        raise RuntimeError(f"the GUI animation bench failed: {result.get('error')}")
    return result


def _run_session(command, env, timeout):
    """Run ``command`` in a session of its own and, however it ends (done, timed out, Ctrl-C),
    stop every process left in that session: ``xvfb-run`` starts Xvfb and FreeCAD as its
    children, and killing only the process started leaves FreeCAD running on (an orphaned GUI
    bench was found an hour after its bench was stopped)."""
    process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"the GUI animation bench did not finish in {timeout} s") from None
    finally:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass  # nothing left of the session
        process.wait()
