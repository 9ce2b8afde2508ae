"""The builder names objects up front (FreeCAD's own search for a free name, and its check of
every label, are O(n) an object: minutes for 10,000 wafers), and what it names reads back as it
was; the preference it turns on for the build is put back as it was."""

import re
import xml.etree.ElementTree as ElementTree
from dataclasses import replace

import FreeCAD as App
import pytest

from waferscan.bench import stack_layout
from waferscan.cad import roles
from waferscan.cad.builder import build_document
from waferscan.cad.layout_files import xml_attribute
from waferscan.cad.reader import read_layout
from waferscan.core.model import Wafer

PREFERENCES = "User parameter:BaseApp/Preferences/Document"


@pytest.fixture
def closing():
    names = []
    yield lambda doc: names.append(doc.Name)
    for name in names:
        if name in App.listDocuments():
            App.closeDocument(name)


def test_objects_are_named_after_their_labels(closing):
    layout = stack_layout(3)
    doc = build_document(layout, "NamedStack")
    closing(doc)
    wafers = [o for o in doc.Objects if getattr(o, "WaferScanRole", "") == roles.WAFER]
    assert [(o.Name, o.Label) for o in wafers] == [(w.name, w.name) for w in layout.wafers]
    for carrier in layout.carriers:
        assert doc.getObject(carrier.name).Label == carrier.name
        assert doc.getObject(f"{carrier.name}_assembly").Label == f"{carrier.name} assembly"
    read = read_layout(doc)
    assert [w.name for w in read.wafers] == [w.name for w in layout.wafers]


def test_names_a_name_cannot_spell_keep_their_labels(closing):
    """Labels with characters a name cannot have, one starting with a digit, and two that make
    the same name: every label reads back as given."""
    base = stack_layout(1)
    free = [Wafer(name=name, center=(1000.0 + 400 * i, 0.0, 300.0), normal=(0.0, 0.0, 1.0),
                  diameter=300.0, thickness=0.7)
            for i, name in enumerate(["wafer #1", "2nd wafer", "wafer_1", "wafer-1", "é"])]
    layout = replace(base, wafers=base.wafers + tuple(free))
    doc = build_document(layout, "OddNames")
    closing(doc)
    read = read_layout(doc)
    assert [w.name for w in read.wafers] == [w.name for w in layout.wafers]
    names = [o.Name for o in doc.Objects]
    assert len(set(names)) == len(names)
    assert doc.getObject("_2nd_wafer").Label == "2nd wafer"


@pytest.mark.parametrize("before", [None, False, True])
def test_the_duplicate_labels_preference_is_put_back(closing, before):
    group = App.ParamGet(PREFERENCES)
    if before is None:
        group.RemBool("DuplicateLabels")
    else:
        group.SetBool("DuplicateLabels", before)
    try:
        closing(build_document(stack_layout(1), "Preference"))
        if before is None:
            assert "DuplicateLabels" not in group.GetBools()
        else:
            assert group.GetBool("DuplicateLabels") is before
    finally:
        group.RemBool("DuplicateLabels")


def test_a_label_set_after_the_build_is_checked_again(closing):
    """Outside the build FreeCAD checks labels as the user asked: a copy's label is made
    unique, as before."""
    doc = build_document(stack_layout(1), "Checked")
    closing(doc)
    App.ParamGet(PREFERENCES).RemBool("DuplicateLabels")
    extra = doc.addObject("Part::Cylinder", "Extra")
    extra.Label = "S1_W01"
    assert extra.Label != "S1_W01"


@pytest.mark.parametrize("text", ["Wafer001", 'a"b', "a'b\"c", "<&>", "line\nbreak\ttab"])
def test_view_data_attributes_are_quoted(text):
    element = ElementTree.fromstring(f"<ViewProvider name={xml_attribute(text)}/>")
    assert element.get("name") == text


@pytest.mark.parametrize("before", [None, False])
def test_layouts_are_saved_with_binary_shapes_and_read_back(closing, tmp_path, before):
    import zipfile

    from waferscan.cad.layout_files import opened_layout, save_document

    group = App.ParamGet(PREFERENCES)
    if before is None:
        group.RemBool("SaveBinaryBrep")
    else:
        group.SetBool("SaveBinaryBrep", before)
    layout = stack_layout(2)
    doc = build_document(layout, "Binary")
    closing(doc)
    path = tmp_path / "binary.FCStd"
    try:
        save_document(doc, path)
        if before is None:
            assert "SaveBinaryBrep" not in group.GetBools()
        else:
            assert group.GetBool("SaveBinaryBrep") is before
    finally:
        group.RemBool("SaveBinaryBrep")
    # FreeCAD 0.20 names the shape files PartShape<N>.bin, 1.0 <Object>.Shape.bin (next to
    # <Object>.Shape.Map.txt element maps; docs/freecad-1.0.md); the extension tells binary
    # (.bin) from text (.brp) either way.
    shapes = [n for n in zipfile.ZipFile(path).namelist()
              if re.fullmatch(r"(PartShape\d*|.+\.Shape)\.(bin|brp)", n)]
    assert len(shapes) == 50 + 2 + 1 and all(n.endswith(".bin") for n in shapes)
    App.closeDocument(doc.Name)
    with opened_layout(path) as reopened:
        read = read_layout(reopened)
    assert [(w.name, w.center) for w in read.wafers] == \
        [(w.name, pytest.approx(w.center, abs=1e-9)) for w in layout.wafers]
