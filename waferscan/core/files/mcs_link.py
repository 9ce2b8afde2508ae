"""The MCS link as a protocol: watch commands.txt, carry out each seq exactly once, answer in
results.txt. docs/reliability.md lists every rule below with the test that holds it.

- One folder, one link: the link holds an exclusive lock (``flock``) on ``.waferscan.lock`` in
  the folder while it lives; a second one is refused (``FolderBusy``). The link answers only
  under that lock, and checks that it is still the folder's before it carries anything out and
  before each answer is written: a lock file deleted or replaced, or a folder removed and
  recreated, is locked again if it is free (what has been done is then read again from the
  folder), and when another link holds it now this one raises ``LockLost`` and never answers
  again. A folder that cannot be locked (read-only, no lock file) gets nothing carried out
  until it can be.
- The reset: results.txt and history/ removed, then commands.txt written again from its start
  (a new file or the same one truncated): the seqs count from the start again, and an answer
  being carried out at that moment is dropped.
- What has been done is read from the folder once, when the link starts: the highest seq
  answered in results.txt, or in the history folder when results.txt is gone. A restarted link
  carries on where the last one stopped. From then on the link (the only writer) keeps it.
- commands.txt is followed by name and read only where it grew: a file replaced (another inode)
  or truncated is read again from its start, and the seqs in it at or below the last answered
  are taken as answered. A last line without its newline is still being written and waits; a
  CR alone ends a line too.
- A seq is 1 to 18 ASCII digits. A line whose seq is not one cannot be answered by seq: it is
  logged (file, line and at most ``SHOWN`` characters of it) and skipped. A seq at or below one
  already answered or read is logged and not answered (results.txt's seq only ever grows, so an
  answer the MCS may be reading is never replaced by one for another command of the same seq).
- A line torn by an MCS killed mid-line and the next command written after it
  (``57 SC`` + ``58 SCF`` = ``57 SC58 SCF``): 57 is answered ``status = error`` (torn line) and 58
  is carried out.
- A command that cannot be carried out (unknown, bad parameters, a scan that fails on bad input)
  is answered with ``status = error`` and the link goes on.
- Every answer is written once to a temporary file beside results.txt, flushed to disk, renamed
  over results.txt (atomic), and the folder flushed: two fsyncs. The same file is then
  hard-linked as ``history/results-<seq>.txt`` (the newest ``HISTORY_KEEP`` are kept). Only an
  answer that reached results.txt counts as done: a fault (disk full, read-only folder,
  results.txt a folder) is reported and the answer is written again at the next polls; when the
  full answer does not fit, a short ``status = error`` answer naming the fault is tried.
- STOP: a scan checks commands.txt while it runs; a STOP that is the next command aborts it. The
  scan is answered ``status = error`` ("stopped by seq N"), then the STOP ``status = ok``. A STOP
  with no scan running is answered ``ok``, "no scan running". Answers are always in seq order.
- The folder's files are read only when they are regular files (a symlink, a FIFO or a device
  is refused) of bounded size: commands.txt lines of at most ``MAX_LINE`` bytes.
"""

from __future__ import annotations

import collections
import errno
import fcntl
import os
import re
import stat
import sys
import threading
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..scan.calibration import CalibrationError
from .mcs import COMMAND_NAMES, COMMANDS, RESULTS, Command, format_results, refusal
from .text_files import atomic_write_text

HISTORY = "history"
LOCK = ".waferscan.lock"
HISTORY_KEEP = 1000  # answers kept in history/ (the newest); older ones are deleted
MAX_LINE = 1024  # bytes of one commands.txt line; a longer one is refused unread
MAX_SEQ_DIGITS = 18  # a seq fits a signed 64-bit integer and makes a short file name
MAX_READ = 1 << 20  # bytes of commands.txt read in one go
SHOWN = 40  # characters of a bad line repeated in a log or an answer
RETRY_SECONDS = 1.0  # how often an answer that could not be written is tried again

