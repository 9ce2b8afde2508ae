"""The suite's guard against processes that outlive their test (tests/processes.py and the
hooks in tests/conftest.py), tried on real processes: an orphaned grandchild in a session of its
own, a command killed at its timeout, a pytest run whose test leaks a process, one stopped by
Ctrl-C."""

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from processes import RUN_VARIABLE, end_processes, processes_of_run, run_in_own_group

TESTS = Path(__file__).resolve().parents[1]


def _env(run_id):
    return dict(os.environ, **{RUN_VARIABLE: run_id})


def _wait_for(predicate, timeout_s=10.0):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.05)
    return predicate()


def _commands(run_id):
    return [p.command for p in processes_of_run(run_id)]


def test_an_orphan_in_a_session_of_its_own_is_found_by_its_run_and_ended(tmp_path):
    run_id = f"guard-orphan-{os.getpid()}"
    # The shell starts a daemon-like grandchild (new session) and exits: init adopts it.
    subprocess.run(["sh", "-c", "setsid sleep 61 >/dev/null 2>&1 &"], env=_env(run_id),
                   check=True)
    try:
        assert _wait_for(lambda: _commands(run_id) == ["sleep 61"])
        assert processes_of_run(f"other-{run_id}") == []
    finally:
        end_processes(processes_of_run(run_id))
    assert _wait_for(lambda: _commands(run_id) == [])


def test_a_command_that_leaves_a_child_behind_leaves_nothing(tmp_path):
    run_id = f"guard-exit-{os.getpid()}"
    returncode, output, timed_out = run_in_own_group(
        ["sh", "-c", "sleep 62 & echo started"], timeout=30, env=_env(run_id))
    assert (returncode, output.strip(), timed_out) == (0, "started", False)
    assert _wait_for(lambda: _commands(run_id) == [])


def test_a_command_killed_at_its_timeout_leaves_nothing(tmp_path):
    run_id = f"guard-timeout-{os.getpid()}"
    started = time.monotonic()
    returncode, _, timed_out = run_in_own_group(
        ["sh", "-c", "sleep 63 & sleep 64"], timeout=1, env=_env(run_id))
    assert timed_out and returncode == -9
    assert time.monotonic() - started < 20
    assert _wait_for(lambda: _commands(run_id) == [])


LEAKING_TEST = '''
import subprocess

def test_leaves_a_process():
    subprocess.Popen(["sleep", "65"])

def test_is_interrupted():
    subprocess.Popen(["sleep", "66"])
    raise KeyboardInterrupt

def test_is_terminated():
    import os, signal, time
    subprocess.Popen(["sleep", "67"])
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(30)
'''


@pytest.fixture
def suite(tmp_path):
    """A small suite with this project's guard: its conftest, processes.py and last test."""
    tests = tmp_path / "tests"
    tests.mkdir()
    for name in ("conftest.py", "processes.py", "test_zz_processes.py"):
        shutil.copy(TESTS / name, tests / name)
    (tests / "test_leak.py").write_text(LEAKING_TEST)
    return tests


def _pytest(suite, run_id, *args):
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "--import-mode=importlib", "--rootdir", str(suite.parent),
                           str(suite), *args],
                          env=_env(run_id), capture_output=True, text=True, timeout=120,
                          cwd=suite.parent)


def test_a_leak_fails_the_suite_naming_the_test_and_the_process_is_ended(suite):
    run_id = f"guard-suite-{os.getpid()}"
    try:
        proc = _pytest(suite, run_id, "-k", "leaves or no_process")
        assert proc.returncode == 1, proc.stdout
        assert "processes left running by tests:" in proc.stdout
        assert "test_leak.py::test_leaves_a_process: " in proc.stdout
        assert "sleep 65" in proc.stdout
        assert "1 failed, 1 passed" in proc.stdout
        assert _commands(run_id) == []  # ended after its test, not left for the next run
    finally:
        end_processes(processes_of_run(run_id))


@pytest.mark.parametrize("how", ["interrupted", "terminated"])
def test_ctrl_c_or_sigterm_ends_what_the_stopped_test_started(suite, how):
    run_id = f"guard-{how}-{os.getpid()}"
    try:
        proc = _pytest(suite, run_id, "-k", how)
        assert proc.returncode == 2, proc.stdout  # pytest's exit status for an interrupted run
        assert "KeyboardInterrupt" in proc.stdout
        assert _commands(run_id) == []
    finally:
        end_processes(processes_of_run(run_id))


def test_the_test_process_own_multiprocessing_helper_is_not_a_leak():
    """multiprocessing's resource tracker, started once for the pytest process (Dask's local
    cluster starts it), lives as long as that process: it is not a test's leak. The same
    command started by a test as a process of its own would be."""
    from multiprocessing import resource_tracker

    from processes import processes_of_this_run

    resource_tracker.ensure_running()
    tracker = resource_tracker._resource_tracker._pid
    assert tracker is not None
    assert os.path.exists(f"/proc/{tracker}")  # it runs, and is not counted
    assert tracker not in [p.pid for p in processes_of_this_run()]
