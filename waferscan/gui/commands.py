"""The workbench's commands. Results come from ``scan_document``, the function headless runs
use; the GUI shows them. Document changes are undo transactions; messages go to the report
view, and a user's mistake also gets a (non-blocking) message box."""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..addon import icon_path, paper_scenario
from ..core.errors import InputError, WaferScanError
from ..core.model import ScanParameters
from . import preferences
from .inputs import format_length
from .qt import alive


class WorkbenchSession:
    """What the workbench keeps between commands while FreeCAD runs (one of it: ``session``).
    Every attribute is here from the start; nothing else holds state between commands."""

    def __init__(self):
        self.results = {}  # document Name -> the ScanResult of its last Run scan
        self.animation = None  # the ScanAnimation playing, or played last
        self.task_panel = None  # our task panel shown last (the scan's or the MCS link's)
        self.dialogs = []  # what the last results or cross-check command opened
        self.message_boxes = []  # non-blocking message boxes (errors, hints) not yet closed
        self.results_windows = {}  # document Name -> {"table" | "code": its results dialog}
        self.close_watcher = None  # the document observer that closes a closed one's dialogs
        self.pocket_animation = None  # a slow scan's jabs and sweeps playing (SPEC §13), or None
        self.tolerance_study = None  # the "Tolerance study…" dialog shown last (SPEC §12)

    def keep_message_box(self, box):
        """Keep a non-blocking box alive (Qt would delete it with its last Python reference)."""
        self.message_boxes = [m for m in self.message_boxes if alive(m)] + [box]


session = WorkbenchSession()


def last_result(doc=None):
    """The ScanResult of the document's last Run scan (the active document's), or None."""
    doc = doc or App.ActiveDocument
    return None if doc is None else session.results.get(doc.Name)


def report_error(message):
    """A user's mistake: in the report view, and in a message box that does not block."""
    App.Console.PrintError(f"WaferScan: {message}\n")
    box = QtGui.QMessageBox(QtGui.QMessageBox.Warning, "WaferScan", str(message),
                            QtGui.QMessageBox.Ok, Gui.getMainWindow())
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    session.keep_message_box(box)
    return box


def report_info(message, title="WaferScan"):
    """What the user should know or do next: in the report view and in a message box that does
    not block (a fresh FreeCAD keeps the report view hidden)."""
    App.Console.PrintMessage(f"WaferScan: {message}\n")
    box = QtGui.QMessageBox(QtGui.QMessageBox.Information, title, str(message),
                            QtGui.QMessageBox.Ok, Gui.getMainWindow())
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    session.keep_message_box(box)
    return box


def ask(question, choices, title="WaferScan"):
    """A question the user must answer before going on: ``choices`` are (button text, Qt
    button role) pairs; returns the text of the button clicked, None when the box was closed."""
    box = QtGui.QMessageBox(QtGui.QMessageBox.Question, title, question,
                            QtGui.QMessageBox.NoButton, Gui.getMainWindow())
    buttons = [(box.addButton(text, button_role), text) for text, button_role in choices]
    box.exec_()
    clicked = box.clickedButton()
    return next((text for button, text in buttons if button is clicked), None)


@contextmanager
def transaction(doc, name):
    """One undo step named ``name`` around the block: committed when it ends, aborted (the
    document left as it was) when it raises."""
    doc.openTransaction(name)
    try:
        yield
    except BaseException:
        doc.abortTransaction()
        raise
    doc.commitTransaction()


def _ours_open():
    panel = session.task_panel
    return panel is not None and panel.is_open()


def check_no_other_task_panel():
    """One task panel at a time, as in FreeCAD: another tool's open panel (a sketch being
    edited, say) is the user's to close, not ours."""
    if Gui.Control.activeDialog() and not _ours_open():
        raise InputError("task panel", None, "another task panel is open: close it first")


