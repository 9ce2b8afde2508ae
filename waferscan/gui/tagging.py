"""Tagging: the selected objects given a WaferScan role (wafer, carrier or scanner) as one undo
step, with what to set or select next said to the user. An object with another role is
re-tagged only when the user says so; a compound of several solids is offered to be split.
The Tag commands ask those questions first (``record_tagging``) and record the answers in the
line they run, ``tag_selection('wafer', [...], split=True)``, so that a macro replays it without
asking."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtGui

from ..core.errors import InputError
from .session import ask, doc_ref, record, report, transaction

__all__ = ["tag_selection", "record_tagging", "untag_selection", "make_carrier_from_solids",
           "ROLE_NAMES", "TAG_HINTS"]


ROLE_NAMES = {"wafer": "Wafer", "carrier": "Carrier", "scanner": "Scanner"}
TAG_HINTS = {"wafer": "its disc is read from its solid",
             "carrier": "give its slots with Set up carrier and sensor… (derived from its "
                        "geometry, slot 1's seat picked in the 3D view), or set SlotCount, "
                        "Pitch and SlotOrigin in its Data tab",
             "scanner": "pick the beam's ends with Set up carrier and sensor…, or set Emitter "
                        "and Receiver (in its own frame) in its Data tab"}


def tag_selection(role, selection=None, diameters=None, split=None, retag=None):
    """Give the selected objects a role (wafer, carrier or scanner) as one undo step; a solid
    that cannot take it leaves the document as it was. An object that has another role is
    re-tagged only when the user says so (``retag``: True re-tags, False leaves all as it is,
    None asks); a compound of several solids (a STEP file imported with "merge compound" on) is
    split into its solids first when the user says so (``split``: True splits, False tags each
    compound whole, not for wafers, None asks), and then only the wafer-like discs among them
    are tagged as wafers (``rules.wafer_like``: a SEMI size, or one of ``diameters`` in mm). A
    disc selected on its own is tagged whatever its size, with a word when it does not look
    like a wafer. A carrier takes its wafers' size from the discs already tagged as wafers."""
    objects = list(Gui.Selection.getSelection() if selection is None else selection)
    if not objects:
        raise InputError("selection", None, f"select the object(s) to tag as {role} first")
    doc = objects[0].Document
    other = _other_roles(role, objects)
    if other:
        if retag is None:
            retag = _ask_retag(role, other)
        if not retag:
            return []
    compounds = _compounds(objects)
    if compounds:
        if split is None:
            split = _offer_split(role, compounds)
        if split is None:
            return []
        if split:
            return _split_and_tag(role, objects, compounds, diameters)
        if role == "wafer":
            raise InputError("split", None, "a wafer is one solid: a compound is split into its "
                                            "solids (split=True), not tagged whole as a wafer")
    notes = []
    with transaction(doc, f"Tag as {role}"):
        notes += _tag_all(role, objects, diameters)
    _show_icons(objects)
    names = ", ".join(o.Label for o in objects)
    message = " ".join([f"Tagged {names} as {role}: {TAG_HINTS[role]}.", *notes])
    if role == "wafer" and not notes:  # nothing to set: the status bar is enough
        App.Console.PrintMessage(f"WaferScan: {message}\n")
        Gui.getMainWindow().statusBar().showMessage(f"WaferScan: {message}", 15000)
    else:
        report(message)
    return objects


def record_tagging(role, selection):
    """Tag as ``role``, as the Tag commands do: the questions tagging would ask (re-tag objects
    with another role? split a compound?) are asked now, and their answers go into the line
    recorded and run, ``tag_selection(role, [...], retag=True, split=True)``, which a macro
    replays without asking. Cancelled: nothing recorded, nothing done."""
    objects = list(selection)
    if not objects:
        tag_selection(role, objects)  # says what to select
        return
    answers = ""
    other = _other_roles(role, objects)
    if other:
        if not _ask_retag(role, other):
            return
        answers += ", retag=True"
    compounds = _compounds(objects)
    if compounds:
        split = _offer_split(role, compounds)
        if split is None:
            return
        answers += f", split={split!r}"
    listed = ", ".join(f"{doc_ref(o.Document)}.getObject({o.Name!r})" for o in objects)
    record(f"tag_selection({role!r}, [{listed}]{answers})")


