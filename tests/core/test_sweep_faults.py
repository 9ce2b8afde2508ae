"""`waferscan sweep` against a careless operator (issue 25): a --scheduler address Dask cannot
use (tls:// without certificates, ucx:// without UCX) is one error line, not a TypeError
traceback; Ctrl-C mid-sweep (SIGINT to the whole process group, as a terminal sends it) is
one line, exit 130, and every process of the sweep ends. Each test failed before the fix."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "resources" / "examples" / "paper.toml"
TOL = '[beam_z]\ndist = "normal"\nmean = 0\nsigma = 0.1\n'


def sweep(tmp_path, *args, **kwargs):
    tol = tmp_path / "TOL.toml"
    tol.write_text(TOL)
    return [sys.executable, "-m", "waferscan.cli", "sweep", str(PAPER), "--tolerances",
            str(tol), *map(str, args)]


@pytest.mark.parametrize("address, message", [
    ("tls://127.0.0.1:9", "--scheduler: cannot use the Dask scheduler at tls://127.0.0.1:9: "),
    ("ucx://127.0.0.1:9", "--scheduler: ucx://127.0.0.1:9: ucx:// needs UCX (the ucx-py "
                          "package), which is not installed; use tcp://"),
])
def test_a_scheduler_address_dask_cannot_use_is_one_line(tmp_path, address, message):
    done = subprocess.run(sweep(tmp_path, "-n", "10", "--scheduler", address), cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr[-3000:]
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, done.stderr[-3000:]
    assert done.stderr.startswith(f"waferscan: error: {message}")


def children(pid):
    """The child processes of every thread of ``pid`` (Dask's nannies start the workers from
    threads of their own)."""
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return found


def test_ctrl_c_mid_sweep_is_one_line_and_ends_every_process(tmp_path):
    process = subprocess.Popen(sweep(tmp_path, "-n", "5000000", "--workers", "2"), cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and len(children(process.pid)) < 2:
            time.sleep(0.1)  # the cluster's workers are up
        assert process.poll() is None
        time.sleep(3.0)  # the sweep is running on them
        os.killpg(process.pid, signal.SIGINT)
        out, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.communicate(timeout=60)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            try:
                os.killpg(process.pid, 0)
            except ProcessLookupError:
                break
            time.sleep(0.1)
        else:
            os.killpg(process.pid, signal.SIGKILL)
            pytest.fail("a process of the sweep outlived it by 30 s")
    assert process.returncode == 130, err[-3000:]
    # the progress line (a line per partition when stderr is not a terminal), then one line
    lines = err.splitlines()
    assert lines[-1] == "waferscan: interrupted", err[-3000:]
    assert all(line.startswith("sweep: ") for line in lines[:-1]), err[-3000:]
    assert out == ""


@pytest.fixture
def small_disk(tmp_path):
    """A 48 kB tmpfs: summary.json and the CSV tables fit, the PNG plots do not (root only)."""
    mount = tmp_path / "disk"
    mount.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=48k", "tmpfs", str(mount)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.strip()}")
    yield mount
    subprocess.run(["umount", "-l", str(mount)], check=True)


def test_a_full_disk_writes_no_part_of_the_set_and_the_summary_is_still_printed(tmp_path,
                                                                                 small_disk):
    out = small_disk / "out"
    done = subprocess.run(sweep(tmp_path, "-n", "300", "--workers", "0", "--out", out),
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr[-3000:]
    assert done.stderr.splitlines()[-1] == (
        f"waferscan: error: {out}: cannot write: No space left on device; nothing written (the "
        "summary is on the standard output)"), done.stderr[-3000:]
    assert "Traceback" not in done.stderr
    assert "300" in done.stdout and "present" in done.stdout  # the summary, computed, printed
    assert os.listdir(small_disk) == []  # no summary.json without its plots, no temporary


def test_a_rerun_into_the_same_out_replaces_the_set_as_a_whole(tmp_path):
    import json
    out = tmp_path / "out"
    for seed in (1, 2):
        done = subprocess.run(sweep(tmp_path, "-n", "300", "--workers", "0", "--seed", seed,
                                    "--out", out), cwd=ROOT, capture_output=True, text=True,
                              timeout=300)
        assert done.returncode == 0, done.stderr[-3000:]
        assert json.loads((out / "summary.json").read_text())["seed"] == seed
    assert sorted(os.listdir(out)) == sorted(["summary.json", "confusion.csv", "rates.csv",
                                              "margins.csv", "confusion.png", "margins.png"])
    assert sorted(os.listdir(tmp_path)) == ["TOL.toml", "out"]  # no temporary left
    (out / "notes.txt").write_text("mine\n")
    done = subprocess.run(sweep(tmp_path, "-n", "300", "--workers", "0", "--out", out),
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and done.stdout == ""  # refused before the sweep
    assert done.stderr == (f"waferscan: error: {out}: holds other files than a sweep's "
                           "('notes.txt'): --out is replaced as a whole; name a new folder\n")
    assert (out / "notes.txt").read_text() == "mine\n"