def _show_task_panel(panel):
    """Show our panel; ours that is open is shut down first (its animation stopped, its
    watching ended)."""
    previous = session.task_panel
    if previous is not None:
        previous.shut_down()
    if Gui.Control.activeDialog():
        Gui.Control.closeDialog()
    Gui.Control.showDialog(panel)
    session.task_panel = panel
    return panel


# --- what the commands do (callable from scripts and tests) -----------------------------------

def open_scenario(path):
    """Build a scenario into a new document and show it all. A scenario without a [mapping]
    table gets the preferences' tolerances, and the preferences' sensor defaults fill what its
    [sensor] and [scan] tables do not set (SPEC §10)."""
    from ..cad.builder import build_document
    from ..core.files.scenario import read_scenario

    layout = read_scenario(path, default_mapping=preferences.mapping_tolerances(),
                           default_sensor=preferences.sensor_defaults())
    doc = build_document(layout, name=Path(path).stem.replace("-", "_") or "Layout")
    Gui.getDocument(doc.Name).ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    App.Console.PrintMessage(f"WaferScan: layout built from {path}: {len(layout.wafers)} "
                             f"wafers, {len(layout.carriers)} carrier(s)\n")
    return doc


def ensure_settings(doc, scene=None):
    """A document scanned without a ScanSettings object gets one, as an undoable step the user
    can then edit: the reader's defaults, the preferences' tolerances and sensor defaults
    (SPEC §10), and a range that covers the windows of the carrier's slots (SPEC §3), wherever
    the scanner happens to stand. With
    several carriers tagged, the user chooses the one to scan. ``scene``: the document's
    DocumentScene when already read. Returns the new ScanSettings object, or None."""
    from ..cad import roles
    from ..cad.features import make_settings
    from ..cad.reader import DocumentScene, carrier_from
    from ..cad.sensor_properties import add_sensor_values
    from ..core.sensor.settings import values_with_defaults

    if any(roles.role_of(o) == roles.SETTINGS for o in doc.Objects):
        return None
    scene = scene or DocumentScene.of(doc)
    check_tagged(scene)
    carriers = [carrier_from(i) for i in scene.carriers]
    chosen = _choose_carrier(doc, carriers) if len(carriers) > 1 else None
    carrier = chosen or carriers[0]
    sensor = preferences.sensor_defaults()
    motion = {k: sensor[k] for k in ("sensor_response", "latch", "acceleration",
                                     "sample_period") if k in sensor}
    scan = ScanParameters(start_z=carrier.seat_z(1) - 0.5 * carrier.pitch,
                          final_z=carrier.seat_z(carrier.slot_count) + 0.5 * carrier.pitch,
                          **motion)
    with transaction(doc, "Add WaferScan scan settings"):
        settings = make_settings(doc, scan, preferences.mapping_tolerances(),
                                 chosen.name if chosen else None)
        add_sensor_values(settings, values_with_defaults(sensor))  # SPEC §10
    App.Console.PrintMessage(f"WaferScan: added {settings.Label} to {doc.Label} (scan of "
                             f"{carrier.name} from {format_length(scan.start_z)} to "
                             f"{format_length(scan.final_z)}: its slots' windows)\n")
    return settings


def check_tagged(scene):
    """An InputError that says what to tag next when the document lacks a carrier or has not
    exactly one scanner (a fresh FreeCAD hides the report view: the message box says it)."""
    missing = []
    if not scene.carriers:
        missing.append("the carrier (the whole container holding the slots, not one of its "
                       "walls) and use Tag as carrier")
    if not scene.scanners:
        missing.append("the through-beam sensor and use Tag as scanner")
    if missing:
        untagged = not (scene.wafers or scene.carriers or scene.scanners)
        raise scene.error(("Nothing in it is tagged yet. " if untagged else "") + "Select " +
                          ", then ".join(missing) + "; wafers are tagged with Tag as wafer.")
    if len(scene.scanners) > 1:
        names = ", ".join(i.path for i in scene.scanners)
        raise scene.error(f"{len(scene.scanners)} visible objects are tagged as scanners "
                          f"({names}): hide the ones not to use (Space), or undo their tagging "
                          "(Edit → Undo)")


