"""The workbench's commands. Results come from ``scan_document``, the function headless runs
use; the GUI shows them. Document changes are undo transactions; messages go to the report
view, and a user's mistake also gets a (non-blocking) message box."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..addon import icon_path
from ..cad.disc import NotADisc
from ..core.errors import InputError
from . import preferences
from .qt import alive

# The last scan of each document (by its Name), the running animation, the open dialogs.
_session = {"results": {}, "animation": None, "dialogs": [], "messages": []}


def last_result(doc=None):
    doc = doc or App.ActiveDocument
    return None if doc is None else _session["results"].get(doc.Name)


def report_error(message):
    """A user's mistake: in the report view, and in a message box that does not block."""
    App.Console.PrintError(f"WaferScan: {message}\n")
    box = QtGui.QMessageBox(QtGui.QMessageBox.Warning, "WaferScan", str(message),
                            QtGui.QMessageBox.Ok, Gui.getMainWindow())
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    _session["messages"] = [m for m in _session["messages"] if alive(m)] + [box]
    return box


def _ours_open():
    panel = _session.get("panel")
    return panel is not None and panel.is_open()


def check_no_other_task_panel():
    """One task panel at a time, as in FreeCAD: another tool's open panel (a sketch being
    edited, say) is the user's to close, not ours."""
    if Gui.Control.activeDialog() and not _ours_open():
        raise InputError("task panel", None, "another task panel is open: close it first")


def _show_task_panel(panel):
    """Show our panel; ours that is open is shut down first (its animation stopped, its
    watching ended)."""
    previous = _session.get("panel")
    if previous is not None:
        previous.shut_down()
    if Gui.Control.activeDialog():
        Gui.Control.closeDialog()
    Gui.Control.showDialog(panel)
    _session["panel"] = panel
    return panel


# --- what the commands do (callable from scripts and tests) -----------------------------------

def open_scenario(path):
    """Build a scenario into a new document and show it all. A scenario without a [mapping]
    table gets the preferences' tolerances."""
    from ..cad.builder import build_document
    from ..core.scenario import read_scenario

    layout = read_scenario(path)
    try:
        has_mapping = "mapping" in tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        has_mapping = True  # read_scenario read it; keep what it gave
    if not has_mapping:
        layout = replace(layout, mapping=preferences.mapping_tolerances())
    doc = build_document(layout, name=Path(path).stem.replace("-", "_") or "Layout")
    Gui.getDocument(doc.Name).ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    App.Console.PrintMessage(f"WaferScan: layout built from {path}: {len(layout.wafers)} "
                             f"wafers, {len(layout.carriers)} carrier(s)\n")
    return doc


def ensure_settings(doc):
    """A document scanned without a ScanSettings object gets one, with the reader's defaults
    and the preferences' tolerances, as an undoable step the user can then edit."""
    from ..cad import roles
    from ..cad.features import make_settings
    from ..cad.reader import read_layout

    if any(roles.role_of(o) == roles.SETTINGS for o in doc.Objects):
        return None
    layout = read_layout(doc)
    doc.openTransaction("Add WaferScan scan settings")
    try:
        settings = make_settings(doc, layout.scan, preferences.mapping_tolerances(), None)
    except Exception:
        doc.abortTransaction()
        raise
    doc.commitTransaction()
    App.Console.PrintMessage(f"WaferScan: added {settings.Label} to {doc.Label} (scan from "
                             f"{layout.scan.start_z:g} to {layout.scan.final_z:g} mm)\n")
    return settings


def scan(doc):
    """The headless scan of the document; its results kept in it as a Spreadsheet (one undo
    step) and for the results commands."""
    from .results_view import store_in_document

    result = results_for(doc)
    _session["results"][doc.Name] = result
    doc.openTransaction("WaferScan results")
    try:
        store_in_document(doc, result)
    except Exception:
        doc.abortTransaction()
        raise
    doc.commitTransaction()
    App.Console.PrintMessage(f"WaferScan: {doc.Label}: slot code {result.code}, "
                             f"{len(result.runs)} sensor runs\n")
    for warning in result.warnings:  # what the result cannot know (SPEC §3)
        App.Console.PrintWarning(f"WaferScan: warning: {warning}\n")
    return result


