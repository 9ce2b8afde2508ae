"""``waferscan sweep`` on Dask (SPEC §12): the same summary from a local cluster of one or two
workers, from no Dask at all and from real ``dask scheduler`` / ``dask worker`` processes on
127.0.0.1; the command's outputs; bad input exits 2 naming the file and line."""

import csv
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import scenarios
from scenarios import ROOT, normal, uniform

from waferscan import cli, sweep

PAPER = str(scenarios.PAPER)
TOL = ("\n" + uniform("seat_offset", -0.7, 0.7) + normal("thickness", 0.7, 0.05)
       + uniform("tilt", 0.0, 0.2)
       + "[states]\npresent = 0.7\nempty = 0.2\ncross = 0.05\ndouble = 0.05\n")


@pytest.fixture
def tol_file(tmp_path):
    path = tmp_path / "tol.toml"
    path.write_text(TOL)
    return path


def study(tol_file, **kw):
    return sweep.run(PAPER, tol_file, 1300, seed=4, **kw)[0]


def test_one_and_two_local_workers_and_no_dask_give_the_same_summary(tol_file):
    alone = study(tol_file, workers=0)
    assert study(tol_file, workers=1) == alone
    assert study(tol_file, workers=2, partition_count=3) == alone
    assert alone["n"] == 1300 and alone["seed"] == 4


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_real_scheduler_and_worker_processes_give_the_local_summary(tol_file, tmp_path):
    dask = Path(sys.executable).with_name("dask")
    port = _free_port()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    logs = [open(tmp_path / name, "w") for name in ("scheduler.log", "worker.log")]
    procs = [subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port",
                               str(port), "--no-dashboard"], cwd=ROOT, env=env,
                              stdout=logs[0], stderr=subprocess.STDOUT)]
    address = f"tcp://127.0.0.1:{port}"
    try:
        procs.append(subprocess.Popen(
            [str(dask), "worker", address, "--nworkers", "2", "--nthreads", "1",
             "--no-dashboard", "--host", "127.0.0.1"], cwd=ROOT, env=env,
            stdout=logs[1], stderr=subprocess.STDOUT))
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
        remote = study(tol_file, scheduler=address)
        assert remote == study(tol_file, workers=0)
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in reversed(procs):
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        for log in logs:
            log.close()