_SEQ = re.compile(r"^seq = ([0-9]+)\s*$", re.MULTILINE)
_HISTORY_NAME = re.compile(r"^results-([0-9]+)\.txt$")
_SEQ_WORD = re.compile(rf"[0-9]{{1,{MAX_SEQ_DIGITS}}}")
# "<seq> <COMMAND>" inside a line, not preceded by a digit: the start of a command written
# after a torn one.
_TAIL = re.compile(rf"(?<![0-9])([0-9]{{1,{MAX_SEQ_DIGITS}}})[ \t]+([A-Za-z]+)(?=[ \t]|$)")


class ScanStopped(Exception):
    """Raised inside a scan when a STOP arrives; carries the STOP's seq."""

    def __init__(self, seq):
        super().__init__(f"stopped by seq {seq}")
        self.seq = seq


class FolderBusy(InputError):
    """Another link holds the folder's lock."""


class LockLost(Exception):
    """The folder's lock is another link's now (its file deleted or replaced, the folder
    removed and recreated, a folder that could not be locked taken by another): this link
    stops answering."""


_PIPE_MADE = threading.Lock()  # StopFlag.wake_fd: one pipe a flag


class StopFlag:
    """Set by SIGINT or SIGTERM (``stop_on_signals``): a plain flag. A signal handler runs in
    the main thread between any two of its steps, so it must take no lock the main thread may
    hold at that moment (a threading.Event's does: its set() would wait for ever on the lock
    its own wait() holds)."""

    def __init__(self):
        self.requested = False
        self._wake = None  # (read end, write end) of a pipe, once a waiter asked for it

    def set(self, *_):
        self.requested = True
        wake = self._wake
        if wake is not None:
            try:
                os.write(wake[1], b"!")  # a write to a pipe: no lock, as a handler needs
            except OSError:  # full (already readable) or closed
                pass

    def is_set(self):
        return self.requested

    def wake_fd(self):
        """A file descriptor that is readable once a stop was requested, for a wait on file
        descriptors (``folder_watch.FolderWatch.wait``) to end at the request instead of
        looking at the flag in slices: an idle watcher then sleeps until something happens."""
        if self._wake is None:
            with _PIPE_MADE:  # (waiters only: a handler's set() takes no lock)
                if self._wake is None:  # two waiting threads make one pipe
                    self._wake = os.pipe2(os.O_NONBLOCK | os.O_CLOEXEC)
                    if self.requested:  # requested before the pipe was there
                        self.set()
        return self._wake[0]

    def __del__(self):
        wake, self._wake = getattr(self, "_wake", None), None
        for fd in wake or ():
            try:
                os.close(fd)
            except OSError:
                pass

    def wait(self, seconds):
        """Sleep up to ``seconds``, in slices, ending early once a stop is requested."""
        deadline = time.monotonic() + seconds
        while not self.requested:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            time.sleep(min(left, 0.05))
        return self.requested


def stop_on_signals(flag):
    """SIGINT and SIGTERM set ``flag`` instead of raising KeyboardInterrupt or ending the
    process (main thread only). Returns the handlers replaced."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return {}
    return {number: signal.signal(number, flag.set)
            for number in (signal.SIGINT, signal.SIGTERM)}


@dataclass(frozen=True)
class Scanned:
    """What a scan function may return in place of a bare ScanResult: the result and a note
    for the answer's ``message`` line (e.g. a parameter the command overrode)."""

    result: object
    message: str = ""
    recipe: dict | None = None  # a CAL's calibrated recipe, for results.txt's header


@dataclass(frozen=True)
class Answer:
    seq: int
    command: str
    status: str
    message: str
    code: str = ""


def shown(text):
    """At most SHOWN characters of a user's text, for a message (a 100 MB line stays in its
    file)."""
    text = str(text)
    return repr(text) if len(text) <= SHOWN else repr(text[:SHOWN]) + f"… ({len(text):,} characters)"


