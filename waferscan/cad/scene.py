"""What the 3D view shows: every visible object instance of a document with its global placement
and shape, through App::Part containers, groups and App::Link.

FreeCAD 0.20 quirk, handled here and only here: ``obj.getGlobalPlacement()`` follows App::Part
containers but not App::Link. An instance is therefore addressed as FreeCAD's selection does,
by a root object and a sub-name path ("Carrier.Wafer."), and its placement and shape are asked
of the root (``getSubObject(sub, retType=3)``, ``Part.getShape(root, sub)``), which follow both.
Through a link, the link's placement replaces the linked object's own (LinkTransform off).
"""

from __future__ import annotations

from dataclasses import dataclass

import FreeCAD as App
import Part

from ..core.errors import InputError

MAX_DEPTH = 32  # links can form cycles; no real assembly nests deeper


@dataclass(frozen=True)
class Instance:
    """One occurrence of an object in the scene."""

    root: object  # top-level document object
    sub: str  # sub-name path from the root, "" for the root itself
    obj: object  # the object at the end of the path (a link object, if it is one)
    target: object  # the object it finally shows (through links)

    @property
    def path(self):
        """A readable, unique name: the labels along the path."""
        names = [self.root.Label]
        for part in self.sub.split(".")[:-1]:
            names.append(self.root.Document.getObject(part).Label)
        return "/".join(names)

    def _gone(self):
        return InputError(self._source, None, f"{self._where} is no longer in the document: it "
                                              "was deleted or unlinked while it was being read")

    def placement(self):
        """Global placement of the instance (App.Placement). InputError if the object has left
        the document since it was found (deleted, or a link broken)."""
        try:
            if not self.sub:
                # FreeCAD 0.20 leaks ~80 B on each read of ``obj.Placement`` (the attribute);
                # getPropertyByName gives the same value without the leak. A free [[wafer]]
                # is read here at every step of a document scan.
                return App.Placement(self.root.getPropertyByName("Placement"))
            placement = self.root.getSubObject(self.sub, retType=3)
        except ReferenceError:
            raise self._gone() from None
        if placement is None:
            raise self._gone()
        return placement

    def shape(self):
        """Global shape of the instance, placed as the 3D view shows it."""
        try:
            shape = Part.getShape(self.root, self.sub)
        except ReferenceError:
            raise self._gone() from None
        if shape.isNull():
            raise self._gone()
        return shape

    def __post_init__(self):
        # Kept at creation: a deleted object can no longer tell its name or its document's.
        object.__setattr__(self, "_where", self.path)
        doc = self.root.Document
        object.__setattr__(self, "_source", doc.FileName or doc.Name)


def _claimed(doc):
    """Names of the objects another object shows as its own children in the tree: those of
    groups and App::Part containers, and also the elements of an App::LinkGroup (STEP import's
    default with "Use LinkGroup" on), which neither ``getParentGroup`` nor
    ``getParentGeoFeatureGroup`` reports. A link's target is not claimed by the link: the tree
    lists it on its own, and the 3D view shows it when it is visible."""
    claimed = set()
    for obj in doc.Objects:
        if getattr(obj, "LinkedObject", None) is not None:
            continue  # a link: its sub-objects belong to its target
        for sub in obj.getSubObjects():
            claimed.add(sub.split(".", 1)[0])
    return claimed


def scene_roots(doc):
    """Objects no group, container or link group claims: the top of the tree, so that each
    solid is walked once, as the tree and the 3D view show it."""
    claimed = _claimed(doc)
    return [o for o in doc.Objects
            if o.getParentGroup() is None and o.getParentGeoFeatureGroup() is None
            and o.Name not in claimed]


def _visible(obj):
    return getattr(obj, "Visibility", True)


def scene_instances(doc):
    """Every visible instance of the document's scene, depth first."""
    found = []

    def walk(root, sub, obj, depth):
        if depth > MAX_DEPTH or not _visible(obj):
            return
        found.append(Instance(root, sub, obj, obj.getLinkedObject(True)))
        for child_sub in obj.getSubObjects():
            child = obj.getSubObject(child_sub, retType=1)
            if child is not None:
                walk(root, sub + child_sub, child, depth + 1)

    for root in scene_roots(doc):
        walk(root, "", root, 0)
    return found
