"""Waking the MCS link as soon as its folder changes (SPEC §9: an answer's median <= 5 ms, an
idle watcher's CPU near zero): Linux's inotify, through the C library (no package), on a folder
of a local filesystem. Elsewhere (a network share, whose changes made on another machine this
kernel never sees; another kernel; no inotify watches left) there is nothing to wait on and the
link polls every ``--poll`` seconds as before.

``FolderWatch(folder).wait(seconds, stop)`` returns as soon as something in the folder was
written, created, moved or deleted, a stop was asked for (``stop.is_set()``: at once for the
MCS link's ``StopFlag``, whose pipe wakes the wait; every ``STOP_SLICE`` seconds for a flag
that can only be looked at), or ``seconds`` passed. A folder that is
removed loses its watch; the watch is made again once a folder of that name is back, and
meanwhile ``active`` is False (the caller polls)."""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import select
import struct
import time

IN_MODIFY = 0x00000002
IN_ATTRIB = 0x00000004
IN_CLOSE_WRITE = 0x00000008
IN_MOVED_FROM = 0x00000040
IN_MOVED_TO = 0x00000080
IN_CREATE = 0x00000100
IN_DELETE = 0x00000200
IN_DELETE_SELF = 0x00000400
IN_MOVE_SELF = 0x00000800
IN_IGNORED = 0x00008000
IN_NONBLOCK = 0o4000
IN_CLOEXEC = 0o2000000
MASK = (IN_MODIFY | IN_ATTRIB | IN_CLOSE_WRITE | IN_MOVED_FROM | IN_MOVED_TO | IN_CREATE
        | IN_DELETE | IN_DELETE_SELF | IN_MOVE_SELF)
STOP_SLICE = 0.05  # s: how often a wait looks at the stop flag (a signal handler only sets it)
EVENT = struct.Struct("=iIII")  # struct inotify_event: wd, mask, cookie, len (then the name)
# Filesystems whose changes may come from another machine, which inotify does not see.
REMOTE = {"nfs", "nfs4", "cifs", "smb3", "smbfs", "ncpfs", "afs", "9p", "ceph", "glusterfs",
          "lustre", "gpfs", "beegfs", "davfs", "sshfs", "fuse.sshfs", "fuse.rclone",
          "fuse.s3fs", "fuse.glusterfs", "fuse.cephfs", "fuse.gcsfuse", "fuse.davfs",
          "fuse.juicefs", "fuse.lizardfs", "fuse.moosefs"}


def _unescaped(field):
    """A /proc/self/mountinfo path field: spaces, tabs, newlines and backslashes are octal."""
    for code, char in (("\\040", " "), ("\\011", "\t"), ("\\012", "\n"), ("\\134", "\\")):
        field = field.replace(code, char)
    return field


def filesystem_type(path, mountinfo="/proc/self/mountinfo"):
    """The type of the filesystem that holds ``path`` (the longest mount point above it), or
    None when it cannot be told."""
    real = os.path.realpath(path)
    best, kind = "", None
    try:
        with open(mountinfo, encoding="utf-8", errors="replace") as table:
            for line in table:
                fields = line.split()
                if " - " not in line or len(fields) < 5:
                    continue
                point = _unescaped(fields[4])
                after = line.split(" - ", 1)[1].split()
                inside = real == point or real.startswith(point.rstrip("/") + "/")
                if after and inside and len(point) >= len(best):
                    best, kind = point, after[0]
    except OSError:
        return None
    return kind


def _libc():
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        libc.inotify_init1.argtypes = [ctypes.c_int]
        libc.inotify_add_watch.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_uint32]
        libc.inotify_rm_watch.argtypes = [ctypes.c_int, ctypes.c_int]
        return libc
    except (OSError, AttributeError):  # not Linux, or a C library without inotify
        return None