def open_regular(path):
    """A read-only descriptor of ``path`` if it is a regular file, not followed through a
    symlink; OSError otherwise (ELOOP for a symlink, EINVAL for a FIFO, a device or a folder).
    O_NONBLOCK: opening a FIFO must not wait for a writer."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file")
    except BaseException:
        os.close(fd)
        raise
    return fd


def _identity(st):
    return st.st_dev, st.st_ino


def _same_file(a, b):
    return _identity(a) == _identity(b) and a.st_nlink > 0


def _reason(exc):
    if exc.errno == errno.ELOOP:
        return "a symbolic link (not followed)"
    return exc.strerror or str(exc)


def read_regular_text(path, limit):
    """The text (UTF-8, BOM dropped) of a regular file of at most ``limit`` bytes; an
    InputError naming the file otherwise. FileNotFoundError passes through."""
    try:
        fd = open_regular(path)
    except FileNotFoundError:
        raise
    except OSError as exc:
        raise InputError(path, None, f"cannot read: {_reason(exc)}") from None
    try:
        with os.fdopen(fd, "rb") as handle:
            raw = handle.read(limit + 1)
    except OSError as exc:
        raise InputError(path, None, f"cannot read: {_reason(exc)}") from None
    if len(raw) > limit:
        raise InputError(path, None, f"larger than {limit:,} bytes: not read")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(path, raw[:exc.start].count(b"\n") + 1, "not UTF-8 text") from None


def answered_seq(folder):
    """The highest seq answered so far in the folder, or None: results.txt says it (its first
    4 kB); the history folder is read only when results.txt is missing or unreadable."""
    folder = Path(folder)
    try:
        fd = open_regular(folder / RESULTS)
        with os.fdopen(fd, "rb") as handle:
            head = handle.read(4096).decode("utf-8-sig", errors="replace")
        match = _SEQ.search(head)
        if match:
            return int(match.group(1))
    except OSError:
        pass
    seqs = []
    history = folder / HISTORY
    try:
        names = os.listdir(history) if not history.is_symlink() else []
    except OSError:
        names = []
    for name in names:
        match = _HISTORY_NAME.match(name)
        if match:
            seqs.append(int(match.group(1)))
    return max(seqs, default=None)


def parse_command_line(text, number):
    """The commands of one line of commands.txt (without its line end), as a list of
    ``Command`` (none for a blank or comment line). A line whose seq is not 1 to 18 ASCII
    digits gives a Command with seq None and the problem; a torn line followed by a command
    gives two (see the module's docstring)."""
    content = text.split("#", 1)[0].strip()
    if not content:
        return []
    words = content.split()
    if not _SEQ_WORD.fullmatch(words[0]):
        return [Command(None, "", (), number,
                        f"seq must be a whole number of 1 to {MAX_SEQ_DIGITS} digits 0-9, "
                        f"got {shown(words[0])}")]
    seq = int(words[0])
    name = words[1].upper() if len(words) > 1 else ""
    if name in COMMAND_NAMES:
        return [Command(seq, name, tuple(words[2:]), number)]
    for tail in _TAIL.finditer(content, len(words[0])):
        if tail.group(2).upper() in COMMAND_NAMES and int(tail.group(1)) > seq:
            torn = content[:tail.start()].strip()
            rest = parse_command_line(content[tail.start():], number)
            return [Command(seq, "?", (), number,
                            f"torn line {shown(torn)}: its end never came (the MCS stopped "
                            f"mid-line?) and seq {tail.group(1)} was written after it")] + rest
    if not name:
        return [Command(seq, "", (), number, "no command after the seq")]
    return [Command(seq, name if len(name) <= 16 else "?", (), number,
                    f"unknown command {shown(words[1])} (known: {', '.join(COMMAND_NAMES)})")]


class CommandFeed:
    """commands.txt read where it grew since the last read (see the module's docstring)."""

    def __init__(self, path, log, report):
        self.path = Path(path)
        self.log = log  # lines that cannot be read
        self.report = report  # the file that cannot be read
        self._identity = None  # (st_dev, st_ino) of the file being followed
        self._signature = None  # what os.stat said at the last read: unchanged means no read
        self._offset = 0
        self._partial = b""
        self._line = 0  # lines (LF) complete so far
        self._skipping = False  # inside a line longer than MAX_LINE
        self._fault = None

    def read(self):
        """(commands, restarted): the complete lines added since the last read; ``restarted``
        when the file was read again from its start (new, replaced or truncated)."""
        try:
            st = os.stat(self.path, follow_symlinks=False)
        except FileNotFoundError:
            self._identity = self._signature = None
            return [], False
        except OSError as exc:
            self._report(f"cannot read: {_reason(exc)}")
            return [], False
        signature = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_mode)
        if signature == self._signature:
            return [], False  # the idle poll: one stat
        restarted = False
        if (st.st_dev, st.st_ino) != self._identity or st.st_size < self._offset:
            self._identity = (st.st_dev, st.st_ino)
            self._offset, self._partial, self._line, self._skipping = 0, b"", 0, False
            restarted = True
        try:
            fd = open_regular(self.path)
        except OSError as exc:
            self._report(f"cannot read: {_reason(exc)}")
            self._signature = signature  # reported once; tried again when the file changes
            return [], restarted
        try:
            if os.fstat(fd).st_ino != st.st_ino:
                return [], restarted  # replaced between stat and open: read at the next poll
            os.lseek(fd, self._offset, os.SEEK_SET)
            data = os.read(fd, MAX_READ)
        except OSError as exc:
            self._report(f"cannot read: {_reason(exc)}")
            return [], restarted
        finally:
            os.close(fd)
        self._fault = None
        if self._offset + len(data) >= st.st_size:
            self._signature = signature  # all read: the next poll with the same stat is idle
        self._offset += len(data)
        return self._lines(data), restarted

    def _report(self, message):
        if message != self._fault:
            self._fault = message
            self.report(f"{self.path}: {message}")

    def _lines(self, data):
        commands = []
        pieces = (self._partial + data).split(b"\n")
        self._partial = pieces.pop()
        for piece in pieces:
            self._line += 1
            if self._skipping:
                self._skipping = False
                continue
            if len(piece) > MAX_LINE:
                self.log(f"{self.path}:{self._line}: longer than {MAX_LINE} bytes: ignored")
                continue
            text = piece.decode("utf-8", errors="replace")
            if self._line == 1:
                text = text.lstrip("\ufeff")
            for part in text.split("\r"):  # CRLF, and a CR alone, end a line
                commands += parse_command_line(part, self._line)
        if len(self._partial) > MAX_LINE:
            self._line += 1
            self.log(f"{self.path}:{self._line}: longer than {MAX_LINE} bytes: ignored")
            self._partial, self._skipping = b"", True
        return commands


