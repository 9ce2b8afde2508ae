"""Tagging: the selected objects given a WaferScan role (wafer, carrier or scanner) as one undo
step, with what to set or select next said to the user. An object with another role is
re-tagged only when the user says so; a compound of several solids is offered to be split."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtGui

from ..core.errors import InputError
from .session import ask, report, transaction

__all__ = ["tag_selection", "ROLE_NAMES", "TAG_HINTS"]


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
        report(message)
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
    report(message)
    return solids
