"""The folder's lock can be lost, and the folder can be reset (issue 25): the lock file deleted
or replaced, the folder removed and recreated while a link holds it, a link that could not lock
at its start, and an MCS that clears results.txt and history/ and starts again at seq 1. Two
links in one process hold two open files of the lock (flock is per open file), as two
processes would; tests/cad/test_watch_lock.py does the same with two real watchers. Each test
failed before the fix."""

import os
import shutil

import pytest

from waferscan.addon import paper_scenario
from waferscan.core.files.mcs_link import LOCK, LockLost, McsLink
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout

RESULT = scan_layout(read_scenario(paper_scenario()))


class Link:
    def __init__(self, folder, during=None):
        self.logged, self.reported, self.calls = [], [], []
        self.during = during  # called inside the next scan (once)
        self.link = McsLink(folder, self._scan, log=self.logged.append,
                            report=self.reported.append)

    def _scan(self, command, should_stop):
        self.calls.append(command.seq)
        should_stop()
        if self.during is not None:
            during, self.during = self.during, None
            during()
        return RESULT

    def poll(self):
        return [(a.seq, a.status) for a in self.link.poll()]

    def close(self):
        self.link.close()


def write(folder, text, mode="w"):
    with open(folder / "commands.txt", mode, encoding="utf-8") as handle:
        handle.write(text)


def seq_of(folder):
    text = (folder / "results.txt").read_text()
    return int(text.split("\n", 1)[0].removeprefix("seq = "))


def history(folder):
    return sorted(os.listdir(folder / "history"))


def test_a_deleted_lock_file_is_taken_again_and_a_second_link_is_refused(tmp_path):
    write(tmp_path, "1 SCF\n")
    first = Link(tmp_path)
    assert first.poll() == [(1, "ok")]
    os.unlink(tmp_path / LOCK)
    write(tmp_path, "2 SCF\n", "a")
    assert first.poll() == [(2, "ok")]  # the lock is taken again before anything is answered
    assert (tmp_path / LOCK).read_text() == f"{os.getpid()}\n"
    assert first.reported == [f"{tmp_path / LOCK}: removed or replaced while this link held "
                              "it: taken again"]
    with pytest.raises(Exception) as caught:
        Link(tmp_path)
    assert "another WaferScan link is watching this folder" in str(caught.value)
    first.close()


def test_a_link_whose_lock_was_taken_by_another_stops_and_never_answers(tmp_path):
    write(tmp_path, "1 SCF\n")
    first = Link(tmp_path)
    assert first.poll() == [(1, "ok")]
    os.unlink(tmp_path / LOCK)
    second = Link(tmp_path)  # took a fresh lock file before the first one looked
    write(tmp_path, "2 SCF\n3 SCS\n", "a")
    with pytest.raises(LockLost) as caught:
        first.poll()
    assert str(caught.value) == (f"{tmp_path}: lost the folder's lock to another WaferScan link "
                                 f"(process {os.getpid()}): this link stops answering")
    assert first.calls == [1] and seq_of(tmp_path) == 1
    assert second.poll() == [(2, "ok"), (3, "ok")]
    with pytest.raises(LockLost):  # and goes on refusing
        first.poll()
    assert first.calls == [1] and seq_of(tmp_path) == 3
    assert history(tmp_path) == [f"results-0000000{n}.txt" for n in (1, 2, 3)]
    second.close()
    first.close()


def test_a_lock_lost_during_a_scan_leaves_the_answer_to_the_new_holder(tmp_path):
    links = {}

    def thief():  # while the first scans seq 2: the lock file deleted, a second link started
        os.unlink(tmp_path / LOCK)
        links["second"] = Link(tmp_path)

    write(tmp_path, "1 SCF\n")
    first = Link(tmp_path)
    assert first.poll() == [(1, "ok")]
    first.during = thief
    write(tmp_path, "2 SCF\n", "a")
    with pytest.raises(LockLost):
        first.poll()
    assert first.calls == [1, 2] and seq_of(tmp_path) == 1  # scanned, never written
    assert links["second"].poll() == [(2, "ok")]
    assert links["second"].calls == [2] and seq_of(tmp_path) == 2
    links["second"].close()
    first.close()