def run_scan(doc, steps_per_frame=None, show_results=True, panel=True):
    """Scan the document (as headless runs do) and animate the scan, with its task panel; the
    results table and the slot code open when the animation reaches the end."""
    from .animation import ScanAnimation
    from .scan_panel import ScanTaskPanel

    if panel:
        check_no_other_task_panel()
    result = scan(doc)
    previous = _session["animation"]
    if previous is not None:
        previous.stop()
    speed = preferences.steps_per_frame() if steps_per_frame is None else steps_per_frame
    animation = ScanAnimation(doc, result, speed)
    _session["animation"] = animation
    # The animation showed this result: its dialogs show it too.
    on_completed = (lambda: show_results_dialogs(doc, result=result)) if show_results else None
    if panel:
        _show_task_panel(ScanTaskPanel(animation, on_completed))
    elif on_completed is not None:
        animation.finished.connect(lambda: animation.completed and on_completed())
    animation.play()
    return animation


def results_for(doc):
    """The document's results as it is now: scanned afresh (a millisecond), so that a wafer
    moved or deleted since the last Run scan is seen. Only Run scan stores them."""
    from ..cad.document_scan import scan_document

    ensure_settings(doc)
    return scan_document(doc, "analytic")


def show_results_dialogs(doc=None, which=("table", "code"), result=None):
    """The results table and/or the slot-code dialog of ``result``, by default of the document
    as it is now."""
    from .results_view import ResultsTable, SlotCodeDialog

    doc = doc or App.ActiveDocument
    result = result or results_for(doc)
    dialogs = []
    if "table" in which:
        dialogs.append(ResultsTable(result, doc))
    if "code" in which:
        dialogs.append(SlotCodeDialog(result))
    for dialog in dialogs:
        dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        dialog.show()
    _session["dialogs"] = dialogs
    return dialogs


def open_mcs_panel(doc, folder=None):
    from .mcs_panel import McsTaskPanel

    check_no_other_task_panel()
    return _show_task_panel(McsTaskPanel(doc, folder))


def tag_selection(role, selection=None):
    """Give the selected objects a role (wafer, carrier or scanner) as one undo step; a solid
    that cannot take it leaves the document as it was."""
    from ..cad import roles

    taggers = {"wafer": roles.tag_wafer, "carrier": roles.tag_carrier,
               "scanner": roles.tag_scanner}
    objects = list(Gui.Selection.getSelection() if selection is None else selection)
    if not objects:
        raise InputError("selection", None, f"select the object(s) to tag as {role} first")
    doc = objects[0].Document
    doc.openTransaction(f"Tag as {role}")
    try:
        for obj in objects:
            taggers[role](obj)
    except Exception:
        doc.abortTransaction()
        raise
    doc.commitTransaction()
    doc.recompute()
    names = ", ".join(o.Label for o in objects)
    hints = {"wafer": "its disc is read from its solid",
             "carrier": "set SlotCount, Pitch and SlotOrigin (slot 1's seat) in its Data tab",
             "scanner": "set Emitter and Receiver (in its own frame) in its Data tab"}
    App.Console.PrintMessage(f"WaferScan: tagged {names} as {role}; {hints[role]}\n")
    return objects


def cross_check(doc):
    """The B-rep cross-check of the document's last scan, reported in the report view and a
    dialog."""
    from ..cad.brep import crosscheck
    from ..core.report import format_crosscheck

    result = results_for(doc)
    QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
    Gui.getMainWindow().statusBar().showMessage("WaferScan: cross-checking with OpenCASCADE…")
    try:
        check = crosscheck(doc, result)
    finally:
        QtGui.QApplication.restoreOverrideCursor()
        Gui.getMainWindow().statusBar().clearMessage()
    text = format_crosscheck(check)
    (App.Console.PrintMessage if check.ok else App.Console.PrintWarning)(
        f"WaferScan cross-check of {doc.Label}:\n{text}\n")
    box = QtGui.QMessageBox(QtGui.QMessageBox.Information if check.ok
                            else QtGui.QMessageBox.Warning, "WaferScan cross-check",
                            f"{'Confirmed' if check.ok else 'NOT confirmed'}: largest deviation "
                            f"{check.largest_deviation:.2e} mm over {len(check.wafers)} wafers "
                            f"and {len(check.runs)} sensor runs.",
                            QtGui.QMessageBox.Ok, Gui.getMainWindow())
    box.setDetailedText(text)
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    _session["dialogs"] = [box]
    return check


# --- the commands ------------------------------------------------------------------------

class _Command:
    menu, tip, icon = "", "", "WaferScan.svg"

    def GetResources(self):
        return {"Pixmap": icon_path(self.icon), "MenuText": self.menu, "ToolTip": self.tip}

    def Activated(self):
        try:
            self.run()
        except (InputError, NotADisc) as exc:
            report_error(exc)

    def IsActive(self):
        return App.ActiveDocument is not None