def _choose_carrier(doc, carriers):
    """Several carriers (a wall tagged by mistake, or two load ports): the user picks the one
    to scan; it goes into ScanSettings.Carrier."""
    names = [c.name for c in carriers]
    answer = ask(f"{doc.Label} has {len(names)} objects tagged as carriers: {', '.join(names)}. "
                 "Which one is to be scanned? (Your choice is kept in ScanSettings.Carrier. A "
                 "wall tagged by mistake: Edit → Undo its tagging, or delete its WaferScanRole "
                 "property.)",
                 [(name, QtGui.QMessageBox.AcceptRole) for name in names] +
                 [("Cancel", QtGui.QMessageBox.RejectRole)])
    if answer is None or answer == "Cancel" and "Cancel" not in names:
        raise InputError(doc.FileName or doc.Name, None,
                         f"several carriers ({', '.join(names)}): choose the one to scan")
    return carriers[names.index(answer)]


def scan_and_store(doc):
    """The headless scan of the document; its results kept in it as a Spreadsheet (one undo
    step) and for the results commands. Returns the DocumentScene it read and the result."""
    from ..cad.results_sheet import store_in_document

    scene, result = _scan_once(doc)
    session.results[doc.Name] = result
    with transaction(doc, "WaferScan results"):
        store_in_document(doc, result)
    App.Console.PrintMessage(f"WaferScan: {doc.Label}: slot code {result.code}, "
                             f"{len(result.runs)} sensor runs\n")
    for warning in result.warnings:  # what the result cannot know (SPEC §3)
        App.Console.PrintWarning(f"WaferScan: warning: {warning}\n")
    return scene, result


def run_scan(doc, steps_per_frame=None, show_results=True, panel=True, duration_s=None):
    """Scan the document (as headless runs do) and animate the scan, with its task panel; the
    results table and the slot code open when the animation reaches the end. The animation
    lasts the preferences' playback time, unless ``duration_s`` or ``steps_per_frame`` (frames
    as fast as the machine draws them) is given."""
    if panel:
        check_no_other_task_panel()
    scene, result = scan_and_store(doc)
    if not result.layout.wafers:
        report_info(f"No wafer in {doc.Label} is tagged, so every slot reads empty. Select the "
                    "wafers and use Tag as wafer, then Run scan again.")
    return play_scan(doc, result, steps_per_frame, show_results, panel, duration_s, scene)


def play_scan(doc, result, steps_per_frame=None, show_results=True, panel=True,
              duration_s=None, scene=None):
    """Animate ``result`` (a scan of ``doc``), with its task panel unless ``panel`` is False.
    ``scene``: the DocumentScene the scan read, unchanged since (None: read the document)."""
    from .animation import ScanAnimation
    from .scan_panel import ScanTaskPanel

    previous = session.animation
    if previous is not None:
        previous.stop()
    if steps_per_frame is None and duration_s is None:
        duration_s = preferences.playback_seconds()
    animation = ScanAnimation(doc, result, steps_per_frame or 10, duration_s, scene)
    session.animation = animation
    # The animation showed this result: its dialogs show it too.
    on_completed = (lambda: show_results_dialogs(doc, result=result)) if show_results else None
    if result.pockets:  # SPEC §13: then the jabs and sweeps, pocket by pocket
        from .pocket_animation import then_pockets

        on_completed = then_pockets(doc, result, on_completed, _show_task_panel if panel
                                    else None, session)
    if panel:
        def replay(seconds):
            if scan_panel.settings_changed:  # settings edited in the panel: scan with them
                run_scan(doc, show_results=show_results, duration_s=seconds)
            else:
                play_scan(doc, result, show_results=show_results, duration_s=seconds)
        scan_panel = ScanTaskPanel(animation, on_completed, replay, transaction)
        _show_task_panel(scan_panel)
    elif on_completed is not None:
        animation.finished.connect(lambda: animation.completed and on_completed())
    animation.play()
    return animation


