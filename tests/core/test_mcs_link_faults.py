"""The MCS link under real faults (issue 10): seqs that are not seqs, repeated or backwards
seqs, torn and overlong lines, files that are not regular files, a folder that cannot be
written, two links on one folder, a bounded history. Each test failed before its fix."""

import errno
import os
import stat

import pytest

from waferscan.addon import paper_scenario
from waferscan.core.files import mcs_link
from waferscan.core.files.mcs_link import FolderBusy, McsLink, answered_seq
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

RESULT = scan_layout(read_scenario(paper_scenario()))


class Scan:
    def __init__(self, fail=None):
        self.calls = []
        self.fail = fail

    def __call__(self, command, should_stop):
        self.calls.append(command.seq)
        should_stop()
        if self.fail:
            raise self.fail
        return RESULT


class Link:
    """A link with its log and fault report kept."""

    def __init__(self, folder, scan=None):
        self.logged, self.reported = [], []
        self.scan = scan or Scan()
        self.link = McsLink(folder, self.scan, log=self.logged.append,
                            report=self.reported.append)

    def poll(self):
        return [(a.seq, a.command, a.status) for a in self.link.poll()]


def write(folder, text, mode="w"):
    with open(folder / "commands.txt", mode, encoding="utf-8", newline="") as handle:
        handle.write(text)


def results_header(folder):
    text = (folder / "results.txt").read_text()
    return dict(line.split(" = ", 1) for line in text.split("\n\n")[0].splitlines()
                if " = " in line)


def test_a_negative_seq_is_logged_once_and_never_carried_out(tmp_path):
    write(tmp_path, "-5 SCF\n")
    l = Link(tmp_path)
    for _ in range(5):
        assert l.poll() == []
    assert l.scan.calls == []
    assert l.logged == [f"{tmp_path / 'commands.txt'}:1: ignored: seq must be a whole number of "
                        "1 to 18 digits 0-9, got '-5'"]


@pytest.mark.parametrize("seq", ["1_0", "١٢", "１３", "+4", "1e3", "0x10"])
def test_only_ascii_digits_make_a_seq(tmp_path, seq):
    write(tmp_path, f"{seq} SCF\n1 SCF\n")
    l = Link(tmp_path)
    assert l.poll() == [(1, "SCF", "ok")]
    assert l.scan.calls == [1]
    assert len(l.logged) == 2 and "ignored: seq must be a whole number" in l.logged[0]


def test_a_huge_seq_is_refused_not_a_crash(tmp_path):
    write(tmp_path, "9" * 230 + " SCF\n" + "1" * 19 + " SCF\n" + "9" * 18 + " SCF\n")
    l = Link(tmp_path)
    assert l.poll() == [(10 ** 18 - 1, "SCF", "ok")]
    assert [m for m in l.logged if "ignored" in m][0].endswith(
        "got '9999999999999999999999999999999999999999'… (230 characters)")
    assert results_header(tmp_path)["seq"] == "9" * 18


def test_repeated_backwards_and_restarted_seqs_are_logged_not_answered(tmp_path):
    write(tmp_path, "1 SCF\n2 SCF\n")
    l = Link(tmp_path)
    assert l.poll() == [(1, "SCF", "ok"), (2, "SCF", "ok")]
    write(tmp_path, "2 SCF\n1 SCF\n3 SCS\n3 SCF\n", "a")  # repeated, backwards, new, repeated
    assert l.poll() == [(3, "SCS", "ok")]
    assert [m.split(": ignored: ")[1] for m in l.logged if "ignored" in m] == [
        "seq 2 is not above seq 2, already read (a seq is answered once)",
        "seq 1 is not above seq 2, already read (a seq is answered once)",
        "seq 3 is not above seq 3, already read (a seq is answered once)"]
    assert results_header(tmp_path)["seq"] == "3"  # the answer to 3 was not replaced
    # An MCS that restarts its numbering with a new file: told on the log, nothing answered.
    (tmp_path / "new").write_text("1 SCF\n2 SCF\n")
    os.replace(tmp_path / "new", tmp_path / "commands.txt")
    assert l.poll() == []
    assert l.logged[-1].endswith("read again from its start (replaced or truncated): 2 "
                                 "command(s) at or below the last answered seq 3 taken as "
                                 "answered")
    assert l.scan.calls == [1, 2, 3]


def test_a_bare_cr_ends_a_line(tmp_path):
    write(tmp_path, "4 SCF\r5 SCF\n6 SCS\r\n")
    assert Link(tmp_path).poll() == [(4, "SCF", "ok"), (5, "SCF", "ok"), (6, "SCS", "ok")]


def test_a_line_torn_by_a_killed_mcs_and_the_next_command(tmp_path):
    write(tmp_path, "56 SCF\n57 SC")
    l = Link(tmp_path)
    assert l.poll() == [(56, "SCF", "ok")]
    write(tmp_path, "58 SCF\n", "a")  # the restarted MCS writes on
    assert l.poll() == [(57, "?", "error"), (58, "SCF", "ok")]
    assert (tmp_path / "history" / "results-00000057.txt").read_text().splitlines()[3] == \
        "message = torn line '57 SC': its end never came (the MCS stopped mid-line?) and seq " \
        "58 was written after it"
    assert l.scan.calls == [56, 58]


