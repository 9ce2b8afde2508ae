"""The processes a test run starts, found and ended.

Every process the suite starts inherits one environment variable, ``WAFERSCAN_TEST_RUN``, set
to a value of this run's own (tests/conftest.py sets it before any test). A process keeps the
environment it was started with in ``/proc/PID/environ`` even when it has left its parent's
session or been re-parented to init (an ``Xvfb`` whose ``xvfb-run`` was killed), so scanning
``/proc`` for that value finds every process of the run and nothing else, whoever started it.

``run_in_own_group`` runs a command that starts others (``xvfb-run`` starts ``Xvfb`` and
FreeCAD) in a process group of its own and ends the whole group however the call ends.
"""

import os
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass

RUN_VARIABLE = "WAFERSCAN_TEST_RUN"
LEAKS = []  # (test id, RunProcess) for each process a test left running (tests/conftest.py)


@dataclass(frozen=True)
class RunProcess:
    pid: int
    command: str

    def __str__(self):
        return f"{self.pid} {self.command}"


def _state(pid):
    """The one-letter state of a process (Z for a zombie), or None if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0].decode()
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return None


def processes_of_run(run_id, exclude=()):
    """The live (not zombie) processes whose environment holds ``RUN_VARIABLE=run_id``."""
    marker = f"{RUN_VARIABLE}={run_id}".encode()
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) in exclude:
            continue
        pid = int(entry)
        try:
            with open(f"/proc/{pid}/environ", "rb") as f:
                environ = f.read().split(b"\0")
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                command = f.read().replace(b"\0", b" ").decode(errors="replace").strip()
        except (FileNotFoundError, ProcessLookupError, PermissionError):
            continue
        if marker in environ and _state(pid) not in (None, "Z"):
            found.append(RunProcess(pid, command))
    return found


# Helpers that Python's multiprocessing starts once for the process that uses it (Dask's local
# cluster does, in the pytest process itself): they belong to that process, not to a test, and
# end when it ends (they exit when the pipe from it closes). Only such a helper whose parent is
# the pytest process is left alone.
_PROCESS_HELPERS = ("from multiprocessing.resource_tracker import main",
                    "from multiprocessing.forkserver import main")


def _parent(pid):
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return int(f.read().rsplit(b")", 1)[1].split()[1])
    except (FileNotFoundError, ProcessLookupError, IndexError, ValueError):
        return None


def processes_of_this_run():
    """The processes of the run this process belongs to, but for this process itself and its
    own multiprocessing helpers."""
    me = os.getpid()
    return [p for p in processes_of_run(os.environ[RUN_VARIABLE], exclude={me})
            if not (any(helper in p.command for helper in _PROCESS_HELPERS)
                    and _parent(p.pid) == me)]


def end_processes(processes, grace_s=3.0):
    """SIGTERM each, then SIGKILL what is still alive after ``grace_s``."""
    for sig, wait_s in ((signal.SIGTERM, grace_s), (signal.SIGKILL, 5.0)):
        alive = [p for p in processes if _state(p.pid) not in (None, "Z")]
        for p in alive:
            try:
                os.kill(p.pid, sig)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + wait_s
        while alive and time.monotonic() < deadline:
            alive = [p for p in alive if _state(p.pid) not in (None, "Z")]
            time.sleep(0.05)
        if not alive:
            return


def run_in_own_group(command, timeout, **popen_kwargs):
    """Run ``command`` in a new session; return ``(returncode, output, timed_out)``.

    However the call ends (the command exits, the timeout, an exception, Ctrl-C), nothing of
    its process group is left: what the command left behind gets SIGTERM, then SIGKILL. A
    command that exits by itself is first allowed to end its own children (``xvfb-run`` stops
    its ``Xvfb`` and removes its lock and authority files)."""
    popen_kwargs.setdefault("stdin", subprocess.DEVNULL)
    # Output to a file, not a pipe: a child left behind holding the pipe open would keep a
    # reader waiting after the command itself has exited.
    with tempfile.TemporaryFile(mode="w+", encoding="utf-8", errors="replace") as output_file:
        proc = subprocess.Popen(command, start_new_session=True, stdout=output_file,
                                stderr=subprocess.STDOUT, text=True, **popen_kwargs)
        timed_out = False
        try:
            try:
                proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                timed_out = True
                _signal_group(proc.pid, signal.SIGKILL)
                proc.wait()
        finally:
            _end_group(proc)
        output_file.seek(0)
        output = output_file.read()
    return proc.returncode, output, timed_out


def _signal_group(pgid, sig):
    try:
        os.killpg(pgid, sig)
        return True
    except ProcessLookupError:
        return False


def _end_group(proc, grace_s=3.0):
    if proc.poll() is None:
        _signal_group(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            pass
    # The leader is gone; anything still in its group (Xvfb, FreeCAD) goes too.
    if _signal_group(proc.pid, signal.SIGTERM):
        deadline = time.monotonic() + grace_s
        while time.monotonic() < deadline and _group_alive(proc.pid):
            time.sleep(0.05)
        _signal_group(proc.pid, signal.SIGKILL)
    if proc.poll() is None:
        _signal_group(proc.pid, signal.SIGKILL)
        proc.wait()


def _group_alive(pgid):
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as f:
                fields = f.read().rsplit(b")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError):
            continue
        if int(fields[2]) == pgid and fields[0] != b"Z":
            return True
    return False
