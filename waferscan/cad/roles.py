"""Roles on document objects: which object is a wafer, a carrier, the scanner, the robot or the
scan settings. A role is a set of properties in the "WaferScan" group, so any object can carry
one, the solids of an imported STEP assembly included; the objects WaferScan builds itself
carry them too (see ``features``). Each role's properties, with types and units, are listed in
``role_properties``."""

from __future__ import annotations

from collections import Counter

import FreeCAD as App

from ..core.files.scenario import SUPPORT_OVERLAP
from ..core.rules import wafer_like
from . import role_properties
from .disc import NotADisc, bowed_disc_of, disc_of

GROUP = "WaferScan"
ROLE = "WaferScanRole"
WAFER, CARRIER, SCANNER, ROBOT, SETTINGS = "Wafer", "Carrier", "Scanner", "Robot", "ScanSettings"
ROLES = (WAFER, CARRIER, SCANNER, ROBOT, SETTINGS)


def role_of(obj):
    """The object's role, or None; through a link, the linked object's role counts."""
    for candidate in (obj, obj.getLinkedObject(True)):
        role = getattr(candidate, ROLE, "")
        if role in ROLES:
            return role
    return None


def role_holder(obj):
    """The object that carries the role's properties (the link's target for a link)."""
    return obj if getattr(obj, ROLE, "") in ROLES else obj.getLinkedObject(True)


def add_property(obj, kind, name, doc, value=None):
    """Add a property in the WaferScan group if it is missing, and set it when a value is given."""
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, GROUP, doc)
    if value is not None:
        setattr(obj, name, value)


def add_role_properties(obj, properties, values):
    """Add a role's properties (``role_properties``' table) with their ``values`` by name."""
    for prop in properties:
        add_property(obj, prop.kind, prop.name, prop.tip, values[prop.name])


def set_role(obj, role):
    add_property(obj, "App::PropertyString", ROLE, "What WaferScan takes this object for", role)
    obj.setEditorMode(ROLE, 1)  # read-only in the property editor


def wafer_disc(obj):
    """(diameter, thickness) in mm of the disc an object's solid is; NotADisc, naming the
    object, when it is not one (a bowed wafer's solid is read with its Bow)."""
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        raise NotADisc(f"{obj.Label} has no shape")
    try:
        try:
            disc = disc_of(shape)
        except NotADisc:
            if not getattr(obj, "Bow", 0.0):
                raise
            disc = bowed_disc_of(shape, float(obj.Bow))  # a bowed wafer (SPEC §10) tagged again
    except NotADisc as exc:
        raise NotADisc(f"{obj.Label} is not a wafer: {exc}") from None
    return disc[2], disc[3]


def why_not_a_wafer(obj, diameters=None):
    """Why WaferScan does not take the object for a wafer when it picks the wafers among many
    solids itself (``rules.wafer_like``: a thin disc of a SEMI size, or of ``diameters``), or
    None when it does."""
    try:
        diameter, thickness = wafer_disc(obj)
    except NotADisc as exc:
        return str(exc).replace(f"{obj.Label} is not a wafer: ", "", 1)
    return wafer_like(diameter, thickness, diameters)


def tag_wafer(obj):
    """Give an existing solid the wafer role; refuses (NotADisc) a solid that is not a disc.
    Returns the disc's (diameter, thickness) in mm."""
    disc = wafer_disc(obj)
    set_role(obj, WAFER)
    return disc


def tagged_wafer_sizes(doc):
    """{(diameter, thickness): count} of the discs tagged as wafers in ``doc`` (mm, to the
    micrometre), the most common first; a tagged object that is no disc now is left out."""
    sizes = Counter()
    for obj in doc.Objects:
        if getattr(obj, ROLE, "") != WAFER:
            continue
        try:
            diameter, thickness = wafer_disc(obj)
        except NotADisc:
            continue
        sizes[(round(diameter, 3), round(thickness, 3))] += 1
    return dict(sizes.most_common())