def _other_roles(role, objects):
    """Those of ``objects`` that have a role other than ``role``."""
    from ..cad import roles

    return [o for o in objects if roles.role_of(o) not in (None, ROLE_NAMES[role])]


def _compounds(objects):
    """Those of ``objects`` (without a role) that are compounds of several solids."""
    from ..cad import roles

    return [o for o in objects if roles.role_of(o) is None and roles.is_compound_of_solids(o)]


def _ask_retag(role, other):
    """Ask whether to tag ``other`` (objects with another role) as ``role`` instead."""
    from ..cad import roles

    names = ", ".join(f"{o.Label} ({roles.role_of(o).lower()})" for o in other)
    retag = f"Tag as {role}"
    return ask(f"{names} already {'has' if len(other) == 1 else 'have'} a WaferScan role. "
               f"Tag {'it' if len(other) == 1 else 'them'} as {role} instead?",
               [(retag, QtGui.QMessageBox.AcceptRole),
                ("Cancel", QtGui.QMessageBox.RejectRole)]) == retag


def _tag_all(role, objects, diameters=None):
    """Tag ``objects`` (inside the caller's transaction), each one's role shown in the tree;
    returns what the user should know: wafers that do not look like wafers, where a carrier's
    wafer size came from."""
    from ..cad import roles
    from ..core.rules import wafer_like

    notes = []
    odd = []
    sizes = {}
    for obj in objects:
        if role == "wafer":
            diameter, thickness = sizes[obj.Label] = roles.tag_wafer(obj)
            why = wafer_like(diameter, thickness, diameters)
            if why:
                odd.append(f"{obj.Label} is {why}")
        elif role == "carrier":
            notes.append(_tag_carrier(obj))
        else:
            roles.tag_scanner(obj)
        roles.show_role_in_tree(obj)
    obj.Document.recompute()
    if odd:
        notes.append("Tagged as you asked, though " + "; ".join(odd) +
                     " (Untag what is not a wafer).")
    if sizes:
        notes += _carrier_size_notes(objects[0].Document, sizes)
    return notes + _hidden_column_note()


_told = set()  # what the user has been told once this session


def _hidden_column_note():
    """Where to see the roles when the tree hides its Description column (FreeCAD 1.0's
    default): said once a session."""
    if "column" in _told:
        return []
    trees = [t for t in Gui.getMainWindow().findChildren(QtGui.QTreeWidget)
             if t.metaObject().className() == "Gui::TreeWidget" and t.columnCount() > 1]
    if not any(t.isColumnHidden(1) for t in trees):
        return []
    _told.add("column")
    return ["The tree's Description column shows each object's WaferScan role; it is hidden "
            "now: right-click the tree → Tree settings → Show description."]


def _carrier_size_notes(doc, sizes):
    """What to say when wafers tagged after their carrier are not of the carrier's nominal
    size (``sizes``: {label: (diameter, thickness)} of the wafers just tagged): the carrier's
    WaferDiameter and WaferThickness are not changed behind the user's back."""
    from ..cad import roles
    from .inputs import format_length

    notes = []
    for carrier in doc.Objects:
        if getattr(carrier, roles.ROLE, "") != roles.CARRIER or \
                "WaferThickness" not in carrier.PropertiesList:
            continue
        nominal = (carrier.WaferDiameter.Value, carrier.WaferThickness.Value)
        other = [label for label, size in sizes.items()
                 if any(abs(a - b) > 1e-6 for a, b in zip(size, nominal))]
        if other:
            diameter, thickness = sizes[other[0]]
            notes.append(
                f"{carrier.Label} holds {format_length(nominal[0])}, "
                f"{format_length(nominal[1])} wafers (its WaferDiameter and WaferThickness), "
                f"but {other[0]}{f' and {len(other) - 1} more' if len(other) > 1 else ''} "
                f"{'is' if len(other) == 1 else 'are'} {format_length(diameter)}, "
                f"{format_length(thickness)}: set them in its Data tab if the wafers are "
                "right.")
    return notes


