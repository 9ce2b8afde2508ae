"""The command line run as a user runs it: ``python -m waferscan.cli`` from the repository
root in a process of its own, FreeCAD's ``freecadcmd -c`` running code or the same command
line inside FreeCAD, and ``waferscan watch`` (the MCS link) left running while a test writes
its commands and reads its answers."""

import os
import re
import subprocess
import sys
import time
from pathlib import Path

from scenarios import ROOT

__all__ = ["CLI", "waferscan", "freecadcmd", "cli_in_freecad", "Watch", "watch", "run_watch",
           "results_seq", "answered", "wait_for"]

CLI = [sys.executable, "-m", "waferscan.cli"]


def waferscan(*args, cwd=ROOT, timeout=300, env=None):
    """``waferscan ARGS…`` (each argument str()-ed) run to its end, its output captured as
    text; the ``CompletedProcess``. Run elsewhere than the repository root, it still runs this
    checkout's code (not an installed copy's)."""
    if Path(cwd) != ROOT:
        env = {**(os.environ if env is None else env), "PYTHONPATH": str(ROOT)}
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


# --- waferscan watch, the MCS link ------------------------------------------------------------

class Watch:
    """A ``waferscan watch`` process, its stdout and stderr in files (a pipe nobody reads would
    fill up and block it)."""

    def __init__(self, folder, *args):
        self.out = (Path(folder).parent / f"watch-{id(self)}.out").open("w+")
        self.err = (Path(folder).parent / f"watch-{id(self)}.err").open("w+")
        self.process = subprocess.Popen([*CLI, "watch", str(folder), *map(str, args)],
                                        cwd=ROOT, stdout=self.out, stderr=self.err, text=True)
        self.pid = self.process.pid

    def poll(self):
        return self.process.poll()

    @property
    def returncode(self):
        return self.process.returncode

    def send_signal(self, sig):
        self.process.send_signal(sig)

    def communicate(self, timeout):
        self.process.wait(timeout)
        texts = []
        for handle in (self.out, self.err):
            handle.seek(0)
            texts.append(handle.read())
            handle.close()
        return tuple(texts)


def watch(folder, *args):
    """``waferscan watch FOLDER ARGS…`` started and left running: its ``Watch``."""
    return Watch(folder, *args)


def run_watch(folder, *args):
    """``waferscan watch FOLDER ARGS…`` run to its end (``--once``, or refused)."""
    return waferscan("watch", folder, *args)


def results_seq(folder):
    """The seq of the answer in ``folder``'s results.txt, or None before the first."""
    try:
        match = re.match(r"seq = (\d+)\n", (folder / "results.txt").read_text())
    except OSError:
        return None
    return int(match.group(1)) if match else None


def answered(out):
    """The seqs a watcher's stdout says it answered, in order."""
    return [int(m) for m in re.findall(r"^seq (\d+) \w+: ", out, re.M)]


def wait_for(predicate, timeout=300.0):
    """Whether ``predicate()`` came true within ``timeout`` seconds (asked every 50 ms)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.05)
    return False
