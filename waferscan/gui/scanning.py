"""Reading and scanning the active layout as headless runs do (``cad.document_scan``): a
scenario built into a document, what is still to tag said in words, ScanSettings added when
missing (the carrier chosen by the user when several are tagged), and the scan's result kept in
the document and in the session. Nothing here animates or opens a dialog."""

from __future__ import annotations

from pathlib import Path

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtGui

from ..core.errors import InputError
from ..core.model import ScanParameters
from ..core.rules import slots_scan_range
from . import preferences
from .inputs import format_length
from .session import ask, session, transaction

__all__ = ["open_scenario", "ensure_settings", "check_tagged", "scan_and_store", "result_now",
           "changed_since"]


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
    start_z, final_z = slots_scan_range(carrier)
    scan = ScanParameters(start_z=start_z, final_z=final_z, **motion)
    with transaction(doc, "Add WaferScan scan settings"):
        settings = make_settings(doc, scan, preferences.mapping_tolerances(),
                                 chosen.name if chosen else None, range_from_carrier=True)
        add_sensor_values(settings, values_with_defaults(sensor))  # SPEC §10
    App.Console.PrintMessage(f"WaferScan: added {settings.Label} to {doc.Label} (scan of "
                             f"{carrier.name} from {format_length(scan.start_z)} to "
                             f"{format_length(scan.final_z)}: its slots' windows, followed "
                             "until you set StartZ or FinalZ)\n")
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
    # One undo step: the results, and a range that follows the carrier shown as scanned.
    with transaction(doc, "WaferScan results"):
        show_followed_range(scene, result.layout)
        store_in_document(doc, result)
    App.Console.PrintMessage(f"WaferScan: {doc.Label}: slot code {result.code}, "
                             f"{len(result.runs)} sensor runs\n")
    for warning in result.warnings:  # what the result cannot know (SPEC §3)
        App.Console.PrintWarning(f"WaferScan: warning: {warning}\n")
    return scene, result


def result_now(doc):
    """The document's results as it is now: scanned afresh (a millisecond), so that a wafer
    moved or deleted since the last Run scan is seen. Only Run scan stores them (and shows a
    range that follows the carrier in StartZ and FinalZ): the document is not changed here."""
    return _scan_once(doc)[1]


def changed_since(doc, result):
    """Whether ``doc`` now reads as another layout than the one ``result`` scanned (a carrier,
    a wafer, the scanner or ScanSettings edited since, an Undo): its scan would differ. A
    document that cannot be read any more has changed too."""
    from dataclasses import replace

    from ..cad.reader import DocumentScene, read_layout

    try:
        now = read_layout(doc, DocumentScene.of(doc))
    except Exception:  # noqa: BLE001 (whatever the reason, the scan shown is not the document's)
        return True
    scanned = result.layout
    if result.asked_scan is not None:  # the scan ran with other settings than those asked
        scanned = replace(scanned, scan=result.asked_scan)
    return now != scanned


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


def show_followed_range(scene, layout):
    """A range that follows the carrier (RangeFromCarrier) is what the reader computed from
    the carrier; StartZ and FinalZ are set to it when they differ, so that the property editor
    shows the range scanned. The caller holds the undo step (Run scan's results)."""
    from ..cad import roles
    from ..cad.features import RANGE_FROM_CARRIER, following_carrier

    if not scene.settings:
        return
    settings = roles.role_holder(scene.settings[0].obj)
    if not getattr(settings, RANGE_FROM_CARRIER, False):
        return
    scan = layout.scan
    if (settings.StartZ.Value, settings.FinalZ.Value) == (scan.start_z, scan.final_z):
        return
    with following_carrier():
        settings.StartZ, settings.FinalZ = scan.start_z, scan.final_z
    App.Console.PrintMessage(f"WaferScan: {settings.Label}: the scan range follows "
                             f"{layout.carrier}'s slots: {format_length(scan.start_z)} to "
                             f"{format_length(scan.final_z)}\n")