def _tag_carrier(obj):
    """Tag ``obj`` as a carrier whose wafer size is that of the wafers tagged in its document
    (the most common one); says where the size came from."""
    from ..cad import roles
    from .inputs import format_length

    sizes = roles.tagged_wafer_sizes(obj.Document)
    if not sizes:
        roles.tag_carrier(obj)
        return (f"No wafers are tagged yet: its WaferDiameter and WaferThickness are the "
                f"defaults ({format_length(obj.WaferDiameter.Value)}, "
                f"{format_length(obj.WaferThickness.Value)}); tag the wafers first to take "
                "theirs, or set them.")
    (diameter, thickness), count = next(iter(sizes.items()))
    roles.tag_carrier(obj, wafer_diameter=diameter, wafer_thickness=thickness)
    total = sum(sizes.values())
    source = (f"the {count} tagged wafers" if count == total else
              f"{count} of the {total} tagged wafers (the most common size)")
    return (f"WaferDiameter {format_length(diameter)} and WaferThickness "
            f"{format_length(thickness)} are those of {source}.")


def _show_icons(objects):
    from .view_providers import ViewProviderRole, attach

    for obj in objects:  # a Python feature shows its new role's icon
        if attach(obj) or isinstance(getattr(obj.ViewObject, "Proxy", None), ViewProviderRole):
            obj.ViewObject.signalChangeIcon()


def untag_selection(selection=None):
    """Take the WaferScan role off the selected objects, as one undo step: the properties
    tagging added removed, the tree's mark taken off, each object as it was before it was
    tagged. The objects WaferScan built itself (a carrier body, a scanner, ScanSettings) are
    refused: delete them instead."""
    from ..cad import roles

    objects = list(Gui.Selection.getSelection() if selection is None else selection)
    if not objects:
        raise InputError("selection", None, "select the tagged object(s) to untag first")
    built = [o for o in objects if roles.built_by_waferscan(o)]
    if built:
        raise InputError("selection", None,
                         f"{', '.join(o.Label for o in built)} "
                         f"{'was' if len(built) == 1 else 'were'} built by WaferScan, not "
                         "tagged: delete instead of untagging")
    tagged = [o for o in objects if getattr(o, roles.ROLE, "") in roles.ROLES]
    if not tagged:
        raise InputError("selection", None,
                         f"{', '.join(o.Label for o in objects)} "
                         f"{'has' if len(objects) == 1 else 'have'} no WaferScan role to remove")
    doc = tagged[0].Document
    was = [f"{o.Label} ({roles.role_of(o).lower()})" for o in tagged]
    with transaction(doc, "Untag"):
        for obj in tagged:
            roles.untag(obj)
        doc.recompute()
    from .view_providers import ViewProviderRole
    for obj in tagged:
        if isinstance(getattr(obj.ViewObject, "Proxy", None), ViewProviderRole):
            obj.ViewObject.signalChangeIcon()
    message = f"Untagged {', '.join(was)}: no WaferScan role any more."
    App.Console.PrintMessage(f"WaferScan: {message}\n")
    Gui.getMainWindow().statusBar().showMessage(f"WaferScan: {message}", 15000)
    return tagged


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
        question += (", then tag the wafer-like discs among them as wafers, as a second "
                     "undo step (the other solids are listed, with why)?")
    else:
        question += f", then select the {role} among them? Or tag the whole as the {role}?"
        choices.append((whole, QtGui.QMessageBox.AcceptRole))
    choices.append(("Cancel", QtGui.QMessageBox.RejectRole))
    answer = ask(question, choices)
    return {split: True, whole: False}.get(answer)


MAX_LISTED = 10  # skipped solids named in the message box; the report view lists them all


