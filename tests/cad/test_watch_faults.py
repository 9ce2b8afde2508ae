"""The MCS link on a FreeCAD document against a hostile folder and a careless user (issue 10):
parameters.txt that is a symlink, a FIFO, a device, too large, half-written or contradicting
the command; labels that would forge results.txt lines; values that overflow together; the
layout read once and again only after the document changed."""

import os

import FreeCAD as App
import pytest
from scenarios import PAPER_CODE as CODE

from waferscan.addon import paper_scenario
from waferscan.cad import mcs_watch
from waferscan.cad.layout_files import open_layout
from waferscan.cad.mcs_watch import document_scanner
from waferscan.core.files.mcs_link import McsLink



@pytest.fixture
def doc():
    document = open_layout(paper_scenario())
    name = document.Name
    yield document
    App.closeDocument(name)


def answers(doc, folder, commands, engine="analytic"):
    (folder / "commands.txt").write_text(commands)
    scan = document_scanner(doc, folder, engine)
    link = McsLink(folder, scan, log=lambda text: None)
    try:
        return [(a.seq, a.status, a.code or a.message) for a in link.poll()]
    finally:
        link.close()
        scan.close()


def test_a_symlinked_parameters_file_is_not_followed(doc, tmp_path):
    secret = tmp_path / "secret"
    secret.write_text("root password hunter2\n")
    os.chmod(secret, 0o600)
    folder = tmp_path / "mcs"
    folder.mkdir()
    (folder / "parameters.txt").symlink_to(secret)
    assert answers(doc, folder, "1 SCF\n") == [
        (1, "error", f"{folder / 'parameters.txt'}: cannot read: a symbolic link (not followed)")]
    assert "hunter2" not in (folder / "results.txt").read_text()


def test_a_fifo_or_a_device_as_parameters_does_not_hang_or_grow(doc, tmp_path):
    os.mkfifo(tmp_path / "parameters.txt")
    assert answers(doc, tmp_path, "1 SCF\n") == [
        (1, "error", f"{tmp_path / 'parameters.txt'}: cannot read: not a regular file")]
    os.unlink(tmp_path / "parameters.txt")
    os.symlink("/dev/zero", tmp_path / "parameters.txt")
    assert answers(doc, tmp_path, "1 SCF\n2 SCF\n")[0][1:] == (
        "error", f"{tmp_path / 'parameters.txt'}: cannot read: a symbolic link (not followed)")


def test_a_parameters_file_larger_than_the_limit_is_refused(doc, tmp_path):
    (tmp_path / "parameters.txt").write_text("# padding\n" * 7000)
    assert answers(doc, tmp_path, "1 SCF\n") == [
        (1, "error", f"{tmp_path / 'parameters.txt'}: larger than 65,536 bytes: not read")]


def test_a_half_written_last_line_of_parameters_is_not_taken(doc, tmp_path):
    (tmp_path / "parameters.txt").write_text("scan_speed = 100\nz_step = 0.0")  # of 0.05
    assert answers(doc, tmp_path, "1 SCF\n") == [
        (1, "error", f"{tmp_path / 'parameters.txt'}:2: the last line has no line end: it may "
                     "still be being written; end every line with a newline")]
    with open(tmp_path / "parameters.txt", "a") as handle:
        handle.write("5\n")
    assert answers(doc, tmp_path, "1 SCF\n2 SCF\n") == [(2, "ok", CODE)]


def test_a_mode_line_that_contradicts_the_command_is_said_in_the_answer(doc, tmp_path):
    (tmp_path / "parameters.txt").write_text("z_step = 0.05\nmode = slow\n")
    assert answers(doc, tmp_path, "1 SCF\n2 SCS\n") == [(1, "ok", CODE), (2, "ok", CODE)]
    first = (tmp_path / "history" / "results-00000001.txt").read_text().splitlines()
    assert first[3] == f"message = {tmp_path / 'parameters.txt'}:2: mode = slow is overridden " \
                       "by SCF (fast scan)"
    assert "mode = fast" in first
    second = (tmp_path / "history" / "results-00000002.txt").read_text().splitlines()
    assert second[3] == "message =" and "mode = slow" in second


@pytest.mark.parametrize("text, line, key", [
    ("scan_speed = 1e200\nsensor_response = 1e200\n", 2, "sensor_response"),
    ("direction = updown\nscan_speed = 1e200\nsensor_response = 1e200\n", 3, "sensor_response"),
    ("first_slot_z = 1e308\n", 1, "first_slot_z"),
    ("slot_pitch = 1e308\n", 1, "slot_pitch"),
])
def test_parameters_that_overflow_together_are_error_answers(doc, tmp_path, text, line, key):
    (tmp_path / "parameters.txt").write_text(text)
    (answer,) = answers(doc, tmp_path, "1 SCS\n")[:1]
    assert answer[:2] == (1, "error")
    assert answer[2].startswith(f"{tmp_path / 'parameters.txt'}:{line}: {key}: ")