def test_a_folder_removed_and_recreated_is_a_new_folder_from_seq_1(tmp_path):
    folder = tmp_path / "mcs"
    folder.mkdir()
    write(folder, "".join(f"{n} SCF\n" for n in range(1, 6)))
    first = Link(folder)
    assert [s for s, _ in first.poll()] == [1, 2, 3, 4, 5]
    shutil.rmtree(folder)  # the MCS "clears the folder"
    folder.mkdir()
    write(folder, "1 SCS\n2 SCF\n")
    assert first.poll() == [(1, "ok"), (2, "ok")]
    assert seq_of(folder) == 2 and (folder / LOCK).read_text() == f"{os.getpid()}\n"
    assert history(folder) == ["results-00000001.txt", "results-00000002.txt"]
    first.close()


def test_a_folder_recreated_and_taken_by_another_link_stops_the_first(tmp_path):
    folder = tmp_path / "mcs"
    folder.mkdir()
    write(folder, "1 SCF\n")
    first = Link(folder)
    assert first.poll() == [(1, "ok")]
    shutil.rmtree(folder)
    folder.mkdir()
    second = Link(folder)
    write(folder, "1 SCF\n2 SCF\n")
    with pytest.raises(LockLost):
        first.poll()
    assert second.poll() == [(1, "ok"), (2, "ok")]
    assert first.calls == [1] and second.calls == [1, 2]
    second.close()
    first.close()


@pytest.mark.parametrize("rewrite", ["replaced", "truncated"])
def test_the_reset_results_and_history_cleared_then_commands_from_seq_1(tmp_path, rewrite):
    write(tmp_path, "".join(f"{n} SCF\n" for n in range(1, 58)))
    link = Link(tmp_path)
    assert len(link.poll()) == 57 and seq_of(tmp_path) == 57
    # The reset (RELIABILITY.md): results.txt and history/ removed first, then commands.txt
    # written again from seq 1 (a new file, or the same one truncated).
    os.unlink(tmp_path / "results.txt")
    shutil.rmtree(tmp_path / "history")
    if rewrite == "replaced":
        os.unlink(tmp_path / "commands.txt")
        write(tmp_path, "1 SCS\n2 SCF\n")
    else:
        with open(tmp_path / "commands.txt", "r+", encoding="utf-8") as handle:
            handle.truncate(0)
            handle.write("1 SCS\n2 SCF\n")
    assert link.poll() == [(1, "ok"), (2, "ok")]
    assert seq_of(tmp_path) == 2
    assert history(tmp_path) == ["results-00000001.txt", "results-00000002.txt"]
    assert link.logged[-3] == (f"{tmp_path / 'commands.txt'}: read again from its start with "
                               "results.txt and history/ cleared: the folder was reset, seqs "
                               "count from the start again")
    write(tmp_path, "3 STOP\n", "a")
    assert link.poll() == [(3, "ok")]
    link.close()


def test_commands_read_again_without_the_reset_are_still_taken_as_answered(tmp_path):
    write(tmp_path, "1 SCF\n2 SCF\n")
    link = Link(tmp_path)
    assert link.poll() == [(1, "ok"), (2, "ok")]
    os.unlink(tmp_path / "commands.txt")
    write(tmp_path, "1 SCF\n2 SCF\n3 SCS\n")  # results.txt kept: no reset
    assert link.poll() == [(3, "ok")]
    assert link.calls == [1, 2, 3]
    link.close()


def test_a_reset_during_a_scan_drops_that_scans_answer(tmp_path):
    def reset():
        os.unlink(tmp_path / "results.txt")
        shutil.rmtree(tmp_path / "history")
        os.unlink(tmp_path / "commands.txt")
        write(tmp_path, "1 SCS\n")

    write(tmp_path, "1 SCF\n2 SCF\n3 SCF\n")
    link = Link(tmp_path)
    link.during = None
    assert link.poll() == [(1, "ok"), (2, "ok"), (3, "ok")]
    link.during = reset
    write(tmp_path, "4 SCF\n", "a")
    assert link.poll() == [(1, "ok")]  # seq 4 of the old numbering is never written
    assert link.calls == [1, 2, 3, 4, 1] and seq_of(tmp_path) == 1
    assert history(tmp_path) == ["results-00000001.txt"]
    link.close()