def result_now(doc):
    """The document's results as it is now: scanned afresh (a millisecond), so that a wafer
    moved or deleted since the last Run scan is seen. Only Run scan stores them."""
    return _scan_once(doc)[1]


def _scan_once(doc):
    """(scene, result): the document read once (its scene walked, its layout read) and scanned
    with the analytic engine. Says what to tag when a role is missing; adds ScanSettings when
    there are none (the scene then read again, to hold them)."""
    from ..cad.document_scan import scan_document
    from ..cad.reader import DocumentScene, read_layout

    scene = DocumentScene.of(doc)
    check_tagged(scene)
    if ensure_settings(doc, scene) is not None:
        scene = DocumentScene.of(doc)
    layout = read_layout(doc, scene)
    return scene, scan_document(doc, "analytic", read=(scene, layout))


DIALOG_TITLES = {"table": "WaferScan results", "code": "WaferScan slot code"}


def show_results_dialogs(doc=None, which=("table", "code"), result=None):
    """The results table and/or the slot-code dialog of ``result``, by default of the document
    as it is now. One of each per document: a later scan's replaces the earlier one in the
    same place, so that dialogs do not pile up; titles name the document."""
    from .results_view import ResultsTable, SlotCodeDialog

    doc = doc or App.ActiveDocument
    result = result or result_now(doc)
    if session.close_watcher is None:
        session.close_watcher = _ClosedDocuments()
        App.addDocumentObserver(session.close_watcher)
    views = session.results_windows.setdefault(doc.Name, {})
    dialogs = []
    for kind in which:
        dialog = ResultsTable(result, doc) if kind == "table" else SlotCodeDialog(result)
        dialog.setWindowTitle(f"{DIALOG_TITLES[kind]}: {doc.Label}")
        dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        if kind == "code":  # room for the side view, on screens that have it
            dialog.resize(max(dialog.width(), 760), max(dialog.height(), 600))
        old = views.get(kind)
        if alive(old) and old.isVisible():
            dialog.setGeometry(old.geometry())
            old.close()
        else:
            fit_screen(dialog)
        views[kind] = dialog
        dialog.show()
        dialog.raise_()
        dialogs.append(dialog)
    session.dialogs = dialogs
    return dialogs


class _ClosedDocuments:
    """A document closed: its results dialogs close too (they would point at nothing)."""

    def slotDeletedDocument(self, doc):  # noqa: N802 (FreeCAD's name)
        for dialog in session.results_windows.pop(doc.Name, {}).values():
            if alive(dialog):
                dialog.close()
        session.results.pop(doc.Name, None)


def fit_screen(dialog, margin=(40, 80)):
    """Shrink a dialog to the screen the main window is on (1024×700 included), less a
    margin for the window frame and the desktop's panels."""
    screen = QtGui.QApplication.desktop().availableGeometry(Gui.getMainWindow())
    size = dialog.size()
    dialog.resize(min(size.width(), screen.width() - margin[0]),
                  min(size.height(), screen.height() - margin[1]))


def open_mcs_panel(doc, folder=None):
    from .mcs_panel import McsTaskPanel

    check_no_other_task_panel()
    return _show_task_panel(McsTaskPanel(doc, folder))


ROLE_NAMES = {"wafer": "Wafer", "carrier": "Carrier", "scanner": "Scanner"}
TAG_HINTS = {"wafer": "its disc is read from its solid",
             "carrier": "set SlotCount, Pitch and SlotOrigin (slot 1's seat) in its Data tab",
             "scanner": "set Emitter and Receiver (in its own frame) in its Data tab"}


