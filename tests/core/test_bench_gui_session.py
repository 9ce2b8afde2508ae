"""The bench's GUI measure runs FreeCAD (under xvfb-run) in a session of its own; whatever that
session leaves behind is stopped when the measure ends, so no FreeCAD outlives the bench."""

import json
import os
import stat
import time

import pytest

from waferscan import bench


@pytest.fixture
def fake_freecad(tmp_path, monkeypatch):
    """A `freecad` on PATH that writes the bench's result, starts a grandchild that would run
    for minutes (as FreeCAD under xvfb-run is a grandchild of the bench) and exits."""
    pid_file = tmp_path / "grandchild.pid"
    script = tmp_path / "bin" / "freecad"
    script.parent.mkdir()
    script.write_text(
        "#!/bin/sh\n"
        "sleep 300 &\n"
        f"echo $! > {pid_file}\n"
        "printf '%s' '{\"ok\": true, \"frames_per_second\": 1.0}' > \"$WAFERSCAN_BENCH_RESULT\"\n")
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("PATH", f"{script.parent}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.setenv("DISPLAY", ":99")  # no xvfb-run: the fake is started directly
    return pid_file


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A killed child of ours that init has not reaped yet shows as a zombie.
    with open(f"/proc/{pid}/stat") as f:
        return f.read().split(")")[-1].split()[0] != "Z"


def test_what_the_gui_measure_started_does_not_outlive_it(fake_freecad, tmp_path):
    result = bench.gui_animation(tmp_path / "layout.FCStd", seconds=0.1)
    assert result == {"ok": True, "frames_per_second": 1.0}
    grandchild = int(fake_freecad.read_text())
    for _ in range(50):  # the kill is sent before gui_animation returns; let it be delivered
        if not _alive(grandchild):
            break
        time.sleep(0.02)
    assert not _alive(grandchild)