@pytest.mark.parametrize("make", ["directory", "fifo", "symlink"])
def test_a_commands_file_that_cannot_be_read_is_reported_once(tmp_path, make):
    path = tmp_path / "commands.txt"
    if make == "directory":
        path.mkdir()
    elif make == "fifo":
        os.mkfifo(path)  # opening it for reading must not hang the link
    else:
        (tmp_path / "elsewhere.txt").write_text("1 SCF\n")
        path.symlink_to(tmp_path / "elsewhere.txt")
    l = Link(tmp_path)
    for _ in range(3):
        assert l.poll() == []
    reason = "a symbolic link (not followed)" if make == "symlink" else "not a regular file"
    assert l.reported == [f"{path}: cannot read: {reason}"]
    assert l.scan.calls == []


def test_a_line_longer_than_the_limit_is_refused_without_echo(tmp_path):
    write(tmp_path, "1 SCF " + "x" * 3_000_000 + "\n2 SCF\n")
    l = Link(tmp_path)
    answers = []
    for _ in range(5):  # read in bounded pieces
        answers += l.poll()
    assert answers == [(2, "SCF", "ok")]
    assert l.logged[0] == f"{tmp_path / 'commands.txt'}:1: longer than 1024 bytes: ignored"
    assert max(len(m) for m in l.logged) < 300
    assert os.path.getsize(tmp_path / "results.txt") < 5000


def test_an_unknown_command_is_not_echoed_in_full(tmp_path):
    write(tmp_path, "1 " + "Z" * 900 + "\n")
    l = Link(tmp_path)
    assert l.poll() == [(1, "?", "error")]
    message = results_header(tmp_path)["message"]
    assert message == f"unknown command '{'Z' * 40}'… (900 characters) (known: SCF, SCS, STOP, CAL, LOAD)"


def test_one_folder_one_link(tmp_path):
    first = Link(tmp_path)
    with pytest.raises(FolderBusy) as caught:
        Link(tmp_path)
    assert str(caught.value) == (f"{tmp_path}: another WaferScan link is watching this folder "
                                 f"(process {os.getpid()}): one folder, one link (lock "
                                 ".waferscan.lock)")
    first.link.close()
    write(tmp_path, "1 SCF\n")
    assert Link(tmp_path).poll() == [(1, "SCF", "ok")]


def test_a_second_link_leaves_the_first_ones_temporary_files_alone(tmp_path):
    first = Link(tmp_path)
    own = tmp_path / ".results.txt.inflight.tmp"
    own.write_text("being written")
    with pytest.raises(FolderBusy):
        Link(tmp_path)
    assert own.read_text() == "being written"
    first.link.close()


def test_results_txt_a_folder_keeps_the_seq_unanswered_until_it_can_be_written(tmp_path,
                                                                             monkeypatch):
    monkeypatch.setattr(mcs_link, "RETRY_SECONDS", 0.0)
    (tmp_path / "results.txt").mkdir()
    write(tmp_path, "1 SCF\n2 SCF\n")
    l = Link(tmp_path)
    assert l.poll() == [] and l.poll() == []
    assert l.scan.calls == [1]  # carried out once, its answer kept until it can be written
    assert not (tmp_path / "history").exists()  # nothing says 1 is done
    assert answered_seq(tmp_path) is None
    assert len(l.reported) == 1 and l.reported[0].startswith(
        f"{tmp_path / 'results.txt'}: cannot write the answer to seq 1: Is a directory; seq 1 "
        "stays unanswered")
    (tmp_path / "results.txt").rmdir()
    assert l.poll() == [(1, "SCF", "ok"), (2, "SCF", "ok")]
    assert l.scan.calls == [1, 2]
    assert sorted(os.listdir(tmp_path / "history")) == ["results-00000001.txt",
                                                       "results-00000002.txt"]


def test_history_a_file_still_answers_and_reports(tmp_path):
    (tmp_path / "history").write_text("the user's file")
    write(tmp_path, "1 SCF\n2 SCF\n")
    l = Link(tmp_path)
    assert l.poll() == [(1, "SCF", "ok"), (2, "SCF", "ok")]
    assert results_header(tmp_path)["seq"] == "2"
    assert (tmp_path / "history").read_text() == "the user's file"
    assert l.reported == [f"{tmp_path / 'history'}: cannot keep answers (from seq 1 on): not "
                          "a folder (a file or a symbolic link)"]  # once, not per answer


