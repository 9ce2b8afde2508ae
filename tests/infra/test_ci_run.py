""".ci/run runs the two suites (FreeCAD 0.20.2 and 1.0) side by side. With a stand-in `make`
first on PATH (`setup` passes; `test` and `test-freecad1` print, wait, and exit as told), this
checks what CI and a developer at a terminal rely on: each suite's lines tagged with its name;
the script's status is a failure when either suite fails, after both have ended; a Ctrl-C, a
kill or a hang-up of the script reaches both suites, which end as they would alone (their
clean-up's last line still printed), and the script exits 130, 143 or 129 only after both have
ended; its output closing mid-run (a Ctrl-C'd `| tee`) cuts no suite's clean-up short."""

import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

# The stand-in make: "setup" logs and passes; a suite's target prints a first line, writes a
# marker that it runs, waits for $STANDIN_HOLD to exist (or for a signal), then prints its last
# line and exits with $STANDIN_EXIT_<target>. On INT, TERM or HUP it logs the signal, takes a
# moment to "clean up" (a root's unmounting), prints and logs that and exits 130, 143 or 129.
MAKE = r"""#!/usr/bin/env bash
target=$1
log="$STANDIN_DIR/log"
[ "$target" = setup ] && { echo "make setup" >>"$log"; echo "setup: ready"; exit 0; }
name=${target//-/_}
on_signal() {
  echo "$target got $1" >>"$log"
  echo "$target cleaning up after $1"
  sleep 0.3
  echo "$target cleaned up after $1"
  echo "$target cleaned up" >>"$log"
  exit "$2"
}
trap 'on_signal INT 130' INT
trap 'on_signal TERM 143' TERM
trap 'on_signal HUP 129' HUP
echo "$target started"
: >"$STANDIN_DIR/running-$target"
while [ ! -e "$STANDIN_HOLD" ]; do sleep 0.05 & wait $!; done
echo "$target done"
echo "$target ended" >>"$log"
var="STANDIN_EXIT_$name"
exit "${!var:-0}"
"""


@pytest.fixture
def checkout(tmp_path):
    """A checkout holding .ci/run, and the environment that puts the stand-in make first."""
    root = tmp_path / "checkout"
    (root / ".ci").mkdir(parents=True)
    shutil.copy2(REPO / ".ci" / "run", root / ".ci" / "run")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "make").write_text(MAKE)
    (bin_dir / "make").chmod(0o755)
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
               STANDIN_DIR=str(tmp_path), STANDIN_HOLD=str(tmp_path / "hold"))
    return root, env, tmp_path


def start(checkout, **exits):
    root, env, folder = checkout
    env = dict(env, **{f"STANDIN_EXIT_{k}": str(v) for k, v in exits.items()})
    return subprocess.Popen([str(root / ".ci" / "run")], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)


def wait_running(folder, process):
    deadline = time.monotonic() + 20
    while not all((folder / f"running-{t}").exists() for t in ("test", "test-freecad1")):
        assert process.poll() is None, process.communicate()[0]
        assert time.monotonic() < deadline, "the two suites did not both start"
        time.sleep(0.05)


def log_lines(folder):
    return (folder / "log").read_text().splitlines()


@pytest.mark.parametrize("exits, status", [({}, 0), ({"test": 1}, 1),
                                           ({"test_freecad1": 2}, 1)])
def test_both_suites_run_at_once_and_either_failing_fails_ci(checkout, exits, status):
    _, _, folder = checkout
    process = start(checkout, **exits)
    try:
        wait_running(folder, process)  # both at once: neither waits for the other to end
        (folder / "hold").touch()
        output, _ = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    assert process.returncode == status, output
    lines = output.splitlines()
    assert "[0.20.2] test started" in lines and "[0.20.2] test done" in lines, output
    assert "[1.0] test-freecad1 started" in lines and "[1.0] test-freecad1 done" in lines, output
    assert log_lines(folder)[0] == "make setup"
    assert sorted(log_lines(folder)[1:]) == ["test ended", "test-freecad1 ended"]
    test_status = exits.get("test", 0)
    freecad1_status = exits.get("test_freecad1", 0)
    assert (f"ci: FreeCAD 0.20.2 suite exit {test_status}, FreeCAD 1.0 suite exit "
            f"{freecad1_status}") in lines


@pytest.mark.parametrize("sent, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143),
                                          (signal.SIGHUP, 129)])
def test_a_signal_to_ci_reaches_both_suites_and_ci_waits_for_their_clean_up(
        checkout, sent, status):
    _, _, folder = checkout
    process = start(checkout)
    try:
        wait_running(folder, process)
        name = signal.Signals(sent).name[3:]
        # As a terminal's Ctrl-C or a CI runner's kill would: to the script alone (the suites
        # are in process groups of their own, where such a signal does not reach them).
        process.send_signal(sent)
        # The script's own end (not its output's: the taggers hold that open too) comes only
        # after both suites have cleaned up.
        process.wait(timeout=30)
        cleaned = [line for line in log_lines(folder) if line.endswith("cleaned up")]
        output, _ = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        (folder / "hold").touch()  # a suite that missed the signal ends now, and the test fails
    assert process.returncode == status, output
    assert sorted(cleaned) == ["test cleaned up", "test-freecad1 cleaned up"], output
    assert sorted(log_lines(folder)[1:]) == ["test cleaned up", f"test got {name}",
                                             "test-freecad1 cleaned up",
                                             f"test-freecad1 got {name}"]
    lines = output.splitlines()
    # Printed 0.3 s after the signal, through the tagger: it outlived the signal too.
    assert f"[0.20.2] test cleaned up after {name}" in lines, output
    assert f"[1.0] test-freecad1 cleaned up after {name}" in lines, output
    assert (f"ci: FreeCAD 0.20.2 suite exit {status}, FreeCAD 1.0 suite exit {status}"
            in lines), output


def test_a_closed_output_cuts_no_suites_clean_up_short(checkout):
    """A Ctrl-C of `.ci/run | tee log` ends tee first: what the taggers write then meets a
    closed pipe. They must go on reading, or each suite would die at its next word, in the
    middle of its clean-up (FreeCAD 1.0's root left mounted)."""
    _, _, folder = checkout
    process = start(checkout)
    try:
        wait_running(folder, process)
        process.stdout.close()  # tee gone
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        (folder / "hold").touch()
    assert process.returncode == 130
    assert sorted(log_lines(folder)[1:]) == ["test cleaned up", "test got INT",
                                             "test-freecad1 cleaned up", "test-freecad1 got INT"]
