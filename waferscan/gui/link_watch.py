"""The MCS link driven from the GUI (``LinkWatch``): the headless link
(``core.files.mcs_link.McsLink`` with ``cad.mcs_watch.document_scanner``), so results.txt is
written exactly as ``waferscan watch`` writes it, and what says when to poll it: a file-system
event and, as a fallback for file systems that send none (network shares), a timer. What the
user sees of it is the MCS link panel's (``mcs_panel``)."""

from __future__ import annotations

from pathlib import Path

import FreeCAD as App
from PySide import QtCore

from ..cad.mcs_watch import document_scanner
from ..core.errors import InputError
from ..core.files.mcs import COMMANDS, refusal
from ..core.files.mcs_link import McsLink

__all__ = ["LinkWatch"]

KEPT_SCANS = 16  # results carried out whose answers are not written yet, kept at most


class LinkWatch:
    """The link on ``folder`` scanning ``doc``, and ``poll_now`` called when it is time to poll:
    on a file-system event in the folder (``events``) and every ``poll_ms`` ms (0: no timer).
    ``how`` says which, in words. Raises InputError when another link (``waferscan watch``)
    holds the folder. ``close()`` stops it all and gives the folder's lock back.
    ``before_scan()``, when given, is called before each command that reads the document (what
    moves the document's objects, a slow scan's jabs and sweeps shown, is ended there)."""

    def __init__(self, doc, folder, poll_now, events=True, poll_ms=0, before_scan=None):
        self.folder = Path(folder)
        self.before_scan = before_scan
        self.watcher = None
        self.timer = None
        # The link's document scanner: it follows the document's changes. Used as `waferscan
        # watch` uses it: every answer, failures included, is then written as the watcher
        # writes it (issue 27: a CAL that failed was answered "cannot scan the document:
        # CalibrationError: ..." here). Only what it returns is kept on the way (``scanned``),
        # for the panel to show; what it raises passes untouched.
        self.scans = {}  # seq -> the ScanResult its answer reports, until the panel takes it
        self.scanner = self._keeping(document_scanner(doc, folder))
        try:
            self.link = McsLink(folder, self.scanner,
                                log=lambda text: App.Console.PrintLog(f"WaferScan MCS: {text}\n"))
        except InputError:
            self.scanner.close()
            raise
        self.how = []
        if events:
            self.watcher = QtCore.QFileSystemWatcher()
            self.watcher.directoryChanged.connect(poll_now)
            self.watcher.fileChanged.connect(poll_now)
            self.watcher.addPath(str(folder))
            self.watch_commands_file()
            self.how.append("file-system events")
        if poll_ms:
            self.timer = QtCore.QTimer()
            self.timer.timeout.connect(poll_now)
            self.timer.start(int(poll_ms))
            self.how.append(f"polling every {poll_ms / 1000:g} s")

    def _keeping(self, scanner):
        """``scanner`` with each result it returns kept in ``scans`` under its command's seq."""

        def scan(command, should_stop):
            if self.before_scan is not None:
                self.before_scan()
            out = scanner(command, should_stop)
            if len(self.scans) >= KEPT_SCANS:  # answers never written (a folder's fault)
                self.scans.pop(min(self.scans))
            self.scans[command.seq] = getattr(out, "result", out)
            return out

        scan.close = scanner.close
        return scan

    def scanned(self, answer):
        """The ScanResult an ``ok`` answer reports (an SCF's or SCS's scan, a CAL's check
        scan), or one refused for its contacts (SPEC §15: the MCS is told not to run it; the
        engineer is shown where the fork meets a wafer), or None; taken: asked once."""
        result = self.scans.pop(answer.seq, None)
        if result is None:
            return None
        return result if answer.status == "ok" or refusal(result) else None

    def poll(self):
        """Carry out what commands.txt holds that results.txt has not answered; returns the
        answers (LockLost when another link answers the folder now)."""
        return self.link.poll()

    def watch_commands_file(self):
        """Watch commands.txt again: a file replaced by rename or deleted drops out of the
        watcher."""
        path = str(self.folder / COMMANDS)
        if self.watcher is not None and path not in self.watcher.files() and \
                Path(path).exists():
            self.watcher.addPath(path)

    def close(self):
        """No more polling; the folder's lock given back, the document no longer followed."""
        if self.timer is not None:
            self.timer.stop()
        if self.watcher is not None:
            self.watcher.deleteLater()
            self.watcher = None
        self.link.close()
        self.scanner.close()
