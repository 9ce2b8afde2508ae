"""The "Tolerance study…" dialog (SPEC §12): the settings of ``waferscan sweep``, a progress bar
and, when the sweep is done, its summary and plots.

The sweep runs as ``python -m waferscan.cli sweep`` of the project's venv in a QProcess, not in
FreeCAD's own process: Dask's worker processes start the running interpreter, which inside
FreeCAD is FreeCAD itself; and the GUI stays responsive. The dialog reads the command's progress
lines (``sweep: 3/8 partitions``) from its stderr, then summary.json and the PNGs it wrote.
Stop interrupts it as Ctrl-C would (nothing is written to the output folder then).

Run and Stop are recorded as lines of Python (``run_tolerance_study(...)``,
``stop_tolerance_study()``), as FreeCAD's own commands are: the console shows them and a macro
replays them. The dialog fits the screen it opens on, and its plots are enlarged by a click.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import sys
import tempfile
from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..addon import ADDON_ROOT, venv_dir
from .qt import fitted_size
from .session import record, session

PROGRESS = re.compile(r"sweep: (\d+)/(\d+) partitions")
DEFAULT_TOLERANCES = Path(ADDON_ROOT) / "resources" / "examples" / "fab_tolerances.toml"


def sweep_python():
    """The Python that runs the sweep: the project's venv (it has Dask); else a python3 on the
    PATH (which may lack Dask: the command then says so)."""
    candidate = Path(venv_dir()) / "bin" / "python"
    if candidate.exists():
        return str(candidate)
    return shutil.which("python3") or sys.executable


def document_input(doc, folder):
    """A file the sweep can read for the document: its own .FCStd when saved and unchanged,
    else a copy saved into ``folder``."""
    if doc.FileName and not doc.isTouched() and Path(doc.FileName).exists():
        return doc.FileName
    path = Path(folder) / f"{doc.Name}.FCStd"
    doc.saveCopy(str(path))
    return str(path)


class ToleranceStudyDialog(QtGui.QDialog):
    """Settings (layout, tolerance file, N, seed, workers, output folder), Run, a progress bar,
    and the result: the text summary and the confusion and margin plots."""

    def __init__(self, input_path="", tolerances=None, n=10_000, seed=0, workers=None,
                 out=None, parent=None):
        super().__init__(parent or Gui.getMainWindow())
        self.setWindowTitle("WaferScan — Tolerance study")
        self.process = None
        self.state = "idle"  # running, done, failed
        self.summary = None
        self.errors = []
        self.last_arguments = None  # the command line of the last sweep started
        self._stderr = b""
        self._stopping = False
        self._scratch = tempfile.mkdtemp(prefix="waferscan-sweep-")
        form = QtGui.QFormLayout()
        self.input_edit = self._file_row(form, "Layout", input_path,
                                         "Scenario or layout (*.toml *.FCStd)",
                                         "(the active document)")
        self.tolerance_edit = self._file_row(form, "Tolerances",
                                             str(tolerances or DEFAULT_TOLERANCES),
                                             "Tolerance file (*.toml)")
        self.n_spin = QtGui.QSpinBox()
        self.n_spin.setRange(1, 100_000_000)
        self.n_spin.setValue(n)
        self.n_spin.setGroupSeparatorShown(True)
        form.addRow("Layouts (N)", self.n_spin)
        self.seed_spin = QtGui.QSpinBox()
        self.seed_spin.setRange(0, 2_000_000_000)
        self.seed_spin.setValue(seed)
        form.addRow("Seed", self.seed_spin)
        self.workers_spin = QtGui.QSpinBox()
        self.workers_spin.setRange(0, 256)
        self.workers_spin.setValue((os.cpu_count() or 1) if workers is None else workers)
        self.workers_spin.setToolTip("Dask worker processes on this machine (0: no Dask)")
        form.addRow("Workers", self.workers_spin)
        # Empty: a temporary folder of this dialog's, not named in the recorded line (it
        # will not be there when a macro replays it).
        self.out_edit = QtGui.QLineEdit(out or "")
        self.out_edit.setPlaceholderText("(a temporary folder)")
        self.out_used = None  # where the last sweep started writes
        form.addRow("Output folder", self.out_edit)
        self.run_button = QtGui.QPushButton("Run")
        self.run_button.clicked.connect(self._record_run)
        self.stop_button = QtGui.QPushButton("Stop")
        self.stop_button.setToolTip("Interrupt the sweep, as Ctrl-C would: nothing is written")
        self.stop_button.setEnabled(False)
        self.stop_button.clicked.connect(lambda: record("stop_tolerance_study()"))
        self.progress = QtGui.QProgressBar()
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.status = QtGui.QLabel("")
        self.status.setWordWrap(True)
        self.text = QtGui.QPlainTextEdit()
        self.text.setReadOnly(True)
        self.text.setFont(QtGui.QFont("monospace"))
        self.confusion_label = PlotLabel("Confusion")
        self.margins_label = PlotLabel("Margins")
        plots = QtGui.QHBoxLayout()
        plots.addWidget(self.confusion_label)
        plots.addWidget(self.margins_label)
        layout = QtGui.QVBoxLayout(self)
        layout.addLayout(form)
        row = QtGui.QHBoxLayout()
        row.addWidget(self.run_button)
        row.addWidget(self.stop_button)
        row.addWidget(self.progress, 1)
        layout.addLayout(row)
        layout.addWidget(self.status)
        layout.addWidget(self.text, 1)
        layout.addLayout(plots, 1)
        self.resize(*fitted_size(1000, 800))

    def _file_row(self, form, label, value, pattern, placeholder=""):
        edit = QtGui.QLineEdit(value)
        edit.setPlaceholderText(placeholder)
        button = QtGui.QPushButton("…")

        def browse():
            path, _ = QtGui.QFileDialog.getOpenFileName(self, label, edit.text(), pattern)
            if path:
                edit.setText(path)

        button.clicked.connect(browse)
        row = QtGui.QHBoxLayout()
        row.addWidget(edit, 1)
        row.addWidget(button)
        form.addRow(label, row)
        return edit

    def arguments(self):
        """The command line of the sweep (after the Python): ``-m waferscan.cli sweep ...``."""
        source = self.input_edit.text().strip()
        if not source:
            doc = App.ActiveDocument
            if doc is None:
                raise ValueError("no layout: open one, or choose a scenario or layout file")
            source = document_input(doc, self._scratch)
        return ["-m", "waferscan.cli", "sweep", source, "--tolerances",
                self.tolerance_edit.text().strip(), "-n", str(self.n_spin.value()), "--seed",
                str(self.seed_spin.value()), "--workers", str(self.workers_spin.value()),
                "--out", self.out_folder()]

    def out_folder(self):
        """The output folder the user chose, or else the dialog's temporary one."""
        return self.out_edit.text().strip() or os.path.join(self._scratch, "out")

    def settings(self):
        """The fields as ``run_tolerance_study``'s keyword arguments; ``out`` only when the
        user chose a folder (none: a temporary folder, made again on replay)."""
        settings = {"input_path": self.input_edit.text().strip(),
                    "tolerances": self.tolerance_edit.text().strip(), "n": self.n_spin.value(),
                    "seed": self.seed_spin.value(), "workers": self.workers_spin.value()}
        if self.out_edit.text().strip():
            settings["out"] = self.out_edit.text().strip()
        return settings

    def _record_run(self):
        """Run, as the line a script would write (the dialog's fields as its arguments)."""
        arguments = ", ".join(f"{key}={value!r}" for key, value in self.settings().items())
        record(f"run_tolerance_study({arguments})")

    def apply_settings(self, input_path="", tolerances=None, n=None, seed=None, workers=None,
                       out=None):
        """Set the fields that are given (None leaves a field as it is)."""
        for edit, value in ((self.input_edit, input_path), (self.tolerance_edit, tolerances),
                            (self.out_edit, out)):
            if value is not None:
                edit.setText(str(value))
        for spin, value in ((self.n_spin, n), (self.seed_spin, seed),
                            (self.workers_spin, workers)):
            if value is not None:
                spin.setValue(int(value))

    def stop(self):
        """Interrupt a running sweep as Ctrl-C would; it ends as "stopped"."""
        if self.process is None:
            return
        self.status.setText("stopping the sweep…")
        self.stop_button.setEnabled(False)
        self._stopping = True
        pid = int(self.process.processId())
        try:
            if pid > 0:
                os.kill(pid, signal.SIGINT)
        except ProcessLookupError:  # it ended as Stop was clicked: _finished says how
            pass

    def start(self):
        """Run the sweep in a QProcess; the progress bar follows its progress lines."""
        if self.process is not None:
            return
        self._stopping = False
        try:
            args = self.arguments()
        except ValueError as exc:
            self._fail(str(exc))
            return
        self.last_arguments = args
        self.out_used = args[args.index("--out") + 1]
        self.state = "running"
        self.summary = None
        self._stderr = b""
        self.text.clear()
        self.confusion_label.set_plot(None)
        self.margins_label.set_plot(None)
        self.progress.setRange(0, 0)  # busy until the first partition is in
        self.status.setText("starting the Dask workers…")
        self.run_button.setEnabled(False)
        self.stop_button.setEnabled(True)
        process = QtCore.QProcess(self)
        env = QtCore.QProcessEnvironment.systemEnvironment()
        env.insert("PYTHONPATH", str(ADDON_ROOT))
        process.setProcessEnvironment(env)
        process.setWorkingDirectory(str(ADDON_ROOT))
        process.readyReadStandardError.connect(self._read_progress)
        process.finished.connect(self._finished)
        self.process = process
        process.start(sweep_python(), args)

    def _read_progress(self):
        data = bytes(self.process.readAllStandardError())
        self._stderr += data
        for match in PROGRESS.finditer(data.decode("utf-8", "replace")):
            done, total = int(match.group(1)), int(match.group(2))
            self.progress.setRange(0, total)
            self.progress.setValue(done)
            self.status.setText(f"{done} of {total} partitions done")

    def _finished(self, code, _status=None):
        self._read_progress()
        self.process = None
        self.run_button.setEnabled(True)
        self.stop_button.setEnabled(False)
        if self._stopping:
            self._stopping = False
            self.state = "stopped"
            self.progress.setRange(0, 1)
            self.progress.setValue(0)
            self.status.setText("stopped: the sweep was interrupted; nothing was written to "
                                f"{self.out_used}")
            App.Console.PrintMessage("WaferScan: tolerance study stopped\n")
            return
        if code != 0:
            lines = self._stderr.decode("utf-8", "replace").strip().splitlines()
            errors = [line for line in lines if "error" in line.lower()]
            self._fail((errors or lines or [f"the sweep stopped with status {code}"])[-1])
            return
        out = Path(self.out_used)
        self.summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
        from ..sweep import format_summary

        self.text.setPlainText(format_summary(self.summary))
        for label, name in ((self.confusion_label, "confusion.png"),
                            (self.margins_label, "margins.png")):
            label.set_plot(QtGui.QPixmap(str(out / name)))
        self.progress.setRange(0, 1)
        self.progress.setValue(1)
        self.status.setText(f"done: {self.summary['n']:,} layouts; summary.json, CSV tables "
                            f"and plots in {out}")
        self.state = "done"

    def _fail(self, message):
        self.state = "failed"
        self.errors.append(message)
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.status.setText(message)
        App.Console.PrintError(f"WaferScan: tolerance study: {message}\n")

    def closeEvent(self, event):  # noqa: N802 (Qt's name)
        if self.process is not None:
            self.process.kill()
            self.process.waitForFinished(5000)
        for label in (self.confusion_label, self.margins_label):
            label.close_window()
        super().closeEvent(event)