def tag_selection(role, selection=None):
    """Give the selected objects a role (wafer, carrier or scanner) as one undo step; a solid
    that cannot take it leaves the document as it was. An object that has another role is
    re-tagged only when the user says so; a compound of several solids (a STEP file imported
    with "merge compound" on) is offered to be split into its solids first."""
    from ..cad import roles

    objects = list(Gui.Selection.getSelection() if selection is None else selection)
    if not objects:
        raise InputError("selection", None, f"select the object(s) to tag as {role} first")
    doc = objects[0].Document
    other = [o for o in objects if roles.role_of(o) not in (None, ROLE_NAMES[role])]
    if other:
        names = ", ".join(f"{o.Label} ({roles.role_of(o).lower()})" for o in other)
        retag = f"Tag as {role}"
        if ask(f"{names} already {'has' if len(other) == 1 else 'have'} a WaferScan role. "
               f"Tag {'it' if len(other) == 1 else 'them'} as {role} instead?",
               [(retag, QtGui.QMessageBox.AcceptRole),
                ("Cancel", QtGui.QMessageBox.RejectRole)]) != retag:
            return []
    compounds = [o for o in objects if roles.role_of(o) is None and roles.is_compound_of_solids(o)]
    if compounds:
        split = _offer_split(role, compounds)
        if split is None:
            return []
        if split:
            return _split_and_tag(role, objects, compounds)
    with transaction(doc, f"Tag as {role}"):
        for obj in objects:
            _tag(role, obj)
    doc.recompute()
    from .view_providers import ViewProviderRole, attach
    for obj in objects:  # a Python feature shows its new role's icon
        if attach(obj) or isinstance(getattr(obj.ViewObject, "Proxy", None), ViewProviderRole):
            obj.ViewObject.signalChangeIcon()
    names = ", ".join(o.Label for o in objects)
    message = f"Tagged {names} as {role}: {TAG_HINTS[role]}."
    if role == "wafer":  # nothing to set: the status bar is enough
        App.Console.PrintMessage(f"WaferScan: {message}\n")
        Gui.getMainWindow().statusBar().showMessage(f"WaferScan: {message}", 15000)
    else:
        report_info(message)
    return objects


def _tag(role, obj):
    from ..cad import roles

    {"wafer": roles.tag_wafer, "carrier": roles.tag_carrier,
     "scanner": roles.tag_scanner}[role](obj)


def _offer_split(role, compounds):
    """Ask whether to split the compounds into their solids: True (split), False (tag each
    compound as a whole, not offered for wafers: a wafer is one solid), None (cancel)."""
    from ..cad import roles

    count = sum(roles.solid_count(o) for o in compounds)
    names = ", ".join(o.Label for o in compounds)
    split = "Split into solids"
    whole = f"Tag as one {role}"
    question = (f"{names} {'is a compound' if len(compounds) == 1 else 'are compounds'} of "
                f"{count} solids (a STEP file imported with \"merge compound\" on is one "
                "compound). Split into one object per solid, as one undo step")
    choices = [(split, QtGui.QMessageBox.AcceptRole)]
    if role == "wafer":
        question += ", and tag the discs among them as wafers?"
    else:
        question += f", then select the {role} among them? Or tag the whole as the {role}?"
        choices.append((whole, QtGui.QMessageBox.AcceptRole))
    choices.append(("Cancel", QtGui.QMessageBox.RejectRole))
    answer = ask(question, choices)
    return {split: True, whole: False}.get(answer)


def _split_and_tag(role, objects, compounds):
    """Split the compounds into their solids (one undo step); for the wafer role, the discs
    among the solids and the other selected objects are tagged in the same step. Says what to
    do next; returns the new solids."""
    from ..cad import roles
    from ..cad.disc import NotADisc

    doc = objects[0].Document
    tagged = []
    with transaction(doc, "Split compound into solids"):
        solids = []
        for compound in compounds:
            solids += roles.split_compound(compound)
        if role == "wafer":
            for obj in [o for o in objects if o not in compounds]:
                roles.tag_wafer(obj)  # one that is not a disc aborts the whole step
                tagged.append(obj)
            for solid in solids:
                try:
                    roles.tag_wafer(solid)
                except NotADisc:
                    continue
                tagged.append(solid)
    doc.recompute()
    rest = [s for s in solids if s not in tagged]
    Gui.Selection.clearSelection()
    for solid in rest:
        Gui.Selection.addSelection(solid)
    names = ", ".join(o.Label for o in compounds)
    if role == "wafer":
        message = (f"Split {names} into {len(solids)} solids and tagged {len(tagged)} as wafers "
                   f"({', '.join(o.Label for o in tagged) or 'none was a disc'}). Next: select "
                   "the carrier among the other solids (selected now) and use Tag as carrier, "
                   "then the sensor and Tag as scanner.")
    else:
        message = (f"Split {names} into {len(solids)} solids (selected now). Next: select the "
                   f"{role} among them and use Tag as {role} again.")
    report_info(message)
    return solids