class McsLink:
    """One MCS folder. ``scan(command, should_stop)`` carries out SCF/SCS and returns a core
    ScanResult (or a ``Scanned``); it raises InputError for bad input and must call
    ``should_stop()`` now and then
    (which raises ScanStopped when a STOP has arrived). ``log`` gets one line per answer and per
    skipped line; ``report`` one line per fault of the folder (default: ``log``). Call
    ``close()`` (or use it as a context manager) to give the folder back."""

    def __init__(self, folder, scan, log=None, report=None):
        self.folder = Path(folder)
        self.scan = scan
        self.log = log or (lambda text: print(text, file=sys.stderr))
        self.report = report or self.log
        self._lock = None
        self._folder_id = None  # (st_dev, st_ino) of the folder when its lock was taken
        self._faults = set()
        self._take_lock()
        self._running = False  # a scan is being carried out (its command is the queue's first)
        self._epoch = 0  # counts the resets: an answer carried out before one is dropped
        self._start_over()
        self._retry_at = 0.0
        self._answers_since_prune = 0
        self._catch_up_history()
        self._prune_history()

    def _start_over(self):
        """What has been done, read from the folder (at the start, after a reset, and after
        the lock was taken again in a folder that changed meanwhile)."""
        self._remove_leftovers()
        self._done = answered_seq(self.folder)
        self._last_read = self._done
        self._feed = CommandFeed(self.folder / COMMANDS, self.log, self.report)
        self._queue = collections.deque()
        self._first_read = True
        self._unwritten = []  # answers carried out but not yet in results.txt

    # --- the folder's lock --------------------------------------------------------------

    def _take_lock(self):
        """Lock the folder (``self._lock``), or leave ``self._lock`` None when it cannot be
        locked (a read-only folder without a lock file). FolderBusy when another link holds
        it."""
        path = self.folder / LOCK
        for _ in range(10):
            fd = self._lock_file(path)
            if fd is None:
                return
            try:
                same = _same_file(os.fstat(fd), os.stat(path, follow_symlinks=False))
            except OSError:
                same = False
            if same:
                break
            # Deleted or replaced between open and flock (a link that just let go of a lock
            # it had lost, a user): that file locks nothing; lock the one there now.
            os.close(fd)
        else:
            raise FolderBusy(self.folder, None, f"the lock file {LOCK} keeps being replaced: "
                                                "the folder cannot be locked")
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
        except OSError:
            pass  # read-only: the lock holds all the same
        self._lock = fd
        try:
            self._folder_id = _identity(os.stat(self.folder))
        except OSError:
            self._folder_id = None

    def _lock_file(self, path):
        """An open descriptor of the lock file, flocked; None when there is none to lock."""
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            if exc.errno == errno.ELOOP:  # planted to keep the link from locking: refused
                raise InputError(path, None, "a symbolic link: the folder cannot be locked; "
                                             "remove it") from None
            try:  # a read-only folder: the lock file may still be there to read-lock
                fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
            except OSError:
                self._fault(f"{path}: cannot lock the folder ({_reason(exc)}); nothing is "
                            "carried out until it can be locked (tried again every "
                            f"{RETRY_SECONDS:g} s)")
                return None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = ""
            # The holder writes its pid just after taking the lock: a link started at the same
            # moment may look in between, so it looks again for a little while.
            for _ in range(50):
                try:
                    holder = os.pread(fd, 32, 0).decode("ascii", errors="replace").strip()
                except OSError:
                    break
                if holder:
                    break
                time.sleep(0.01)
            os.close(fd)
            raise FolderBusy(self.folder, None, "another WaferScan link is watching this folder"
                             + (f" (process {holder})" if holder.isdigit() else "")
                             + f": one folder, one link (lock {LOCK})") from None
        return fd

    def _lock_held(self):
        """True while the lock file at the folder's path is still the one this link locked:
        not deleted, not replaced, and the folder not removed and recreated."""
        if self._lock is None:
            return False
        try:
            return _same_file(os.fstat(self._lock),
                              os.stat(self.folder / LOCK, follow_symlinks=False))
        except OSError:
            return False

    def _ensure_lock(self):
        """True when this link holds the folder's lock, taken again if it was lost and is
        free; False when the folder cannot be locked (yet). LockLost when another link holds
        it now: this link must not answer again. Called before anything is carried out and
        before every answer is written."""
        if self._lock_held():
            return True
        had = self._lock is not None
        if not had and time.monotonic() < self._retry_at:
            return False
        if had:
            self.close()  # a lock on a file no longer the folder's locks nothing
        before = self._folder_id
        try:
            self._take_lock()
        except InputError as exc:
            holder = re.search(r"\(process [0-9]+\)", str(exc))
            raise LockLost(f"{self.folder}: lost the folder's lock to another WaferScan link"
                           + (f" {holder.group(0)}" if holder else "")
                           + ": this link stops answering") from None
        if self._lock is None:
            self._retry_at = time.monotonic() + RETRY_SECONDS
            return False
        waited = any(f.startswith(str(self.folder / LOCK)) for f in self._faults)
        self._faults = {f for f in self._faults if not f.startswith(str(self.folder / LOCK))}
        if waited:
            self.report(f"{self.folder / LOCK}: the folder is locked now: commands are carried "
                        "out")
        if had:
            self.report(f"{self.folder / LOCK}: removed or replaced while this link held it: "
                        "taken again")
        if not had or before != self._folder_id or answered_seq(self.folder) != self._done:
            # Locked for the first time, or the folder is not the one it was: what has been
            # done is the folder's to say; anything carried out meanwhile is dropped.
            if had:
                self.report(f"{self.folder}: not the folder it was (removed and recreated, or "
                            "reset): commands are read again from its start")
            self._epoch += 1
            running = self._queue[0] if self._running and self._queue else None
            self._start_over()
            if running is not None:
                self._queue.append(running)  # still being carried out: its answer is dropped
        return True

    def close(self):
        """Give the folder back (release its lock)."""
        fd, self._lock = self._lock, None  # never closed twice, even if interrupted here
        if fd is not None:
            os.close(fd)  # closing the descriptor releases the flock

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def _remove_leftovers(self):
        """Temporary files of a writer killed mid-write (``.results.txt.*.tmp``, and the
        ``.results-*.tmp`` of earlier versions in history/): the real files were never touched
        by them, so they can go. Only under the lock: they are never another live link's."""
        if self._lock is None:
            return
        for folder in (self.folder, self.folder / HISTORY):
            try:
                entries = list(folder.glob(".*.tmp")) if folder.is_dir() else []
            except OSError:
                entries = []
            for entry in entries:
                if entry.name.startswith((f".{RESULTS}.", ".results-")):
                    try:
                        entry.unlink()
                    except OSError:
                        pass

    # --- reading commands ---------------------------------------------------------------

    def _read_commands(self):
        """Queue the commands added to commands.txt; log the lines that cannot be answered."""
        commands, restarted = self._feed.read()
        first, self._first_read = self._first_read, False
        if restarted:
            # The file read again is the truth: drop what was queued from the old one, but not
            # the command being carried out.
            running = self._queue[0] if self._running and self._queue else None
            self._queue = collections.deque([running] if running else [])
            self._last_read = max((s for s in (self._done, running and running.seq)
                                   if s is not None), default=None)
            if not first and self._done is not None:
                now = answered_seq(self.folder)
                if now is None or now < self._done:
                    # The reset: results.txt and history/ cleared, then commands.txt written
                    # again from its start. Seqs count from the start again; an answer carried
                    # out before (the scan running now) is dropped.
                    self._epoch += 1
                    self._unwritten = []
                    self._done = self._last_read = now
                    self.log(f"{self._feed.path}: read again from its start with {RESULTS} and "
                             f"{HISTORY}/ cleared: the folder was reset, seqs count from the "
                             "start again")
        taken = 0
        for command in commands:
            if command.seq is None:
                self.log(f"{self._feed.path}:{command.line}: ignored: {command.problem}")
                continue
            if self._last_read is not None and command.seq <= self._last_read:
                if restarted and self._done is not None and command.seq <= self._done:
                    taken += 1  # history of a file read again from its start
                else:
                    self.log(f"{self._feed.path}:{command.line}: ignored: seq {command.seq} is "
                             f"not above seq {self._last_read}, already read (a seq is "
                             "answered once)")
                continue
            self._last_read = command.seq
            self._queue.append(command)
        if restarted and taken and not first:
            self.log(f"{self._feed.path}: read again from its start (replaced or truncated): "
                     f"{taken} command(s) at or below the last answered seq {self._done} taken "
                     "as answered")

    def pending(self):
        """Commands not answered yet, in order."""
        self._read_commands()
        return list(self._queue)

    # --- carrying out -------------------------------------------------------------------

    def poll(self, stop=None):
        """Carry out every pending command; returns the answers given (written to
        results.txt). After a fault of the folder, nothing new is carried out until the
        answers already carried out are written. ``stop()``, when given, is asked before each
        command: once it is true, the commands still pending wait (for the next poll, or the
        next link)."""
        answers = []
        if not self._ensure_lock():  # never carried out without the folder's lock
            return answers
        if self._unwritten and not self._flush_unwritten(answers):
            return answers
        self._read_commands()
        while self._queue:
            if stop is not None and stop():
                break
            command = self._queue[0]
            if self._done is not None and command.seq <= self._done:
                self._queue.popleft()  # answered meanwhile (a STOP answered during a scan)
                continue
            epoch = self._epoch
            carried = self._carry_out(command)
            self._queue.popleft()
            if epoch != self._epoch:
                self.log(f"seq {command.seq} {command.name}: not answered: the folder was reset "
                         "while it was carried out")
                continue
            self._unwritten = carried
            if not self._flush_unwritten(answers):
                break
        return answers

    @property
    def locked(self):
        """True while this link holds the folder's lock (it answers only then)."""
        return self._lock_held()

    @property
    def unanswered(self):
        """Seqs carried out whose answers could not be written yet (a fault of the folder)."""
        return [seq for seq, _, _, _ in self._unwritten]

    def _flush_unwritten(self, answers):
        """Write the answers carried out but not written; False when the folder still fails."""
        if time.monotonic() < self._retry_at:
            return False
        while self._unwritten:
            # Just before writing: the lock still this link's, the folder not reset meanwhile
            # (either drops these answers).
            if not self._ensure_lock():
                return False
            self._read_commands()
            if not self._unwritten:
                break
            seq, name, text, answer = self._unwritten[0]
            try:
                self._write(seq, text)
            except OSError as exc:
                fault = f"cannot write the answer to seq {seq}: {_reason(exc)}"
                try:  # a short error answer may still fit where the full one did not
                    self._write(seq, format_results(seq, name, error=fault))
                except OSError:
                    self._fault(f"{self.folder / RESULTS}: {fault}; seq {seq} stays "
                                f"unanswered and is written again in {RETRY_SECONDS:g} s")
                    self._retry_at = time.monotonic() + RETRY_SECONDS
                    return False
                self._fault(f"{self.folder / RESULTS}: {fault}; answered status = error")
                answer = Answer(seq, name, "error", fault)
            self._unwritten.pop(0)
            self._cleared(str(self.folder / RESULTS))
            self._log_answer(answer)
            answers.append(answer)
        return True

    def _fault(self, message):
        """Report a fault of the folder once, until it is cleared (the write worked again)."""
        if message not in self._faults:
            self._faults.add(message)
            self.report(message)

    def _cleared(self, prefix):
        self._faults = {f for f in self._faults if not f.startswith(prefix)}

    def _carry_out(self, command):
        """The command's answers as (seq, name, results text, Answer), in seq order."""
        if command.problem:
            return [self._answer(command.seq, command.name or "?", error=command.problem)]
        if command.name == "STOP":
            return [self._answer(command.seq, "STOP", message="no scan running")]

        def should_stop():
            # Only the very next command may stop this one: answers stay in seq order, so no
            # command queued in between is ever taken for done.
            self._read_commands()
            following = self._queue[1] if len(self._queue) > 1 else None
            if following is not None and following.name == "STOP" and not following.problem:
                raise ScanStopped(following.seq)

        self._running = True
        try:
            result = self.scan(command, should_stop)
        except ScanStopped as stop:
            return [self._answer(command.seq, command.name, error=str(stop)),
                    self._answer(stop.seq, "STOP", message=f"stopped the scan of seq {command.seq}")]
        except InputError as exc:
            return [self._answer(command.seq, command.name, error=str(exc))]
        except CalibrationError as exc:  # SPEC §11: CAL's failures, in their own words
            return [self._answer(command.seq, command.name, error=str(exc))]
        except Exception as exc:  # a fault of ours must not stop the link: answered, reported
            self.report(f"seq {command.seq}: internal error\n{traceback.format_exc().rstrip()}")
            return [self._answer(command.seq, command.name, error=f"internal error: "
                                 f"{type(exc).__name__}: {shown(exc)}")]
        finally:
            self._running = False
        if isinstance(result, Scanned):
            return [self._answer(command.seq, command.name, result=result.result,
                                 message=result.message, recipe=result.recipe)]
        return [self._answer(command.seq, command.name, result=result)]

    def _answer(self, seq, name, result=None, error=None, message="", recipe=None):
        if result is not None and not error:
            error = refusal(result)  # SPEC §15: a contact; the answer and the log agree
        text = format_results(seq, name, result=result, error=error, message=message,
                              recipe=recipe)
        answer = Answer(seq, name, "error" if error else "ok", error or message,
                        result.code if result is not None and not error else "")
        return seq, name, text, answer

    def _log_answer(self, answer):
        self.log(f"seq {answer.seq} {answer.command}: {answer.status}"
                 + (f" {answer.code}" if answer.code else "")
                 + (f" ({answer.message})" if answer.message else ""))

    # --- writing answers ----------------------------------------------------------------

    def _write(self, seq, text):
        """results.txt replaced by ``text`` atomically and durably (file and folder flushed);
        then the history's link to it. Raises OSError when results.txt was not replaced."""
        target = self.folder / RESULTS
        # the folder's flush: below; leftovers are removed once, at the start, under the lock
        atomic_write_text(target, text, sync_folder=False, remove_stale=False)
        self._done = seq
        try:
            dir_fd = os.open(self.folder, os.O_RDONLY | os.O_DIRECTORY)
            try:
                os.fsync(dir_fd)
            finally:
                os.close(dir_fd)
        except OSError as exc:
            self._fault(f"{self.folder}: cannot flush the folder to disk: {_reason(exc)}")
        self._keep_in_history(seq, target, text)

    def _keep_in_history(self, seq, target, text):
        """history/results-<seq>.txt: a hard link to the results.txt just written (no second
        write, no fsync: results.txt is the durable record), a copy where links are not
        possible. A fault here is reported; the answer stands."""
        history = self.folder / HISTORY
        name = history / f"results-{seq:08d}.txt"
        try:
            try:
                os.mkdir(history)
            except FileExistsError:
                if not stat.S_ISDIR(os.lstat(history).st_mode):
                    raise OSError(errno.ENOTDIR, "not a folder (a file or a symbolic link)")
            try:
                os.unlink(name)
            except FileNotFoundError:
                pass
            try:
                os.link(target, name)
            except OSError as exc:
                if exc.errno not in (errno.EPERM, errno.EXDEV, errno.EOPNOTSUPP, errno.EMLINK):
                    raise
                with open(name, "x", encoding="utf-8", newline="\n") as handle:
                    handle.write(text)
        except OSError as exc:
            self._fault(f"{history}: cannot keep answers (from seq {seq} on): {_reason(exc)}"
                        if not any(f.startswith(str(history)) for f in self._faults) else
                        next(f for f in self._faults if f.startswith(str(history))))
            return
        self._cleared(str(history))
        self._answers_since_prune += 1
        if self._answers_since_prune >= max(1, HISTORY_KEEP // 10):
            self._prune_history()

    def _catch_up_history(self):
        """A link killed between renaming results.txt and linking it into the history: the
        history gets that answer now, so it holds every answer results.txt ever gave."""
        if self._lock is None or self._done is None:
            return
        name = self.folder / HISTORY / f"results-{self._done:08d}.txt"
        target = self.folder / RESULTS
        try:
            if os.path.lexists(name) or not stat.S_ISREG(os.lstat(target).st_mode):
                return
            text = read_regular_text(target, 64 << 20)
        except (OSError, InputError):
            return
        if _SEQ.search(text[:4096]) and int(_SEQ.search(text[:4096]).group(1)) == self._done:
            self._keep_in_history(self._done, target, text)

    def _prune_history(self):
        """Keep the newest HISTORY_KEEP answers in history/ (listed every HISTORY_KEEP / 10
        answers, so the cost per answer stays flat)."""
        self._answers_since_prune = 0
        history = self.folder / HISTORY
        if self._lock is None or history.is_symlink() or not history.is_dir():
            return
        try:
            names = os.listdir(history)
        except OSError:
            return
        seqs = sorted(int(m.group(1)) for m in map(_HISTORY_NAME.match, names) if m)
        for seq in seqs[:max(0, len(seqs) - HISTORY_KEEP)]:
            try:
                os.unlink(history / f"results-{seq:08d}.txt")
            except OSError:
                pass
