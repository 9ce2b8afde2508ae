"""The workbench's commands: the paper's layout, a scenario, the animated scan, the results
table and the slot code. Results come from ``scan_document``, the function headless runs use."""

from __future__ import annotations

from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtGui

from ..addon import icon_path
from ..core.errors import InputError

_session = {"result": None, "animation": None, "dialogs": []}


def last_result():
    return _session["result"]


def _report_error(exc):
    App.Console.PrintError(f"WaferScan: {exc}\n")
    QtGui.QMessageBox.warning(Gui.getMainWindow(), "WaferScan", str(exc))


def open_scenario(path):
    """Build a scenario into a new document in the GUI and show it all."""
    from ..cad.builder import build_document
    from ..core.scenario import read_scenario

    doc = build_document(read_scenario(path), name=Path(path).stem.replace("-", "_") or "Layout")
    Gui.getDocument(doc.Name).ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    App.Console.PrintMessage(f"WaferScan: layout built from {path}\n")
    return doc


def run_scan(doc, steps_per_frame=10, show_results=True):
    """Scan the document (as headless runs do), keep the results in it, and animate the scan;
    the results table and the slot code open when the animation ends."""
    from ..cad.document_scan import scan_document
    from .animation import ScanAnimation
    from .results_view import store_in_document

    result = scan_document(doc, "analytic")
    _session["result"] = result
    store_in_document(doc, result)
    if _session["animation"] is not None and _session["animation"].running:
        _session["animation"].stop()
    animation = ScanAnimation(doc, result, steps_per_frame)
    _session["animation"] = animation
    if show_results:
        animation.finished.connect(show_results_dialogs)
    animation.play()
    App.Console.PrintMessage(f"WaferScan: scanning {doc.Label}, code {result.code}\n")
    return animation


def show_results_dialogs():
    from .results_view import ResultsTable, SlotCodeDialog

    result = last_result()
    if result is None:
        return []
    doc = App.ActiveDocument
    dialogs = [ResultsTable(result, doc), SlotCodeDialog(result)]
    for dialog in dialogs:
        dialog.show()
    _session["dialogs"] = dialogs
    return dialogs


class _Command:
    menu, tip = "", ""

    def GetResources(self):
        return {"Pixmap": icon_path(), "MenuText": self.menu, "ToolTip": self.tip}


class NewPaperLayout(_Command):
    menu = "New paper layout"
    tip = "Build the paper's experiment: a 25-slot FOUP, ten wafers, the robot"

    def Activated(self):
        from ..cli import paper_scenario
        try:
            open_scenario(paper_scenario())
        except InputError as exc:
            _report_error(exc)

    def IsActive(self):
        return True


class OpenScenario(_Command):
    menu = "Open scenario…"
    tip = "Build a layout from a scenario file (.toml)"

    def Activated(self):
        path, _ = QtGui.QFileDialog.getOpenFileName(Gui.getMainWindow(), "Open scenario", "",
                                                    "Scenario (*.toml)")
        if path:
            try:
                open_scenario(path)
            except InputError as exc:
                _report_error(exc)

    def IsActive(self):
        return True


class RunScan(_Command):
    menu = "Run scan"
    tip = "Scan the active layout, animated; then show the results and the slot code"

    def Activated(self):
        try:
            run_scan(App.ActiveDocument)
        except InputError as exc:
            _report_error(exc)

    def IsActive(self):
        return App.ActiveDocument is not None


class ResultsTableCommand(_Command):
    menu = "Results table"
    tip = "The last scan's results, slot by slot (the paper's Table 1)"

    def Activated(self):
        show_results_dialogs()

    def IsActive(self):
        return last_result() is not None


COMMANDS = {
    "WaferScan_NewPaperLayout": NewPaperLayout(),
    "WaferScan_OpenScenario": OpenScenario(),
    "WaferScan_RunScan": RunScan(),
    "WaferScan_Results": ResultsTableCommand(),
}


def register():
    for name, command in COMMANDS.items():
        Gui.addCommand(name, command)
    return list(COMMANDS)
