"""Each tagged scanner's beam drawn in the 3D view from the moment it is tagged or its document
opened, not only while a scan plays (issue 27: a beam set beside the wafers went unseen until
the map came out empty). A line from the scanner's Emitter to its Receiver in the scanner's own
scene-graph node, so that it moves with it, drawn over what hides it (the beam runs inside the
carrier, behind its walls). View only: nothing enters the document or its undo history. A
scan's animation hides it and draws the beam its own way (``scan_appearance``)."""

from __future__ import annotations

import FreeCAD as App
from PySide import QtCore

from ..cad import roles
from .scan_appearance import BEAM_CLEAR

__all__ = ["previews", "install"]

WATCHED = ("WaferScanRole", "Emitter", "Receiver")  # the properties that move or make a beam


class BeamLine:
    """The line of one scanner, in its view's root node."""

    def __init__(self, obj):
        from pivy import coin

        holder = roles.role_holder(obj)
        self.root = obj.ViewObject.RootNode
        self.node = coin.SoAnnotation()  # drawn after the scene, over it
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        colour = coin.SoBaseColor()
        colour.rgb.setValue(*BEAM_CLEAR)
        style = coin.SoDrawStyle()
        style.lineWidth = 2
        style.linePattern = 0xF0F0  # dashed: a preview, not the scan's beam
        self.points = coin.SoCoordinate3()
        self.points.point.setValues(0, 2, [tuple(holder.Emitter), tuple(holder.Receiver)])
        line = coin.SoLineSet()
        line.numVertices.setValue(2)
        for node in (light, colour, style, self.points, line):
            self.node.addChild(node)
        self.shown = False
        self.show()

    def show(self):
        if not self.shown:
            self.root.addChild(self.node)
            self.shown = True

    def hide(self):
        if self.shown:
            self.root.removeChild(self.node)
            self.shown = False


class BeamPreviews:
    """The document observer that keeps a ``BeamLine`` on every tagged scanner of every open
    document (``lines``: (document, object) names -> BeamLine). ``hide(doc)`` and ``show(doc)``
    take a document's lines off the view and put them back (a scan plays meanwhile)."""

    def __init__(self):
        self.lines = {}
        self.hidden = set()  # documents whose lines are off the view (a scan plays)

    def slotChangedObject(self, obj, prop):  # noqa: N802 (FreeCAD's names)
        if prop in WATCHED:
            key = (obj.Document.Name, obj.Name)
            # Later: the object may be half made (tag_scanner sets its properties in turn).
            QtCore.QTimer.singleShot(0, lambda: self.refresh(*key))

    def slotDeletedObject(self, obj):  # noqa: N802
        line = self.lines.pop((obj.Document.Name, obj.Name), None)
        if line is not None:
            line.hide()  # the object stays for undo, its view with it

    def slotDeletedDocument(self, doc):  # noqa: N802
        # FreeCAD's GUI has deleted the views already: the lines are let go, not touched.
        self.lines = {key: line for key, line in self.lines.items() if key[0] != doc.Name}
        self.hidden.discard(doc.Name)

    def refresh(self, doc_name, obj_name):
        """Draw (again) the beam of the object named, or take it away when it is no scanner."""
        doc = App.listDocuments().get(doc_name)
        obj = doc.getObject(obj_name) if doc is not None else None
        old = self.lines.pop((doc_name, obj_name), None)
        if old is not None and obj is not None:
            old.hide()
        if obj is None or getattr(obj, "ViewObject", None) is None or \
                roles.role_of(obj) != roles.SCANNER:
            return
        try:
            line = BeamLine(obj)
        except Exception:  # noqa: BLE001 (a scanner without Emitter/Receiver yet: nothing shown)
            return
        if doc_name in self.hidden:
            line.hide()
        self.lines[(doc_name, obj_name)] = line

    def hide(self, doc):
        self.hidden.add(doc.Name)
        for (name, _), line in self.lines.items():
            if name == doc.Name:
                line.hide()

    def show(self, doc):
        self.hidden.discard(doc.Name)
        for (name, _), line in self.lines.items():
            if name == doc.Name:
                line.show()


previews = BeamPreviews()
_installed = []


def install():
    """Start drawing the scanners' beams (once, when the GUI starts)."""
    if not _installed:
        App.addDocumentObserver(previews)
        _installed.append(previews)