def cross_check(doc):
    """The B-rep cross-check of the document's last scan, reported in the report view and a
    dialog."""
    from ..cad.crosscheck import crosscheck
    from ..core.files.report import format_crosscheck

    result = result_now(doc)
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
    box.setWindowTitle(f"WaferScan cross-check: {doc.Label}")
    for details in box.findChildren(QtGui.QTextEdit):  # a table: its columns line up
        details.setFont(QtGui.QFontDatabase.systemFont(QtGui.QFontDatabase.FixedFont))
        details.setLineWrapMode(QtGui.QTextEdit.NoWrap)
    box.setModal(False)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.show()
    session.dialogs = [box]
    return check


def calibrate_layout(doc):
    """SPEC §11: calibrate the document's recipe from its reference wafers (slots 1 and n) and
    show the calibrated recipe beside the current one with the check scan's code. A failure is
    reported in its own words. Returns the core Calibration, or None."""
    from ..cad.document_calibration import calibrate_document
    from ..core.scan.calibration import CalibrationError, format_calibration
    from .calibration_view import calibration_dialog

    QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
    try:
        calibration = calibrate_document(doc)
    except CalibrationError as exc:
        report_error(f"Calibration of {doc.Label} failed: {exc}")
        return None
    finally:
        QtGui.QApplication.restoreOverrideCursor()
    App.Console.PrintMessage(f"WaferScan calibration of {doc.Label}:\n"
                             f"{format_calibration(calibration)}\n")
    dialog = calibration_dialog(calibration, f"WaferScan calibration: {doc.Label}",
                                Gui.getMainWindow())
    dialog.show()
    session.dialogs = [dialog]
    return calibration


def open_tolerance_study(input_path="", **settings):
    """The "Tolerance study…" dialog (SPEC §12), non-modal; ``settings`` preset its fields
    (tolerances, n, seed, workers, out). Returns the dialog."""
    from .tolerance_dialog import ToleranceStudyDialog

    dialog = ToleranceStudyDialog(input_path, **settings)
    dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    dialog.show()
    session.tolerance_study = dialog
    return dialog


# --- the commands ------------------------------------------------------------------------

def record(call):
    """Run ``call``, a line of Python on this module's functions, as FreeCAD's own commands do:
    through ``Gui.doCommand``, so that the Python console shows it and macro recording keeps
    it, the call a script would make."""
    Gui.addModule("waferscan.gui.commands")
    Gui.doCommand(f"waferscan.gui.commands.{call}")


def _doc_ref(doc):
    return f"App.getDocument({doc.Name!r})"


def _objects_ref(objects):
    return "[" + ", ".join(f"{_doc_ref(o.Document)}.getObject({o.Name!r})"
                           for o in objects) + "]"


class _Command:
    menu, tip, icon = "", "", "WaferScan.svg"
    shows_only = False  # True: usable even while another tool's task panel is open

    def GetResources(self):
        resources = {"Pixmap": icon_path(self.icon), "MenuText": self.menu, "ToolTip": self.tip}
        if self.shows_only:
            resources["CmdType"] = "ForEdit"
        return resources

    def Activated(self):
        try:
            self.run()
        except WaferScanError as exc:
            report_error(exc)

    def IsActive(self):
        return App.ActiveDocument is not None