def test_disk_full_answers_briefly_or_waits(tmp_path, monkeypatch):
    """ENOSPC at the fsync of the full answer: a short error answer is tried; when even that
    fails, the seq waits and nothing counts as done."""
    monkeypatch.setattr(mcs_link, "RETRY_SECONDS", 0.0)
    real_fsync = os.fsync
    room = {"bytes": 0}

    def fsync(fd):
        if stat.S_ISREG(os.fstat(fd).st_mode) and os.fstat(fd).st_size > room["bytes"]:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_fsync(fd)

    monkeypatch.setattr(mcs_link.os, "fsync", fsync)
    write(tmp_path, "1 SCF\n")
    l = Link(tmp_path)
    assert l.poll() == [] and answered_seq(tmp_path) is None
    assert os.listdir(tmp_path) == [".waferscan.lock", "commands.txt"]  # no temporary left
    room["bytes"] = 500  # room for a short answer, not the table
    assert l.poll() == [(1, "SCF", "error")]
    assert results_header(tmp_path)["message"] == \
        "cannot write the answer to seq 1: No space left on device"
    assert l.reported[-1].endswith("answered status = error")
    room["bytes"] = 10 ** 9
    write(tmp_path, "2 SCF\n", "a")
    assert l.poll() == [(2, "SCF", "ok")]
    assert l.scan.calls == [1, 2]


def test_a_fault_in_a_scan_is_answered_and_the_link_goes_on(tmp_path):
    write(tmp_path, "1 SCF\n")
    l = Link(tmp_path, Scan(fail=OverflowError("cannot convert float infinity to integer")))
    assert l.poll() == [(1, "SCF", "error")]
    assert results_header(tmp_path)["message"] == \
        "internal error: OverflowError: 'cannot convert float infinity to integer'"
    assert "Traceback" in l.reported[0]
    l.link.scan = Scan()
    write(tmp_path, "2 SCF\n", "a")
    assert l.poll() == [(2, "SCF", "ok")]


def test_history_keeps_the_newest_answers(tmp_path, monkeypatch):
    monkeypatch.setattr(mcs_link, "HISTORY_KEEP", 20)
    l = Link(tmp_path)
    for seq in range(1, 46):
        write(tmp_path, f"{seq} SCF\n", "a")
        assert l.poll() == [(seq, "SCF", "ok")]
    kept = sorted(os.listdir(tmp_path / "history"))
    assert kept[0] >= "results-00000024.txt" and kept[-1] == "results-00000045.txt"
    assert 20 <= len(kept) <= 22  # pruned every HISTORY_KEEP / 10 answers


def test_history_holds_the_same_bytes_as_results(tmp_path):
    write(tmp_path, "1 SCF\n2 SCS\n")
    Link(tmp_path).poll()
    assert (tmp_path / "history" / "results-00000002.txt").read_bytes() == \
        (tmp_path / "results.txt").read_bytes()
    assert "seq = 1\n" in (tmp_path / "history" / "results-00000001.txt").read_text()


def test_only_what_was_appended_is_read(tmp_path, monkeypatch):
    write(tmp_path, "".join(f"{seq} SCF\n" for seq in range(1, 2001)))
    (tmp_path / "results.txt").write_text("seq = 2000\n")
    l = Link(tmp_path)
    assert l.poll() == []
    read = []
    real_read = os.read

    def counted(fd, size):
        data = real_read(fd, size)
        read.append(len(data))
        return data

    monkeypatch.setattr(mcs_link.os, "read", counted)
    for _ in range(10):
        assert l.poll() == []  # idle: not a byte read
    assert read == []
    write(tmp_path, "2001 SCS\n", "a")
    assert l.poll() == [(2001, "SCS", "ok")]
    assert read == [len("2001 SCS\n")]


def test_two_fsyncs_an_answer(tmp_path, monkeypatch):
    """The answer file and the folder (before: four, history and results written apart)."""
    synced = []
    real_fsync = os.fsync

    def fsync(fd):
        synced.append(stat.S_ISDIR(os.fstat(fd).st_mode))
        return real_fsync(fd)

    write(tmp_path, "1 SCF\n2 SCS\n3 STOP\n")
    l = Link(tmp_path)
    monkeypatch.setattr(mcs_link.os, "fsync", fsync)
    assert len(l.poll()) == 3
    assert synced == [False, True] * 3


def test_results_txt_a_symlink_is_replaced_not_followed_nor_its_mode_taken(tmp_path):
    outside = tmp_path / "outside.txt"
    outside.write_text("keep me\n")
    folder = tmp_path / "mcs"
    folder.mkdir()
    (folder / "results.txt").symlink_to(outside)
    write(folder, "1 SCF\n")
    assert Link(folder).poll() == [(1, "SCF", "ok")]
    assert outside.read_text() == "keep me\n"
    assert not (folder / "results.txt").is_symlink()
    assert stat.S_IMODE(os.stat(folder / "results.txt").st_mode) & 0o022 == 0


def test_a_planted_lock_symlink_is_refused(tmp_path):
    (tmp_path / ".waferscan.lock").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(mcs_link.InputError) as caught:
        Link(tmp_path)
    assert str(caught.value) == f"{tmp_path / '.waferscan.lock'}: a symbolic link: the folder " \
                                "cannot be locked; remove it"
