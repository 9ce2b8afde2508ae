"""The headless MCS link on a FreeCAD document: each SCF/SCS reads parameters.txt afresh and
scans the document, checking for STOP while it runs; a CAL calibrates the document's recipe
from its reference wafers (SPEC §11) under parameters.txt and answers with the check scan.

The document's layout is read once and again only after the document changed (a FreeCAD
document observer says so): reading it asks every wafer's solid for its surfaces, and FreeCAD
0.20's surface and vector-property accessors leak a little on each call (FREECAD-NOTES), so a
link that read it at every command would grow without bound.
"""

from __future__ import annotations

import os
import signal
import sys
import time
import traceback
from pathlib import Path

import FreeCAD as App

from ..core.errors import InputError
from ..core.files.folder_watch import FolderWatch
from ..core.files.mcs import COMMANDS, PARAMETERS, Parameters, parse_parameters
from ..core.files.mcs_link import (
    LockLost,
    McsLink,
    Scanned,
    StopFlag,
    read_regular_text,
    stop_on_signals,
)
from ..core.scan.clearance import SweepBlocked
from ..core.scan.engines import ENGINES
from .document_scan import scan_document
from .layout_files import setting_error
from .reader import DocumentScene, read_layout

# parameters.txt is a few hundred bytes; more is not a parameters file.
MAX_PARAMETERS_BYTES = 64 * 1024
COMMAND_MODES = {"SCF": "fast", "SCS": "slow"}


def read_link_parameters(path):
    """parameters.txt for one SCF/SCS: a regular file (no symlink, FIFO or device) of at most
    MAX_PARAMETERS_BYTES, every line ended (a last line without its newline may be cut short
    while the MCS writes it: ``z_step = 0.0`` of ``0.05``). None when there is no file."""
    path = Path(path)
    try:
        text = read_regular_text(path, MAX_PARAMETERS_BYTES)
    except FileNotFoundError:
        return None
    if text and not text.endswith("\n"):
        last = text.count("\n") + 1
        raise InputError(path, last, "the last line has no line end: it may still be being "
                                     "written; end every line with a newline")
    return parse_parameters(text, str(path))


def mode_note(parameters, command):
    """The answer's note when parameters.txt sets a ``mode`` other than the command's: the
    command wins (SCF is a fast scan, SCS a slow one), and the answer says so."""
    mode = COMMAND_MODES[command]
    if parameters is None or parameters.values.get("mode", mode) == mode:
        return ""
    return (f"{parameters.source}:{parameters.lines['mode']}: mode = "
            f"{parameters.values['mode']} is overridden by {command} ({mode} scan)")


class DocumentLayout:
    """The document's scene and layout, read again only after the document changed. While the
    link's own scan runs, placement changes are the scan moving the scanner or the robot (and
    putting them back), not edits."""

    def __init__(self, doc):
        self.doc = doc
        self.version = 0
        self.scanning = False
        self._read = None  # (version, scene, layout)
        App.addDocumentObserver(self)

    def close(self):
        App.removeDocumentObserver(self)

    # FreeCAD's document observer slots
    def slotChangedObject(self, obj, prop):
        if not (self.scanning and prop in ("Placement", "Shape")):
            self.version += 1

    def slotCreatedObject(self, obj):
        self.version += 1

    def slotDeletedObject(self, obj):
        self.version += 1

    def slotRecomputedDocument(self, doc):
        self.version += 1

    def get(self):
        """(scene, layout), read now if the document changed since the last read."""
        if self._read is None or self._read[0] != self.version:
            version = self.version
            scene = DocumentScene.of(self.doc)
            self._read = (version, scene, read_layout(self.doc, scene))
        return self._read[1], self._read[2]


def document_scanner(doc, folder, engine="analytic"):
    """The ``scan`` function of an ``McsLink`` for a document; its ``close()`` stops following
    the document's changes."""
    folder = Path(folder)
    cache = DocumentLayout(doc)

    def scan(command, should_stop):
        should_stop()
        path = folder / PARAMETERS
        read = read_link_parameters(path)
        if command.name == "LOAD":  # SPEC §14: only a link with load ports takes carriers
            raise InputError(folder / COMMANDS, command.line, "LOAD places a carrier on a load "
                             "port of the host link: this folder is watched by a link without "
                             "one (run `waferscan serve INPUT --hsms HOST:PORT --mcs DIR`)")
        if command.name == "CAL":  # SPEC §11: the recipe from the reference wafers
            if engine not in ENGINES:  # as `waferscan calibrate --engine` offers them
                raise InputError(folder / COMMANDS, command.line, "CAL calibrates with the core "
                                 f"engines only ({', '.join(sorted(ENGINES))}), as `waferscan "
                                 f"calibrate` does; this watcher scans with the {engine} "
                                 "engine: start one with --engine analytic to calibrate")
            return _calibrated(doc, cache, read, engine, should_stop)
        note = mode_note(read, command.name)
        parameters = read or Parameters({}, {}, str(path))
        parameters = Parameters({**parameters.values, "mode": COMMAND_MODES[command.name]},
                                parameters.lines, parameters.source)
        scene, layout = cache.get()
        cache.scanning = True
        try:
            result = scan_document(doc, engine, progress=lambda done, total: should_stop(),
                                   parameters=parameters, read=(scene, layout))
        except SweepBlocked as exc:  # named by parameters.txt's line, else the layout
            raise setting_error(exc.message, doc.FileName or doc.Label, read, "scan",
                                "sweep") from None
        finally:
            cache.scanning = False
        return Scanned(result, note) if note else result

    scan.close = cache.close
    return scan


