"""The MCS link as a protocol: watch commands.txt, carry out each seq exactly once, answer in
results.txt.

- What has been done is read from the folder, not kept in memory: the highest seq answered in
  results.txt or in the history folder. A restarted link carries on where the last one stopped.
- commands.txt is read afresh at every poll, by name: a file replaced by rename, or deleted and
  written again, is followed. A last line without its newline is still being written and waits.
- Every answer is first written to ``history/results-<seq>.txt``, then to results.txt, both
  atomically (temporary file, then rename): the MCS never reads half an answer, and no earlier
  answer is lost.
- A command that cannot be carried out (unknown, bad seq order, bad parameters, a scan that
  fails on bad input) is answered with ``status = error`` and the link goes on.
- STOP: a scan polls commands.txt while it runs; a STOP that is the next command aborts it. The
  scan is answered ``status = error`` ("stopped by seq N"), then the STOP ``status = ok``. A STOP
  with no scan running is answered ``ok``, "no scan running". Answers are always in seq order.
"""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path

from .errors import InputError
from .mcs import COMMANDS, RESULTS, atomic_write_text, format_results, parse_commands

HISTORY = "history"
_SEQ = re.compile(r"^seq = (\d+)\s*$", re.MULTILINE)
_HISTORY_NAME = re.compile(r"^results-(\d+)\.txt$")


class ScanStopped(Exception):
    """Raised inside a scan when a STOP arrives; carries the STOP's seq."""

    def __init__(self, seq):
        super().__init__(f"stopped by seq {seq}")
        self.seq = seq


@dataclass(frozen=True)
class Answer:
    seq: int
    command: str
    status: str
    message: str
    code: str = ""


def answered_seq(folder):
    """The highest seq answered so far in the folder, or None: results.txt says it; the history
    folder is read only when results.txt is missing or unreadable (listing it at every poll
    would cost more with every answer kept)."""
    folder = Path(folder)
    try:
        match = _SEQ.search((folder / RESULTS).read_text(encoding="utf-8-sig"))
        if match:
            return int(match.group(1))
    except (OSError, UnicodeDecodeError):
        pass
    seqs = []
    history = folder / HISTORY
    if history.is_dir():
        for name in os.listdir(history):
            match = _HISTORY_NAME.match(name)
            if match:
                seqs.append(int(match.group(1)))
    return max(seqs, default=None)


def read_commands(folder):
    """The complete commands of commands.txt (empty when the file is missing or unreadable)."""
    try:
        text = (Path(folder) / COMMANDS).read_bytes().decode("utf-8-sig", errors="replace")
    except OSError:
        return []
    return parse_commands(text)


class McsLink:
    """One MCS folder. ``scan(command, should_stop)`` carries out SCF/SCS and returns a core
    ScanResult; it raises InputError for bad input and must call ``should_stop()`` now and then
    (which raises ScanStopped when a STOP has arrived)."""

    def __init__(self, folder, scan, log=None):
        self.folder = Path(folder)
        self.scan = scan
        self.log = log or (lambda text: print(text, file=sys.stderr))
        self._warned = set()
        self._remove_leftovers()

    def _remove_leftovers(self):
        """Temporary files of a writer killed mid-write (atomic_write_text's ``.NAME.*.tmp``):
        the real files were never touched by them, so they can go."""
        for folder in (self.folder, self.folder / HISTORY):
            if folder.is_dir():
                for entry in folder.glob(".*.tmp"):
                    if entry.name.startswith((f".{RESULTS}.", ".results-")):
                        entry.unlink(missing_ok=True)

    def pending(self):
        """Commands not answered yet, in order."""
        done = answered_seq(self.folder)
        waiting = []
        for command in read_commands(self.folder):
            if command.seq is None:
                if command.line not in self._warned:
                    self._warned.add(command.line)
                    self.log(f"{self.folder / COMMANDS}:{command.line}: ignored: {command.problem}")
                continue
            if done is None or command.seq > done:
                waiting.append(command)
        return waiting

    def poll(self):
        """Carry out every pending command; returns the answers given."""
        answers = []
        for command in self.pending():
            done = answered_seq(self.folder)
            if done is not None and command.seq <= done:
                continue  # answered meanwhile (a STOP answered during a scan)
            answers += self._carry_out(command)
        return answers

    def _carry_out(self, command):
        if command.problem:
            return [self._answer(command.seq, command.name or "?", error=command.problem)]
        if command.name == "STOP":
            return [self._answer(command.seq, "STOP", message="no scan running")]

        def should_stop():
            # Only the very next command may stop this one: answers stay in seq order, so no
            # command queued in between is ever taken for done.
            following = [c for c in read_commands(self.folder)
                         if c.seq is not None and c.seq > command.seq]
            if following and following[0].name == "STOP" and following[0].problem is None:
                raise ScanStopped(following[0].seq)

        try:
            result = self.scan(command, should_stop)
        except ScanStopped as stop:
            return [self._answer(command.seq, command.name, error=str(stop)),
                    self._answer(stop.seq, "STOP", message=f"stopped the scan of seq {command.seq}")]
        except InputError as exc:
            return [self._answer(command.seq, command.name, error=str(exc))]
        return [self._answer(command.seq, command.name, result=result)]

    def _answer(self, seq, name, result=None, error=None, message=""):
        text = format_results(seq, name, result=result, error=error, message=message)
        history = self.folder / HISTORY
        history.mkdir(exist_ok=True)
        atomic_write_text(history / f"results-{seq:08d}.txt", text)
        atomic_write_text(self.folder / RESULTS, text)
        answer = Answer(seq, name, "error" if error else "ok", error or message,
                        result.code if result is not None and not error else "")
        self.log(f"seq {seq} {name}: {answer.status}"
                 + (f" {answer.code}" if answer.code else "")
                 + (f" ({answer.message})" if answer.message else ""))
        return answer
