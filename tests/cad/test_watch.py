"""The MCS link on a FreeCAD document under faults, and `waferscan watch` as the MCS meets it."""

import os
import random
import signal
import subprocess
import sys
import time

import FreeCAD as App
import pytest
from commands import CLI
from scenarios import PAPER, ROOT
from scenarios import PAPER_CODE as CODE

from waferscan.cad import roles
from waferscan.cad.layout_files import open_layout
from waferscan.cad.mcs_watch import document_scanner
from waferscan.core.files.mcs_link import McsLink


@pytest.fixture
def doc():
    document = open_layout(PAPER)
    name = document.Name
    yield document
    App.closeDocument(name)


def quiet_link(folder, scan):
    return McsLink(folder, scan, log=lambda text: None)


def test_a_wafer_deleted_during_a_scan_is_an_error_answer_and_the_link_goes_on(doc, tmp_path):
    inner = document_scanner(doc, tmp_path, "document")
    scanner = doc.getObjectsByLabel("Scanner")[0]
    start = scanner.Placement.toMatrix()

    def scan(command, should_stop):
        checks = []

        def user_deletes_a_wafer():
            checks.append(1)
            if command.seq == 1 and len(checks) == 3:
                doc.removeObject(doc.getObjectsByLabel("LP1_W05")[0].Name)
            should_stop()

        return inner(command, user_deletes_a_wafer)

    (tmp_path / "commands.txt").write_text("1 SCF\n2 SCF\n")
    first, second = quiet_link(tmp_path, scan).poll()
    assert first.status == "error"
    assert "LP1 assembly/LP1_W05 is no longer in the document" in first.message
    assert (second.status, second.code) == ("ok", "1101220001220001010000010")
    # The robot went back to its start pose after the failed scan.
    assert doc.getObjectsByLabel("Scanner")[0].Placement.toMatrix() == start
    assert scanner.Placement.toMatrix() == start


def test_a_non_disc_tagged_as_wafer_is_an_error_answer(doc, tmp_path):
    box = doc.addObject("Part::Box", "Box")
    doc.recompute()
    roles.set_role(box, roles.WAFER)
    (tmp_path / "commands.txt").write_text("1 SCF\n")
    (answer,) = quiet_link(tmp_path, document_scanner(doc, tmp_path)).poll()
    assert answer.status == "error"
    assert "Box is tagged as a wafer but has no cylindrical rim" in answer.message
    doc.removeObject(box.Name)
    (tmp_path / "commands.txt").write_text("1 SCF\n2 SCF\n")
    (answer,) = quiet_link(tmp_path, document_scanner(doc, tmp_path)).poll()
    assert (answer.seq, answer.code) == (2, CODE)


def wait_for_seq(folder, seq, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            text = (folder / "results.txt").read_text()
        except FileNotFoundError:
            text = ""
        if f"seq = {seq}\n" in text:
            return text
        time.sleep(0.05)
    raise AssertionError(f"no answer to seq {seq} within {timeout} s")


def test_watch_command_end_to_end(tmp_path):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    command = [*CLI, "watch", str(tmp_path), "--engine", "document", "--poll", "0.05"]
    watcher = subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    commands = tmp_path / "commands.txt"
    try:
        commands.write_text("1 SCF\n")
        assert f"code = {CODE}" in wait_for_seq(tmp_path, 1)
        (tmp_path / "parameters.txt").write_text("# taught\nz_step = 0.1\nfinal_z = 5x0\n")
        with open(commands, "a") as handle:
            handle.write("2 SCF\n")
        text = wait_for_seq(tmp_path, 2)
        assert "status = error" in text
        assert f"message = {tmp_path / 'parameters.txt'}:3: final_z: expected a number" in text
        (tmp_path / "parameters.txt").write_text("z_step = 0.1\n")
        with open(commands, "a") as handle:
            handle.write("3 SCS\n")
        text = wait_for_seq(tmp_path, 3)
        assert "status = ok" in text and "z_step = 0.1\n" in text and "mode = slow\n" in text
        with open(commands, "a") as handle:
            handle.write("4 SCF\n5 STOP\n")
        text = wait_for_seq(tmp_path, 5)
        assert "message = stopped the scan of seq 4" in text
        history = tmp_path / "history" / "results-00000004.txt"
        assert "message = stopped by seq 5" in history.read_text()
    finally:
        watcher.send_signal(signal.SIGINT)
        out, err = watcher.communicate(timeout=60)
    assert watcher.returncode == 0, err
    assert "Traceback" not in err
    assert "seq 4 SCF: error (stopped by seq 5)" in out
    # Restarted, the link finds everything answered and does nothing again.
    before = sorted(p.name for p in (tmp_path / "history").iterdir())
    again = subprocess.run(command + ["--once"], cwd=ROOT, capture_output=True, text=True,
                           timeout=120)
    assert again.returncode == 0 and again.stdout == ""
    assert sorted(p.name for p in (tmp_path / "history").iterdir()) == before == \
        [f"results-0000000{i}.txt" for i in range(1, 6)]


WRITER = """
import sys
from waferscan.core.files.text_files import atomic_write_text
versions = [("A" * 200 + "\\n") * 500, ("B" * 100 + "\\n") * 900]
print("ready", flush=True)
i = 0
while True:
    atomic_write_text(sys.argv[1], versions[i % 2])
    i += 1
"""


def test_results_are_never_half_written_when_the_writer_is_killed(tmp_path):
    """Kill the writer with SIGKILL at random moments, many times: results.txt is always one of
    the complete versions."""
    target = tmp_path / "results.txt"
    complete = {("A" * 200 + "\n") * 500, ("B" * 100 + "\n") * 900}
    rng = random.Random(5)
    kills = 0
    for _ in range(60):
        writer = subprocess.Popen([sys.executable, "-c", WRITER, str(target)], cwd=ROOT,
                                  stdout=subprocess.PIPE, text=True)
        writer.stdout.readline()
        time.sleep(rng.uniform(0.0, 0.03))
        writer.kill()
        writer.wait()
        kills += 1
        if target.exists():
            assert target.read_text() in complete
    assert kills == 60 and target.exists()