class FolderWatch:
    """inotify on one folder, when this machine and the folder's filesystem allow it."""

    def __init__(self, folder, mountinfo="/proc/self/mountinfo"):
        self.folder = os.fsencode(os.path.abspath(folder))
        self.fd = None
        self.watch = -1
        self.reason = None  # why there is no watch, in words
        kind = filesystem_type(folder, mountinfo)
        libc = _libc()
        if libc is None:
            self.reason = "this system has no inotify"
        elif kind is None or kind in REMOTE:
            self.reason = (f"the folder is on a {kind} filesystem, whose changes from other "
                           f"machines inotify does not see" if kind else
                           "the folder's filesystem cannot be told")
        else:
            fd = libc.inotify_init1(IN_NONBLOCK | IN_CLOEXEC)
            if fd < 0:
                self.reason = f"inotify: {os.strerror(ctypes.get_errno())}"
            else:
                self.fd, self._libc = fd, libc
                self._poller = select.poll()  # (select.select cannot take an fd over 1023)
                self._poller.register(fd, select.POLLIN)
                self._add()
                if self.watch < 0:
                    self.reason = f"inotify cannot watch it: {os.strerror(ctypes.get_errno())}"

    @property
    def active(self):
        """True while the folder is watched: a change wakes ``wait``."""
        return self.fd is not None and self.watch >= 0

    def _add(self):
        watch = self._libc.inotify_add_watch(self.fd, self.folder, MASK)
        self.watch = watch if watch >= 0 else -1

    def _drain(self):
        """Read the events waiting: (whether this watch's folder went away, whether the kernel
        already dropped the watch). Events of a watch removed before (a folder moved away and
        made again gets a new one) are read and let be."""
        gone = dropped = False
        while True:
            try:
                data = os.read(self.fd, 65536)
            except BlockingIOError:
                return gone, dropped
            except OSError:
                return True, True
            offset = 0
            while offset + EVENT.size <= len(data):
                wd, mask, _, length = EVENT.unpack_from(data, offset)
                if wd == self.watch:
                    gone |= bool(mask & (IN_IGNORED | IN_DELETE_SELF | IN_MOVE_SELF))
                    dropped |= bool(mask & IN_IGNORED)
                offset += EVENT.size + length

    def wait(self, seconds, stop):
        """Until something in the folder changes (True), or ``seconds`` passed or a stop was
        asked for (False; the caller reads ``stop`` itself). Without a watch, a plain wait."""
        if self.fd is not None and self.watch < 0 and os.path.isdir(self.folder):
            self._add()  # the folder is back: watched again, and read now
            if self.watch >= 0:
                return True
        # A stop flag that can wake the poll (mcs_link.StopFlag.wake_fd) lets it sleep until
        # the deadline; another is looked at every STOP_SLICE (20 wake-ups a second). Its file
        # descriptor is polled during this wait only (a flag's pipe closes with the flag).
        make = getattr(stop, "wake_fd", None) if self.active else None
        try:
            wake = None if make is None else make()
        except OSError:  # no file descriptor left for its pipe: the flag in slices
            wake = None
        if wake is None:
            return self._wait(seconds, stop, None)
        self._poller.register(wake, select.POLLIN)
        try:
            return self._wait(seconds, stop, wake)
        finally:
            self._poller.unregister(wake)

    def _wait(self, seconds, stop, wake):
        deadline = time.monotonic() + seconds
        while not stop.is_set():
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            if not self.active:
                time.sleep(min(left, STOP_SLICE))
                continue
            ready = self._poller.poll(1000.0 * (left if wake is not None else
                                                min(left, STOP_SLICE)))
            if any(fd == self.fd for fd, _ in ready):
                gone, dropped = self._drain()
                if gone:  # removed or moved away: polled until a folder is back
                    if not dropped:
                        self._libc.inotify_rm_watch(self.fd, self.watch)
                    self.watch = -1
                return True
        return False

    def close(self):
        if self.fd is not None:
            os.close(self.fd)
            self.fd, self.watch = None, -1
