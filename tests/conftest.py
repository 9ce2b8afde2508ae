"""Shared test set-up: the tests folder on sys.path (for the modules the tests share:
scenarios, commands, figures, random_layouts, sensor_layouts) and the repository root.
Hypothesis runs derandomised, so that every run (CI's too) tries the same cases and can be
repeated; HYPOTHESIS_PROFILE=explore draws new ones, to look for bugs."""

import os
import signal
import sys
import time
from pathlib import Path

from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("explore", print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# The tests press Ctrl-C on the processes they start (SIGINT), as a user at a terminal does. A
# suite started in the background of a shell without job control (`make test &` in a script)
# inherits SIGINT ignored, and so would every process it starts: Python then installs no
# KeyboardInterrupt at all. Handled here, the children start with SIGINT's default action.
signal.signal(signal.SIGINT, signal.default_int_handler)

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


# --- No process outlives the suite -------------------------------------------------------
# Every process started during the run carries RUN_VARIABLE (tests/processes.py). After each
# test (its fixtures that end with it torn down), a process of the run still alive is a leak:
# it is ended there and then, so nothing piles up, and recorded; the suite's last test
# (tests/test_zz_processes.py) fails naming every leak. Ctrl-C or a crash of pytest still
# ends them (pytest_unconfigure).
import pytest  # noqa: E402

from processes import LEAKS, RUN_VARIABLE, end_processes, processes_of_this_run  # noqa: E402

os.environ.setdefault(RUN_VARIABLE, f"{os.getpid()}-{os.urandom(6).hex()}")
LAST_TEST = "test_zz_processes.py"
_ours = processes_of_this_run


def pytest_collection_modifyitems(items):
    """The leak check runs last, after every other test (and its module's fixtures) ended."""
    last = [item for item in items if item.path.name == LAST_TEST]
    items[:] = [item for item in items if item.path.name != LAST_TEST] + last


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    yield
    if nextitem is not None and nextitem.path == item.path:
        # A process may live on for a fixture the next test of this module shares: it is judged
        # after the module's last test.
        return
    left = _ours()
    if left:
        # A process being stopped may need a moment to go: look again before calling it a leak.
        deadline = time.monotonic() + 5.0
        while left and time.monotonic() < deadline:
            time.sleep(0.1)
            left = _ours()
    for process in left:
        LEAKS.append((item.nodeid, process))
    end_processes(left)


def _stop_on_sigterm(signum, frame):
    """SIGTERM (a CI job's time limit, a `kill`) stops the run as Ctrl-C does, so that
    pytest_unconfigure still ends the run's processes."""
    raise KeyboardInterrupt(f"signal {signum}")


signal.signal(signal.SIGTERM, _stop_on_sigterm)


def pytest_unconfigure(config):
    end_processes(_ours())