def tag_carrier(obj, slot_count=25, pitch=10.0, wafer_diameter=300.0, wafer_thickness=0.775,
                support_span=None, slot_origin=None):
    """Give an object the carrier role. ``slot_origin`` is where slot 1's seat centre is in the
    object's own frame, with X across the carrier (left to right), -Y out of its opening towards
    the robot and Z up; by default the object's origin."""
    set_role(obj, CARRIER)
    add_role_properties(obj, role_properties.CARRIER, {
        "SlotCount": slot_count, "Pitch": pitch, "WaferDiameter": wafer_diameter,
        "WaferThickness": wafer_thickness,
        "SupportSpan": wafer_diameter - 2 * SUPPORT_OVERLAP if support_span is None
        else support_span,
        "SlotOrigin": slot_origin if slot_origin is not None else App.Placement()})


def tag_scanner(obj, emitter=(0.0, 0.0, 0.0), receiver=(160.0, 0.0, 0.0), lift_axis=(0, 0, 1)):
    """Give an object the scanner role: the beam runs from ``emitter`` to ``receiver``, both in
    the object's own frame. ``lift_axis`` is the global direction the scan moves it along when no
    robot carries it."""
    set_role(obj, SCANNER)
    add_role_properties(obj, role_properties.SCANNER, {
        "Emitter": App.Vector(*emitter), "Receiver": App.Vector(*receiver),
        "LiftAxis": App.Vector(*lift_axis)})


def solid_count(obj):
    """How many solids the object's own shape holds (0 for an object without a shape)."""
    shape = getattr(obj, "Shape", None)
    return 0 if shape is None or shape.isNull() else len(shape.Solids)


def is_compound_of_solids(obj):
    """Whether the object is one shape of several solids of its own (what STEP import makes of
    a whole file with "merge compound" on), as opposed to a container, a group or a link, whose
    solids are objects of their own in the tree."""
    if obj.getSubObjects() or getattr(obj, "LinkedObject", None) is not None:
        return False
    return solid_count(obj) > 1


def split_compound(obj):
    """Put each solid of a compound (a STEP file imported with "merge compound" on, FreeCAD's
    default, is one) into a Part::Feature of its own, placed where it was, and hide the
    compound; returns the new objects, to be tagged one by one. The caller makes it one undo
    step. Names are given up front (``<Name>_S001``...), so that FreeCAD need not search for
    free ones."""
    solids = obj.Shape.Solids
    doc = obj.Document
    container = obj.getParentGeoFeatureGroup()
    group = obj.getParentGroup()
    width = max(3, len(str(len(solids))))
    made = []
    for number, solid in enumerate(solids, start=1):
        name = f"{obj.Name}_S{number:0{width}d}"
        part = doc.addObject("Part::Feature", name)
        part.Label = f"{obj.Label} solid {number}"
        # The compound's shape is placed by the compound's Placement: the solids keep it.
        part.Shape = solid
        for parent in (container, group):
            if parent is not None:
                parent.addObject(part)
                break
        made.append(part)
    obj.Visibility = False
    return made


# The tree's Description column (Label2) shows a tagged object's role whatever its type: FreeCAD
# 0.20 lets Python change the icon of Python features only. Any text already there is kept
# after the mark, and Untag takes the mark off again.
TREE_MARK = "{} (WaferScan)"  # the role first: the column is narrow
TREE_SEPARATOR = " · "


def tree_mark(role):
    """What the tree's Description column starts with for an object of ``role``."""
    return TREE_MARK.format(role)


def show_role_in_tree(obj):
    """Put the object's role at the front of its Label2 (the tree's Description column)."""
    role = role_of(obj)
    text = _unmarked(obj.Label2)
    if role is not None:
        mark = tree_mark(role)
        text = mark + TREE_SEPARATOR + text if text else mark
    if obj.Label2 != text:
        obj.Label2 = text


def _unmarked(text):
    for role in ROLES:
        mark = tree_mark(role)
        if text == mark:
            return ""
        if text.startswith(mark + TREE_SEPARATOR):
            return text[len(mark + TREE_SEPARATOR):]
    return text


def built_by_waferscan(obj):
    """Whether WaferScan built the object (a carrier body, a scanner beam, ScanSettings): its
    properties are what it is made of, not a role given to it."""
    return "WaferScanVersion" in obj.PropertiesList


def untag(obj):
    """Take the role off an object tagged by the user: the role's properties (all of the
    WaferScan group) removed and the tree's mark taken off Label2, so the object is as it was
    before it was tagged. The caller makes it one undo step."""
    for name in [p for p in obj.PropertiesList if obj.getGroupOfProperty(p) == GROUP]:
        obj.removeProperty(name)
    show_role_in_tree(obj)
