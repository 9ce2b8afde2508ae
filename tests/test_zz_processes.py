"""The suite's last test (tests/conftest.py runs it after all others): no process that a test
started outlived its test. A test that leaves one (an Xvfb whose xvfb-run was killed, a watcher
never stopped) is named here with the process's command line; the process itself was already
ended after that test, so runs do not pile up on a CI machine."""

from processes import LEAKS, processes_of_this_run


def test_no_process_of_the_run_outlived_its_test():
    leaks = [f"{test}: {process}" for test, process in LEAKS]
    assert not leaks, "processes left running by tests:\n" + "\n".join(leaks)
    alive = [str(p) for p in processes_of_this_run()]
    assert not alive, "processes of this run still alive:\n" + "\n".join(alive)