class PlotLabel(QtGui.QLabel):
    """A plot that scales with the dialog (keeping its proportions) and opens at full size,
    in a window of its own that can be resized or maximised, when clicked."""

    def __init__(self, title):
        super().__init__()
        self.title = title
        self.plot = None  # the PNG at its own size
        self.enlarged = None
        self.setMinimumSize(160, 100)
        self.setAlignment(QtCore.Qt.AlignCenter)
        self.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Ignored)

    def set_plot(self, pixmap):
        self.plot = None if pixmap is None or pixmap.isNull() else pixmap
        self.setCursor(QtCore.Qt.PointingHandCursor if self.plot else QtCore.Qt.ArrowCursor)
        self.setToolTip("Click to enlarge" if self.plot else "")
        self._show_scaled()

    def _show_scaled(self):
        if self.plot is None:
            self.clear()
            return
        self.setPixmap(self.plot.scaled(self.size(), QtCore.Qt.KeepAspectRatio,
                                        QtCore.Qt.SmoothTransformation))

    def resizeEvent(self, event):  # noqa: N802 (Qt's name)
        super().resizeEvent(event)
        self._show_scaled()

    def mousePressEvent(self, event):  # noqa: N802 (Qt's name)
        if self.plot is not None and event.button() == QtCore.Qt.LeftButton:
            self.enlarge()
        super().mousePressEvent(event)

    def enlarge(self):
        """The plot in a window of its own, at full size where the screen allows."""
        if self.plot is None:
            return None
        self.close_window()
        window = QtGui.QDialog(self.window())
        window.setWindowTitle(f"WaferScan — {self.title}")
        window.setSizeGripEnabled(True)
        view = PlotLabel(self.title)
        layout = QtGui.QVBoxLayout(window)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(view)
        window.resize(*fitted_size(self.plot.width(), self.plot.height()))
        view.set_plot(self.plot)
        view.setCursor(QtCore.Qt.ArrowCursor)
        view.setToolTip("")
        view.mousePressEvent = lambda event: None  # already enlarged
        window.show()
        self.enlarged = window
        return window

    def close_window(self):
        if self.enlarged is not None:
            try:
                self.enlarged.close()
            except RuntimeError:  # already deleted with its parent
                pass
            self.enlarged = None


def open_study(input_path="", **settings):
    """A new tolerance study dialog, shown (non-modal) and kept as the session's; ``settings``
    preset its fields (tolerances, n, seed, workers, out)."""
    dialog = ToleranceStudyDialog(input_path, **settings)
    dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    dialog.show()
    session.tolerance_study = dialog
    return dialog


def _open_dialog():
    """The open tolerance study dialog, or None."""
    dialog = session.tolerance_study
    try:
        return dialog if dialog is not None and dialog.isVisible() else None
    except RuntimeError:  # closed: Qt deleted it
        return None


def run_tolerance_study(input_path="", tolerances=None, n=None, seed=None, workers=None,
                        out=None):
    """Run a tolerance study as the dialog's Run button does: in the open dialog, or in one
    opened for it, with the given fields (the rest as they are or their defaults). What the
    Run button records, so a macro replays it. Returns the dialog."""
    dialog = _open_dialog() or open_study()
    dialog.apply_settings(input_path, tolerances, n, seed, workers, out)
    dialog.start()
    return dialog


def stop_tolerance_study():
    """Stop the open dialog's running sweep (what its Stop button records)."""
    dialog = _open_dialog()
    if dialog is not None:
        dialog.stop()
