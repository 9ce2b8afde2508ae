"""The "Tolerance study…" dialog (SPEC §12): the settings of ``waferscan sweep``, a progress bar
and, when the sweep is done, its summary and plots.

The sweep runs as ``python -m waferscan.cli sweep`` of the project's venv in a QProcess, not in
FreeCAD's own process: Dask's worker processes start the running interpreter, which inside
FreeCAD is FreeCAD itself; and the GUI stays responsive. The dialog reads the command's progress
lines (``sweep: 3/8 partitions``) from its stderr, then summary.json and the PNGs it wrote.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import tempfile
from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..addon import ADDON_ROOT, venv_dir

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
        self.out_edit = QtGui.QLineEdit(out or os.path.join(self._scratch, "out"))
        form.addRow("Output folder", self.out_edit)
        self.run_button = QtGui.QPushButton("Run")
        self.run_button.clicked.connect(self.start)
        self.progress = QtGui.QProgressBar()
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.status = QtGui.QLabel("")
        self.status.setWordWrap(True)
        self.text = QtGui.QPlainTextEdit()
        self.text.setReadOnly(True)
        self.text.setFont(QtGui.QFont("monospace"))
        self.confusion_label = QtGui.QLabel()
        self.margins_label = QtGui.QLabel()
        plots = QtGui.QHBoxLayout()
        plots.addWidget(self.confusion_label)
        plots.addWidget(self.margins_label)
        layout = QtGui.QVBoxLayout(self)
        layout.addLayout(form)
        row = QtGui.QHBoxLayout()
        row.addWidget(self.run_button)
        row.addWidget(self.progress, 1)
        layout.addLayout(row)
        layout.addWidget(self.status)
        layout.addWidget(self.text, 1)
        layout.addLayout(plots)
        self.resize(1000, 800)

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
                "--out", self.out_edit.text().strip()]

    def start(self):
        """Run the sweep in a QProcess; the progress bar follows its progress lines."""
        if self.process is not None:
            return
        try:
            args = self.arguments()
        except ValueError as exc:
            self._fail(str(exc))
            return
        self.last_arguments = args
        self.state = "running"
        self.summary = None
        self._stderr = b""
        self.text.clear()
        self.confusion_label.clear()
        self.margins_label.clear()
        self.progress.setRange(0, 0)  # busy until the first partition is in
        self.status.setText("starting the Dask workers…")
        self.run_button.setEnabled(False)
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
        if code != 0:
            lines = self._stderr.decode("utf-8", "replace").strip().splitlines()
            errors = [line for line in lines if "error" in line.lower()]
            self._fail((errors or lines or [f"the sweep stopped with status {code}"])[-1])
            return
        out = Path(self.out_edit.text().strip())
        self.summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
        from ..sweep import format_summary

        self.text.setPlainText(format_summary(self.summary))
        for label, name in ((self.confusion_label, "confusion.png"),
                            (self.margins_label, "margins.png")):
            pixmap = QtGui.QPixmap(str(out / name))
            label.setPixmap(pixmap.scaledToWidth(480, QtCore.Qt.SmoothTransformation))
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
        super().closeEvent(event)