def test_a_label_cannot_forge_lines_in_results(doc, tmp_path):
    wafer = doc.getObjectsByLabel("LP1_W01")[0]
    wafer.Label = "W1\tx\nseq = 99999"
    assert answers(doc, tmp_path, "1 SCF\n") == [(1, "ok", CODE)]
    lines = (tmp_path / "results.txt").read_text().split("\n")
    assert [line for line in lines if line.startswith("seq = ")] == ["seq = 1"]
    table = lines[lines.index("") + 1:-1]
    assert all(row.count("\t") == 6 for row in table)
    assert any("W1\\tx\\nseq = 99999" in row for row in table)


def test_the_layout_is_read_once_and_again_after_a_change(doc, tmp_path, monkeypatch):
    reads = []
    real = mcs_watch.read_layout

    def counted(document, scene=None):
        reads.append(1)
        return real(document, scene)

    monkeypatch.setattr(mcs_watch, "read_layout", counted)
    scan = document_scanner(doc, tmp_path, "document")
    link = McsLink(tmp_path, scan, log=lambda text: None)
    (tmp_path / "parameters.txt").write_text("z_step = 0.5\n")
    try:
        for seq in range(1, 5):
            with open(tmp_path / "commands.txt", "a") as handle:
                handle.write(f"{seq} SCF\n")
            (answer,) = link.poll()
            assert answer.status == "ok"
        assert len(reads) == 1  # the document engine's own moves are not edits
        doc.removeObject(doc.getObjectsByLabel("LP1_W05")[0].Name)
        with open(tmp_path / "commands.txt", "a") as handle:
            handle.write("5 SCF\n")
        (answer,) = link.poll()
        assert len(reads) == 2 and answer.code == "1101220001220001010000010"
    finally:
        link.close()
        scan.close()


# --- issue 25 ----------------------------------------------------------------------------

@pytest.mark.parametrize("engine", ["document", "brep"])
def test_cal_on_a_watcher_with_a_document_engine_is_answered_as_bad_input(doc, tmp_path,
                                                                           engine):
    reports = []
    (tmp_path / "commands.txt").write_text("1 CAL\n2 SCF\n")
    scan = document_scanner(doc, tmp_path, engine)
    link = McsLink(tmp_path, scan, log=lambda text: None, report=reports.append)
    try:
        answered = [(a.seq, a.status, a.code or a.message) for a in link.poll()]
    finally:
        link.close()
        scan.close()
    assert answered == [
        (1, "error", f"{tmp_path / 'commands.txt'}:1: CAL calibrates with the core engines "
                     "only (analytic, loop, paper, vector), as `waferscan calibrate` does; this "
                     f"watcher scans with the {engine} engine: start one with --engine analytic "
                     "to calibrate"),
        (2, "ok", CODE)]
    assert reports == []  # no internal error, no traceback


LONG = "x" * 60000


@pytest.mark.parametrize("text, message", [
    (f"{LONG}\n", "1: expected 'key = value' (a line of 60,000 characters)"),
    (f"{LONG} = 1\n", "1: unknown key (60,000 characters) (known: "),
    (f"z_step = {LONG}\n", "1: z_step: a value of 60,000 characters: not read"),
    (f"carrier = {LONG}\n", "1: carrier: a value of 60,000 characters: not read"),
    ("root:$6$saltsalt$hashhashhash:19000:0:99999:7:::\n",
     "1: expected 'key = value' (a line of 48 characters)"),
    ("secret_token = hunter2\n", "1: unknown key 'secret_token' (known: "),
    ("z_stp = 0.5\n", "1: unknown key 'z_stp' (known: "),
    ("z_step = abc\n", "1: z_step: expected a number, got 'abc'"),
])
def test_a_bad_parameters_line_is_echoed_bounded_and_only_as_far_as_recognised(doc, tmp_path,
                                                                               text, message):
    (tmp_path / "parameters.txt").write_text(text)
    (answer,) = answers(doc, tmp_path, "1 SCF\n")
    assert answer[:2] == (1, "error")
    assert answer[2].startswith(f"{tmp_path / 'parameters.txt'}:{message}"), answer[2]
    assert len(answer[2]) < 2000
    results = (tmp_path / "results.txt").read_text()
    assert "hunter2" not in results and "saltsalt" not in results and LONG not in results
    assert os.path.getsize(tmp_path / "results.txt") < 5000