def _split_and_tag(role, objects, compounds, diameters=None):
    """Split the compounds into their solids (one undo step); for the wafer role, the
    wafer-like discs among the solids, and the other selected objects, are then tagged (a
    second undo step), and the solids skipped are listed with the reason. Says what to do
    next; returns the new solids."""
    from ..cad import roles

    doc = objects[0].Document
    _own_undo_steps("Split compound into solids")
    with transaction(doc, "Split compound into solids"):
        solids = []
        for compound in compounds:
            solids += roles.split_compound(compound)
    doc.recompute()
    names = ", ".join(o.Label for o in compounds)
    if role != "wafer":
        _select(solids)
        report(f"Split {names} into {len(solids)} solids (selected now). Next: select the "
               f"{role} among them and use Tag as {role} again.")
        return solids
    skipped = [(s, roles.why_not_a_wafer(s, diameters)) for s in solids]
    wafers = [s for s, why in skipped if why is None]
    skipped = [(s, why) for s, why in skipped if why is not None]
    chosen = [o for o in objects if o not in compounds]
    tagged = chosen + wafers
    notes = []
    if tagged:
        with transaction(doc, "Tag as wafer"):
            notes = _tag_all("wafer", tagged, diameters)
    _show_icons(tagged)
    _select([s for s, _ in skipped])
    lines = [f"{s.Label}: {why}" for s, why in skipped]
    message = (f"Split {names} into {len(solids)} solids and tagged {len(wafers)} as wafers "
               f"({_listed([o.Label for o in wafers]) or 'none was a wafer-like disc'}).")
    if skipped:
        shown = lines[:MAX_LISTED]
        more = len(lines) - len(shown)
        message += (f"\n\nSkipped {len(skipped)}, not wafer-like (selected now):\n" +
                    "\n".join(f"• {line}" for line in shown) +
                    (f"\n• and {more} more (the report view lists them all)" if more else ""))
        for line in lines[MAX_LISTED:]:
            App.Console.PrintMessage(f"WaferScan: skipped {line}\n")
    message += "\n\n" + " ".join([*notes, (
        "Next: select the carrier among the other solids (or several, and Make carrier from "
        "solids), use Tag as carrier, then the sensor and Tag as scanner. A wafer tagged "
        "wrongly: select it and Untag.")])
    report(message)
    return solids


def _own_undo_steps(name):
    """Let each transaction opened from here on be an undo step of its own. FreeCAD folds all
    that a GUI command does into one undo step (its AutoTransaction ignores the commits made
    inside it); a persistent active transaction turns that off for the rest of the command.
    Outside a command (a macro replayed) it changes nothing."""
    App.setActiveTransaction(name)
    App.setActiveTransaction(name, True)


def _listed(labels):
    """``labels`` joined, the first ``MAX_LISTED`` of a long list and how many more."""
    if len(labels) <= MAX_LISTED:
        return ", ".join(labels)
    return f"{', '.join(labels[:MAX_LISTED])} and {len(labels) - MAX_LISTED} more"


def _select(objects):
    Gui.Selection.clearSelection()
    for obj in objects:
        Gui.Selection.addSelection(obj)


def make_carrier_from_solids(selection=None, label="Carrier"):
    """Gather the selected solids (a STEP file's walls, split from its compound) into one
    App::Part labelled ``label`` and tag it as the carrier, as one undo step. The part is made
    in the solids' own container, so that nothing moves; it takes the tagged wafers' size."""
    from ..cad import roles

    objects = list(Gui.Selection.getSelection() if selection is None else selection)
    if not objects:
        raise InputError("selection", None,
                         "select the solids the carrier is made of first (its walls, its base)")
    roled = [o for o in objects if roles.role_of(o) not in (None, roles.WAFER)]
    if roled:
        raise InputError("selection", None, "; ".join(
            f"{o.Label} is tagged as {roles.role_of(o).lower()}" for o in roled) +
            ": a carrier is made of untagged solids (and may hold wafers); Untag it first, or "
            "leave it out")
    parents = {o.getParentGeoFeatureGroup() for o in objects}
    if len(parents) > 1:
        places = sorted(p.Label if p is not None else "the document itself" for p in parents)
        raise InputError("selection", None,
                         f"the selected solids lie in different containers ({', '.join(places)}):"
                         " select solids of one container, or tag that container as the carrier")
    parent = parents.pop()
    doc = objects[0].Document
    with transaction(doc, "Make carrier from solids"):
        part = doc.addObject("App::Part", "Carrier")
        part.Label = label
        if parent is not None:
            parent.addObject(part)
        for obj in objects:
            part.addObject(obj)
        note = " ".join([_tag_carrier(part), *_hidden_column_note()])
        roles.show_role_in_tree(part)
        doc.recompute()
    _select([part])
    report(f"Made {part.Label} of {len(objects)} solids "
           f"({', '.join(o.Label for o in objects)}) and tagged it as the carrier: "
           f"{TAG_HINTS['carrier']}. {note}")
    return part