def _calibrated(doc, cache, parameters, engine, should_stop):
    """A CAL: calibrate the document's layout under parameters.txt's recipe; the answer is the
    check scan with the calibrated recipe's keys in its header (a failure raises
    CalibrationError, answered with its words)."""
    from ..core.scan.calibration import REPORTED_KEYS, recipe_values
    from .document_calibration import calibrate_document

    scene, layout = cache.get()
    cache.scanning = True
    try:
        calibration = calibrate_document(doc, parameters, engine, read=(scene, layout),
                                         progress=lambda done, total: should_stop())
    finally:
        cache.scanning = False
    values = recipe_values(calibration.values(calibration.after))  # at 1 µm, as written
    return Scanned(calibration.check, "calibrated from the reference wafers in slots 1 and "
                   f"{calibration.after.scanned_carrier.slot_count}",
                   {key: values[key] for key in REPORTED_KEYS})


LAYOUT_CHECK_SECONDS = 1.0  # how often the layout file is checked for a change
WATCHED_POLL = 1.0  # s: how often a watched folder is read when nothing woke the link


def _file_signature(path):
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


class _FailingScanner:
    """Answers every scan with the reason the layout cannot be opened (the link goes on)."""

    def __init__(self, error):
        self.error = error

    def __call__(self, command, should_stop):
        raise self.error

    def close(self):
        pass


def watch(folder, layout_path, engine="analytic", poll=0.01, once=False, stopping=None):
    """``waferscan watch``: the link on ``folder`` with the layout at ``layout_path`` (a
    scenario or a .FCStd), answers logged on stdout, faults on stderr. The layout is opened
    again when its file changes (a new one that cannot be opened answers every scan with the
    reason until it is fixed). Returns the exit status; InputError when the layout cannot be
    opened at the start or another link holds the folder. ``stopping``: a StopFlag whose
    signal handlers the caller installed (the command line, before FreeCAD loads); without
    one, SIGINT and SIGTERM stop the watch while it runs (FreeCAD quirk: a KeyboardInterrupt
    raised inside a document observer's callback is swallowed by FreeCAD, so a watcher
    interrupted there would never stop)."""
    from .layout_files import open_layout

    def out(text):
        print(text, flush=True)

    def err(text):
        print(f"waferscan: {text}", file=sys.stderr, flush=True)

    signature = _file_signature(layout_path)
    doc = open_layout(layout_path)
    scanner = document_scanner(doc, folder, engine)
    try:
        link = McsLink(folder, scanner, log=out, report=err)
    except BaseException:
        scanner.close()
        App.closeDocument(doc.Name)
        raise
    handled = {}
    if stopping is None:
        stopping = StopFlag()
        handled = stop_on_signals(stopping)
    woken = None
    try:
        if once:
            link.poll(stop=stopping.is_set)
            # the fault (unwritten answers, a folder that cannot be locked) is on stderr
            return 1 if link.unanswered or not link.locked else 0
        woken = FolderWatch(folder)
        how = ("woken by each change (inotify)" if woken.active else
               f"read every {poll:g} s ({woken.reason})")
        out(f"watching {Path(folder) / COMMANDS} (layout {layout_path}), {how}; Ctrl-C to stop")
        checked = time.monotonic()
        faults = set()
        while not stopping.is_set():
            try:
                link.poll(stop=stopping.is_set)  # a stop: after the command in hand
            except LockLost:
                raise
            except Exception as exc:  # a fault of ours: said once, and the watching goes on
                if repr(exc) not in faults:
                    faults.add(repr(exc))
                    err(f"internal error, still watching\n{traceback.format_exc().rstrip()}")
                stopping.wait(max(poll, 1.0))
            # A change wakes the link at once; it reads the folder at least once a
            # WATCHED_POLL all the same. Without a watch (or while a removed folder is away):
            # every ``poll`` seconds, as before.
            woken.wait(WATCHED_POLL if woken.active else poll, stopping)
            if stopping.is_set():
                break
            if time.monotonic() - checked >= LAYOUT_CHECK_SECONDS:
                checked = time.monotonic()
                now = _file_signature(layout_path)
                if now != signature:
                    signature = now
                    scanner.close()
                    if doc is not None:
                        App.closeDocument(doc.Name)
                        doc = None
                    try:
                        doc = open_layout(layout_path)
                        scanner = document_scanner(doc, folder, engine)
                        out(f"{layout_path}: changed, opened again")
                    except Exception as exc:  # noqa: BLE001 (any reason: answered, not fatal)
                        if not isinstance(exc, InputError):
                            exc = InputError(layout_path, None, f"cannot open it: "
                                             f"{type(exc).__name__}: {exc}")
                        scanner = _FailingScanner(exc)
                        err(f"{exc} (each scan is answered with this until it is fixed)")
                    link.scan = scanner
        return 0
    except LockLost as exc:  # another link answers this folder now: this one must not
        err(str(exc))
        return 1
    except KeyboardInterrupt:
        return 0
    finally:
        # Everything closed while a further Ctrl-C still only sets the flag; the handlers
        # given back last.
        try:
            if woken is not None:
                woken.close()
            link.close()
            scanner.close()
            if doc is not None:
                App.closeDocument(doc.Name)
        finally:
            for number, previous in handled.items():
                signal.signal(number, previous)