class NewPaperLayout(_Command):
    menu, icon = "New paper layout", "WaferScan_NewPaperLayout.svg"
    tip = "Build the paper's experiment: a 25-slot FOUP with ten wafers and the robot"

    def run(self):
        from ..cli import paper_scenario
        open_scenario(paper_scenario())

    def IsActive(self):
        return True


class OpenScenario(_Command):
    menu, icon = "Open scenario…", "WaferScan_OpenScenario.svg"
    tip = "Build a layout from a scenario file (.toml)"

    def run(self):
        from ..cli import paper_scenario
        path, _ = QtGui.QFileDialog.getOpenFileName(Gui.getMainWindow(), "Open scenario",
                                                    str(paper_scenario().parent),
                                                    "Scenario (*.toml)")
        if path:
            open_scenario(path)

    def IsActive(self):
        return True


class Tag(_Command):
    icon = "WaferScan_TagSelection.svg"

    def __init__(self, role, tip):
        self.role, self.menu, self.tip = role, f"Tag as {role}", tip

    def run(self):
        tag_selection(self.role)

    def IsActive(self):
        return bool(Gui.Selection.getSelection())


class TagGroup:
    """The three tag commands as one toolbar button with a drop-down."""

    def GetCommands(self):
        return tuple(TAG_COMMANDS)

    def GetResources(self):
        return {"Pixmap": icon_path("WaferScan_TagSelection.svg"), "MenuText": "Tag selection",
                "ToolTip": "Give the selected solids a WaferScan role"}

    def IsActive(self):
        return bool(Gui.Selection.getSelection())


class RunScan(_Command):
    menu, icon = "Run scan", "WaferScan_RunScan.svg"
    tip = ("Scan the active layout, animated (play, pause, stop, speed in the task panel); "
           "then show the results and the slot code")

    def run(self):
        run_scan(App.ActiveDocument)


class McsLinkCommand(_Command):
    menu, icon = "MCS link…", "WaferScan_McsLink.svg"
    tip = ("Talk to the robot's motion control software through parameters.txt, commands.txt "
           "and results.txt in a folder")

    def run(self):
        open_mcs_panel(App.ActiveDocument)


class ResultsTableCommand(_Command):
    menu, icon = "Results table", "WaferScan_Results.svg"
    tip = "The scan's results, slot by slot (the paper's Table 1); selecting a row selects the wafer"

    def run(self):
        show_results_dialogs(App.ActiveDocument, ("table",))


class SlotCodeCommand(_Command):
    menu, icon = "Slot code", "WaferScan_SlotCode.svg"
    tip = "The slot code, its per-slot strip, a side view of the runs and the E87 map"

    def run(self):
        show_results_dialogs(App.ActiveDocument, ("code",))


class CrossCheckCommand(_Command):
    menu, icon = "Cross-check with CAD", "WaferScan_CrossCheck.svg"
    tip = "Confirm every IN and OUT of the scan with FreeCAD's B-rep geometry (OpenCASCADE)"

    def run(self):
        cross_check(App.ActiveDocument)


class PreferencesCommand(_Command):
    menu, icon = "Preferences…", "WaferScan_Preferences.svg"
    tip = "Default tolerances, the MCS folder and the playback speed"

    def run(self):
        Gui.showPreferences("WaferScan")

    def IsActive(self):
        return True


TAG_COMMANDS = {
    "WaferScan_TagWafer": Tag("wafer", "Tag the selected solids as wafers (each must be a disc)"),
    "WaferScan_TagCarrier": Tag("carrier", "Tag the selected object as a wafer carrier"),
    "WaferScan_TagScanner": Tag("scanner", "Tag the selected object as the through-beam scanner"),
}

COMMANDS = {
    "WaferScan_NewPaperLayout": NewPaperLayout(),
    "WaferScan_OpenScenario": OpenScenario(),
    "WaferScan_Tag": TagGroup(),
    "WaferScan_RunScan": RunScan(),
    "WaferScan_McsLink": McsLinkCommand(),
    "WaferScan_Results": ResultsTableCommand(),
    "WaferScan_SlotCode": SlotCodeCommand(),
    "WaferScan_CrossCheck": CrossCheckCommand(),
    "WaferScan_Preferences": PreferencesCommand(),
}


def register():
    """Add the commands to FreeCAD; returns the toolbar's and the menu's command names: the
    toolbar has the tag commands behind one drop-down, the menu lists them."""
    for name, command in {**TAG_COMMANDS, **COMMANDS}.items():
        Gui.addCommand(name, command)
    toolbar = list(COMMANDS)
    menu = []
    for name in toolbar:
        menu += ["Separator", *TAG_COMMANDS, "Separator"] if name == "WaferScan_Tag" else [name]
    return toolbar, menu
