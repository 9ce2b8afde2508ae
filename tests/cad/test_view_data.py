"""A layout saved headless (layout_files.save_document) opens in the GUI as the GUI would have
saved it: every object shown as its Visibility says, the Parts' origins hidden. The GUI reads
an object's visibility from both files (Document.xml's Visibility, GuiDocument.xml's view
data)."""

import xml.etree.ElementTree as ElementTree
import zipfile

import FreeCAD as App

from waferscan.cad.layout_files import save_document

ORIGIN_TYPES = ("App::Origin", "App::Line", "App::Plane")


def _visibility(path, member, element):
    """{object name: "true"/"false"} of the Visibility property in one of the file's XMLs."""
    with zipfile.ZipFile(path) as archive:
        root = ElementTree.fromstring(archive.read(member))
    found = {}
    for holder in root.iter(element):
        for prop in holder.iter("Property"):
            if prop.get("name") == "Visibility":
                found[holder.get("name")] = prop.find("Bool").get("value")
    return found


def test_origins_are_saved_hidden_and_the_rest_as_shown(tmp_path):
    doc = App.newDocument("viewdata")
    try:
        part = doc.addObject("App::Part", "Assembly")
        box = doc.addObject("Part::Box", "Box")
        part.addObject(box)
        hidden = doc.addObject("Part::Box", "Hidden")
        hidden.Visibility = False
        path = tmp_path / "layout.FCStd"
        save_document(doc, path)
        origin_features = {o.Name for o in doc.Objects if o.TypeId in ORIGIN_TYPES}
        # Saving changed nothing in the document.
        still_shown = {o.Name: o.Visibility for o in doc.Objects if o.TypeId in ORIGIN_TYPES}
    finally:
        App.closeDocument(doc.Name)
    assert len(origin_features) == 7  # the origin and its three axes and three planes
    assert still_shown == {name: True for name in origin_features}
    hidden_origin = {name: "false" for name in origin_features}
    for member, element in (("GuiDocument.xml", "ViewProvider"), ("Document.xml", "Object")):
        shown = _visibility(path, member, element)
        assert {name: shown.get(name) for name in origin_features} == hidden_origin, member
        assert shown["Assembly"] == "true" and shown["Box"] == "true", member
        assert shown["Hidden"] == "false", member