class NewPaperLayout(_Command):
    menu, icon = "New paper layout", "WaferScan_NewPaperLayout.svg"
    tip = "Build the paper's experiment: a 25-slot FOUP with ten wafers and the robot"

    def run(self):
        record(f"open_scenario({str(paper_scenario())!r})")

    def IsActive(self):
        return True


class OpenScenario(_Command):
    menu, icon = "Open scenario…", "WaferScan_OpenScenario.svg"
    tip = "Build a layout from a scenario file (.toml)"

    def run(self):
        path, _ = QtGui.QFileDialog.getOpenFileName(Gui.getMainWindow(), "Open scenario",
                                                    str(paper_scenario().parent),
                                                    "Scenario (*.toml)")
        if path:
            record(f"open_scenario({path!r})")

    def IsActive(self):
        return True


class Tag(_Command):
    def __init__(self, role, tip):
        self.role, self.menu, self.tip = role, f"Tag as {role}", tip
        self.icon = f"WaferScan_Tag{role.capitalize()}.svg"

    def run(self):
        selection = Gui.Selection.getSelection()
        if not selection:
            tag_selection(self.role, selection)  # says what to select
            return
        record(f"tag_selection({self.role!r}, {_objects_ref(selection)})")

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
        record(f"run_scan({_doc_ref(App.ActiveDocument)})")


class CalibrateCommand(_Command):
    menu, icon = "Calibrate", "WaferScan_Calibrate.svg"
    tip = ("Calibrate the recipe from reference wafers in the bottom and top slots: slot-1 seat, "
           "pitch, scan range, thickness correction, then a check scan (SPEC §11)")

    def run(self):
        record(f"calibrate_layout({_doc_ref(App.ActiveDocument)})")


class McsLinkCommand(_Command):
    menu, icon = "MCS link…", "WaferScan_McsLink.svg"
    tip = ("Talk to the robot's motion control software through parameters.txt, commands.txt "
           "and results.txt in a folder")

    def run(self):
        record(f"open_mcs_panel({_doc_ref(App.ActiveDocument)})")


class ResultsTableCommand(_Command):
    shows_only = True
    menu, icon = "Results table", "WaferScan_Results.svg"
    tip = "The scan's results, slot by slot (the paper's Table 1); selecting a row selects the wafer"

    def run(self):
        record(f"show_results_dialogs({_doc_ref(App.ActiveDocument)}, ('table',))")


class SlotCodeCommand(_Command):
    shows_only = True
    menu, icon = "Slot code", "WaferScan_SlotCode.svg"
    tip = "The slot code, its per-slot strip, a side view of the runs and the E87 map"

    def run(self):
        record(f"show_results_dialogs({_doc_ref(App.ActiveDocument)}, ('code',))")


class CrossCheckCommand(_Command):
    shows_only = True
    menu, icon = "Cross-check with CAD", "WaferScan_CrossCheck.svg"
    tip = "Confirm every IN and OUT of the scan with FreeCAD's B-rep geometry (OpenCASCADE)"

    def run(self):
        record(f"cross_check({_doc_ref(App.ActiveDocument)})")


class ToleranceStudyCommand(_Command):
    shows_only = True
    menu, icon = "Tolerance study…", "WaferScan_ToleranceStudy.svg"
    tip = ("Monte Carlo sweep of the recipe under tolerances (seat, thickness, beam...): how "
           "often each state is misread, the margins and safer windows (SPEC §12)")

    def run(self):
        record("open_tolerance_study()")

    def IsActive(self):
        return True


class PreferencesCommand(_Command):
    shows_only = True
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
    "WaferScan_Calibrate": CalibrateCommand(),
    "WaferScan_McsLink": McsLinkCommand(),
    "WaferScan_Results": ResultsTableCommand(),
    "WaferScan_SlotCode": SlotCodeCommand(),
    "WaferScan_CrossCheck": CrossCheckCommand(),
    "WaferScan_ToleranceStudy": ToleranceStudyCommand(),
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
