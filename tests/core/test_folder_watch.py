"""The MCS link's folder watch (SPEC §9: an answer's median <= 5 ms, an idle watcher's CPU
near zero): inotify wakes a wait as soon as the folder changes; a removed folder is polled
until it is back; a network filesystem, whose changes from other machines inotify never sees,
is polled. Outcomes, not times: a wait of a minute that returns True was woken."""

import os
import threading
import time

import pytest

from waferscan.core.files import folder_watch
from waferscan.core.files.folder_watch import FolderWatch, filesystem_type
from waferscan.core.files.mcs_link import StopFlag

LONG = 60.0  # a wait this long that returns True was woken by the change


def later(action, delay=0.2):
    thread = threading.Thread(target=lambda: (time.sleep(delay), action()))
    thread.start()
    return thread


@pytest.fixture
def watched(tmp_path):
    watch = FolderWatch(tmp_path)
    if not watch.active:
        pytest.skip(f"no inotify here: {watch.reason}")
    yield tmp_path, watch
    watch.close()


def test_a_command_appended_wakes_the_wait(watched):
    folder, watch = watched
    (folder / "commands.txt").write_text("")
    watch.wait(0.0, StopFlag())  # the write above, read
    thread = later(lambda: open(folder / "commands.txt", "a").write("1 SCF\n"))
    assert watch.wait(LONG, StopFlag()) is True
    thread.join()
    assert watch.wait(0.2, StopFlag()) in (True, False)  # what the append's close left
    assert watch.wait(0.2, StopFlag()) is False  # nothing since: the wait runs out


def test_a_file_replaced_by_a_rename_wakes_it(watched):
    folder, watch = watched
    (folder / "parameters.txt.tmp").write_text("z_step = 0.1\n")
    watch.wait(0.0, StopFlag())
    thread = later(lambda: os.replace(folder / "parameters.txt.tmp",
                                      folder / "parameters.txt"))
    assert watch.wait(LONG, StopFlag()) is True
    thread.join()


def test_a_stop_ends_the_wait(watched):
    _, watch = watched
    stop = StopFlag()
    thread = later(stop.set)
    assert watch.wait(LONG, stop) is False and stop.is_set()
    thread.join()


class CountedPoll:
    """A watch's poller, its polls counted."""

    def __init__(self, poller):
        self.poller, self.calls = poller, 0

    def poll(self, *args):
        self.calls += 1
        return self.poller.poll(*args)

    def register(self, *args):
        return self.poller.register(*args)

    def unregister(self, *args):
        return self.poller.unregister(*args)


def test_an_idle_wait_sleeps_until_its_deadline(watched):
    """With the MCS link's StopFlag, whose pipe wakes the poll, an idle wait is one poll to its
    deadline; with a flag that can only be looked at (a threading.Event), one every
    STOP_SLICE."""
    _, watch = watched
    counted = watch._poller = CountedPoll(watch._poller)
    assert watch.wait(0.6, StopFlag()) is False
    assert counted.calls == 1
    counted.calls = 0
    assert watch.wait(0.6, threading.Event()) is False
    assert counted.calls >= 0.6 / folder_watch.STOP_SLICE - 2


def test_a_signal_ends_the_wait_at_once(watched):
    """SIGINT and SIGTERM set the flag from a handler (``stop_on_signals``): its pipe ends a
    wait of a minute there and then."""
    import signal

    _, watch = watched
    stop = StopFlag()
    old = signal.signal(signal.SIGALRM, stop.set)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.2)
        assert watch.wait(LONG, stop) is False and stop.is_set()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_a_flag_set_before_the_wait_ends_it(watched):
    _, watch = watched
    stop = StopFlag()
    stop.set()
    assert watch.wait(LONG, stop) is False
    stop.wake_fd()  # made after the request: readable all the same
    assert watch._poller.poll(0) == [] and select_readable(stop.wake_fd())


def select_readable(fd):
    import select

    return bool(select.select([fd], [], [], 0)[0])


def test_a_removed_folder_is_polled_until_it_is_back(watched):
    folder, watch = watched
    thread = later(lambda: os.rmdir(folder))
    assert watch.wait(LONG, StopFlag()) is True
    thread.join()
    if watch.active:  # the removal's events may come in two reads
        assert watch.wait(LONG, StopFlag()) is True
    assert not watch.active
    assert watch.wait(0.1, StopFlag()) is False  # away: a plain wait
    folder.mkdir()
    assert watch.wait(LONG, StopFlag()) is True and watch.active  # back: watched, read now
    thread = later(lambda: (folder / "commands.txt").write_text("1 SCF\n"))
    assert watch.wait(LONG, StopFlag()) is True
    thread.join()


def _mountinfo(tmp_path, point, kind):
    table = tmp_path / "mountinfo"
    table.write_text(f"22 1 8:1 / / rw,relatime shared:1 - ext4 /dev/sda1 rw\n"
                     f"40 22 0:50 / {point} rw,relatime shared:20 - {kind} server:/x rw\n")
    return table


@pytest.mark.parametrize("kind", ["nfs4", "cifs", "fuse.sshfs"])
def test_a_network_filesystem_is_polled(tmp_path, kind):
    table = _mountinfo(tmp_path, str(tmp_path).replace(" ", "\\040"), kind)
    assert filesystem_type(tmp_path, table) == kind
    watch = FolderWatch(tmp_path, mountinfo=table)
    assert not watch.active
    assert watch.reason == (f"the folder is on a {kind} filesystem, whose changes from other "
                            f"machines inotify does not see")
    stop = StopFlag()
    assert watch.wait(0.1, stop) is False


def test_the_longest_mount_point_above_the_folder_is_its_filesystem(tmp_path):
    table = _mountinfo(tmp_path, "/mnt/share", "nfs")
    assert filesystem_type("/mnt/share/mcs", table) == "nfs"
    assert filesystem_type("/mnt/shared", table) == "ext4"  # not under /mnt/share
    assert filesystem_type("/mnt/share", table) == "nfs"
    assert filesystem_type("/x", tmp_path / "missing") is None


def test_without_inotify_the_wait_is_a_plain_one(tmp_path, monkeypatch):
    monkeypatch.setattr(folder_watch, "_libc", lambda: None)
    watch = FolderWatch(tmp_path)
    assert not watch.active and watch.reason == "this system has no inotify"
    assert watch.wait(0.1, StopFlag()) is False


def test_a_folder_moved_aside_and_made_again_is_watched_not_spun_on(tmp_path):
    # The kernel's IN_IGNORED for the watch removed when the folder moved away arrives after
    # the new folder's watch was made: it must not take that one away too (a wait that
    # returned True at once, for ever, after such a move: a watcher spinning on a core).
    folder = tmp_path / "mcs"
    folder.mkdir()
    watch = FolderWatch(folder)
    if not watch.active:
        pytest.skip(f"no inotify here: {watch.reason}")
    try:
        folder.rename(tmp_path / "mcs.old")
        assert watch.wait(LONG, StopFlag()) is True and not watch.active
        folder.mkdir()
        assert watch.wait(LONG, StopFlag()) is True and watch.active  # back: read now
        woken = [watch.wait(0.2, StopFlag()) for _ in range(3)]
        assert watch.active and woken.count(False) >= 2, woken  # nothing changed: waits run out
        thread = later(lambda: (folder / "commands.txt").write_text("1 SCF\n"))
        assert watch.wait(LONG, StopFlag()) is True  # and a change still wakes it
        thread.join()
    finally:
        watch.close()