def test_command_writes_summary_tables_and_plots(tol_file, tmp_path, capsys):
    out = tmp_path / "out"
    status = cli.main(["sweep", PAPER, "--tolerances", str(tol_file), "-n", "600",
                       "--seed", "2", "--workers", "0", "--out", str(out)])
    assert status == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n"] == 600 and summary["seed"] == 2
    assert sum(sum(row.values()) for row in summary["confusion"].values()) == 600 * 25
    with open(out / "confusion.csv") as f:
        rows = list(csv.reader(f))
    names = rows[0][1:]
    for row in rows[1:]:
        assert [int(v) for v in row[1:]] == [summary["confusion"][row[0]].get(n, 0)
                                              for n in names]
    for png in ("confusion.png", "margins.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary left
    printed = capsys.readouterr()
    assert "confusion" in printed.out
    assert "sweep: 2/2 partitions" not in printed.out  # progress goes to stderr


@pytest.mark.parametrize("text,line,words", [
    ("[seat_offset]\ndist = \"uniform\"\nlo = -0.5\nhi = 0.5\n[warp]\ndist = \"fixed\"\n"
     "value = 0.1\n", 5, "unknown table 'warp'"),
    ("[thickness]\ndist = \"gauss\"\nmean = 0.7\n", 2, "'gauss' is not a distribution"),
    ("[thickness]\ndist = \"normal\"\nmean = 0.7\nsigma = 0.01\nlo = 1\n", 5,
     "lo: unknown key"),
    ("[tilt]\ndist = \"uniform\"\nlo = 0.5\nhi = 0.1\n", 4, "below lo"),
    ("\n[states]\npresent = 0.8\nempty = 0.1\n", 2, "sum to 0.9, not 1"),
    ("[states]\npresent = 0.9\nwobbly = 0.1\n", 3, "wobbly: unknown state"),
    ("[beam_z]\ndist = \"fixed\"\nvalue = \"high\"\n", 3, "expected a finite number"),
    # A dist that is not a string was a TypeError traceback.
    ("[thickness]\ndist = [\"normal\"]\nmean = 0.7\nsigma = 0.01\n", 2,
     "dist: ['normal'] is not a distribution"),
    # The key and line blamed are the limit's own: lo here (hi was named).
    ("[thickness]\ndist = \"uniform\"\nlo = -0.1\nhi = 0.8\n", 3,
     "[thickness] lo: a thickness must stay above 0 mm"),
    ("[threshold_on]\ndist = \"uniform\"\nlo = 0.0\nhi = 0.5\n", 3, "[threshold_on] lo: "),
    ("[threshold_on]\ndist = \"uniform\"\nlo = 0.4\nhi = 1.5\n", 4, "[threshold_on] hi: "),
    ("[tilt]\ndist = \"uniform\"\nlo = -100.0\nhi = 0.0\n", 3, "[tilt] lo: "),
])
def test_bad_tolerance_file_exits_2_with_its_line(tmp_path, capsys, text, line, words):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    status = cli.main(["sweep", PAPER, "--tolerances", str(path), "-n", "10", "--workers",
                       "0"])
    err = capsys.readouterr().err
    assert status == 2
    assert err.startswith(f"waferscan: error: {path}:{line}: ") and words in err, err
    assert "Traceback" not in err


def test_bad_count_and_bad_scheduler_exit_2(tol_file, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["sweep", PAPER, "--tolerances", str(tol_file), "-n", "0"])
    assert exc.value.code == 2
    port = _free_port()  # nothing listens there
    start = time.monotonic()
    status = cli.main(["sweep", PAPER, "--tolerances", str(tol_file), "-n", "10",
                       "--scheduler", f"tcp://127.0.0.1:{port}"])
    err = capsys.readouterr().err
    assert status == 2 and "cannot reach the Dask scheduler" in err, err
    assert time.monotonic() - start < 120


def test_local_workers_keep_glibcs_adaptive_memory_trim(tol_file):
    """Dask's nannies set MALLOC_TRIM_THRESHOLD_ to 64 KiB by default, which made a sweep's
    partition ~20 % slower in a worker than in process; the local cluster leaves it unset and
    keeps Dask's other settings (one thread for OpenMP/BLAS in each single-threaded worker)."""
    from distributed import Client

    cluster = sweep.local_cluster(1)
    try:
        with Client(cluster) as client:
            seen = list(client.run(lambda: (os.environ.get("MALLOC_TRIM_THRESHOLD_"),
                                            os.environ.get("OMP_NUM_THREADS"))).values())
    finally:
        cluster.close()
    assert seen == [(None, "1")]


def _profiling():
    import dask

    return dask.config.get("distributed.worker.profile.enabled")


def test_local_workers_do_not_sample_their_tasks_for_a_dashboard_profile(tol_file):
    """Dask's profiler sampled each worker's task thread every 10 ms: one worker swept ~15 %
    slower than one process. The local cluster's workers run without it."""
    from distributed import Client

    cluster = sweep.local_cluster(1)
    try:
        with Client(cluster) as client:
            seen = list(client.run(_profiling).values())
    finally:
        cluster.close()
    assert seen == [False]


def test_an_out_that_cannot_be_a_folder_is_refused_before_the_sweep(tmp_path, capsys):
    """--out naming a file was refused only after the whole sweep, its results lost."""
    taken = tmp_path / "afile"
    taken.write_text("")
    status = cli.main(["sweep", PAPER, "--tolerances", str(tmp_path / "missing.toml"), "-n",
                       "10", "--workers", "0", "--out", str(taken)])
    err = capsys.readouterr().err
    # The tolerance file is missing too: the --out folder was checked first, before any work.
    assert status == 2 and err == f"waferscan: error: {taken}: cannot make the folder: File exists\n"


def test_a_negative_seed_is_refused_as_the_seed(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["sweep", PAPER, "--tolerances", "x.toml", "-n", "10", "--seed", "-1"])
    assert exc.value.code == 2
    assert "argument --seed: must not be negative, got '-1'" in capsys.readouterr().err
