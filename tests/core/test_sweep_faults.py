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
from commands import CLI
from scenarios import PAPER, ROOT, normal

TOL = normal("beam_z", 0, 0.1)


def sweep(tmp_path, *args, **kwargs):
    tol = tmp_path / "TOL.toml"
    tol.write_text(TOL)
    return [*CLI, "sweep", str(PAPER), "--tolerances", str(tol), *map(str, args)]


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


def _free_port():
    import socket
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _end_group(process):
    """A process started in a session of its own, ended with every process of that session."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(timeout=20)
            os.killpg(process.pid, 0)
        except (subprocess.TimeoutExpired, ProcessLookupError):
            pass
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            try:
                os.killpg(process.pid, 0)
            except ProcessLookupError:
                return
            time.sleep(0.1)


@pytest.mark.parametrize("killed", ["workers", "scheduler"])
def test_a_cluster_that_dies_mid_sweep_ends_it_with_one_line(tmp_path, killed):
    """A real `dask scheduler` and `dask worker` (2 processes) on 127.0.0.1; once the sweep has
    finished a partition, the workers (with their nanny) or the scheduler are killed with
    SIGKILL. Before: the sweep waited for ever with a frozen progress line (workers), or ended
    with a FutureCancelledError traceback (scheduler)."""
    dask = Path(sys.executable).with_name("dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "WAFERSCAN_SWEEP_WORKERLESS_SECONDS": "5"}
    logs = {name: open(tmp_path / f"{name}.log", "w+") for name in ("scheduler", "worker",
                                                                     "sweep")}
    started = []
    try:
        scheduler = subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port",
                                      str(port), "--no-dashboard"], cwd=ROOT, env=env,
                                     stdout=logs["scheduler"], stderr=subprocess.STDOUT,
                                     start_new_session=True)
        started.append(scheduler)
        worker = subprocess.Popen([str(dask), "worker", address, "--nworkers", "2",
                                   "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"],
                                  cwd=ROOT, env=env, stdout=logs["worker"],
                                  stderr=subprocess.STDOUT, start_new_session=True)
        started.append(worker)
        from distributed import Client
        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
        swept = subprocess.Popen(sweep(tmp_path, "-n", "4000000", "--partitions", "40",
                                       "--scheduler", address), cwd=ROOT, env=env,
                                 stdout=subprocess.PIPE, stderr=logs["sweep"], text=True,
                                 start_new_session=True)
        started.append(swept)
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and swept.poll() is None and \
                "sweep: " not in Path(logs["sweep"].name).read_text():
            time.sleep(0.1)  # a partition is done: the sweep is under way
        assert swept.poll() is None, Path(logs["sweep"].name).read_text()[-3000:]
        os.killpg((worker if killed == "workers" else scheduler).pid, signal.SIGKILL)
        try:
            out, _ = swept.communicate(timeout=180)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the sweep still runs 180 s after the {killed} were killed")
    finally:
        for process in reversed(started):
            _end_group(process)
        for log in logs.values():
            log.flush()
    err = Path(logs["sweep"].name).read_text()
    lines = err.splitlines()
    assert swept.returncode == 2, err[-3000:]
    assert "Traceback" not in err and all(line.startswith("sweep: ") for line in lines[:-1]), \
        err[-3000:]
    if killed == "workers":
        assert lines[-1].startswith(f"waferscan: error: --scheduler: {address} has had no "
                                    "worker for 5 s: "), lines[-1]
        assert lines[-1].endswith(f"lost; start workers (dask worker {address}) and run the "
                                  "sweep again"), lines[-1]
    else:
        assert lines[-1].startswith(f"waferscan: error: --scheduler: lost the Dask scheduler "
                                    f"at {address} mid-sweep ("), lines[-1]
    assert out == ""
    for log in logs.values():
        log.close()


@pytest.mark.parametrize("n", ["1" + "0" * 30, "14757395258967642"])
def test_an_n_beyond_the_sweeps_counts_is_refused_before_anything_is_drawn(tmp_path, n):
    """10^30 was an OverflowError traceback. A sweep's memory no longer grows with N
    (test_sweep_memory.py: 10^9 and 10^13 are swept, in their time); its counts are 64-bit
    integers summing up to N x 25² for the paper: 2^63 // 625 + 1 layouts is one too many."""
    done = subprocess.run(sweep(tmp_path, "-n", n, "--workers", "0"), cwd=ROOT,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr[-3000:]
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith("waferscan: error: -n: ") and " layouts: more than a sweep " \
        "counts exactly (its counts are 64-bit integers, up to N x slots²): at most " \
        "14,757,395,258,967,641 layouts of 25 slots\n" in done.stderr, done.stderr
    assert done.stdout == ""
