"""View providers of WaferScan's own document objects (wafers, carrier body, scanner beam, scan
settings): each shows its role's icon in the tree. As Draft does, they are attached only when
the GUI is up: when such an object is made in a GUI session, and when a document saved without
them (built headless, by the command line or a script) is opened in the GUI.

FreeCAD 0.20 lets Python give a view provider only to Python features; a user's solid tagged
with a role (a Part::Box, an imported STEP solid) keeps the icon of its own type."""

from __future__ import annotations

import zipfile
from xml.etree import ElementTree

import FreeCAD as App

from ..addon import icon_path
from ..cad import roles

ROLE_ICONS = {roles.WAFER: "WaferScan_Wafer.svg", roles.CARRIER: "WaferScan_Carrier.svg",
              roles.SCANNER: "WaferScan_Scanner.svg", roles.SETTINGS: "WaferScan_ScanSettings.svg",
              roles.ROBOT: "WaferScan.svg"}


def role_icon(role):
    """The icon file of a role (the workbench's icon for an object without one)."""
    return icon_path(ROLE_ICONS.get(role, "WaferScan.svg"))


class ViewProviderRole:
    """FreeCAD's default drawing of the object, with its role's icon."""

    def __init__(self, vobj):
        vobj.Proxy = self
        self.Object = vobj.Object

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):  # noqa: N802 (FreeCAD's name)
        return role_icon(roles.role_of(self.Object))

    def dumps(self):
        return None

    def loads(self, state):
        return None

    __getstate__ = dumps
    __setstate__ = loads


def attach(obj):
    """Give ``obj`` the role view provider when it can take one (a Python feature in a GUI
    session without a view-provider proxy of its own); returns whether it did."""
    view = getattr(obj, "ViewObject", None)
    if not App.GuiUp or view is None or "Proxy" not in view.PropertiesList or view.Proxy:
        return False  # a C++ view provider (a Part::Box...) has no Proxy to give
    ViewProviderRole(view)
    return True


_shown_as_saved = set()  # (document name, file) already done


def show_saved_visibility(doc):
    """Show and hide the objects of ``doc`` as its file says. FreeCAD 0.20 opens a document
    saved without a GUI (by the command line, a script) with every object hidden, its view
    data missing; the objects' own Visibility is in Document.xml. Done once per document."""
    key = (doc.Name, doc.FileName)
    if key in _shown_as_saved or not doc.FileName:
        return
    _shown_as_saved.add(key)
    try:
        with zipfile.ZipFile(doc.FileName) as archive:
            root = ElementTree.fromstring(archive.read("Document.xml"))
    except (OSError, KeyError, zipfile.BadZipFile, ElementTree.ParseError):
        return  # nothing to go by: left as FreeCAD opened it
    for data in root.iter("Object"):
        value = data.find("./Properties/Property[@name='Visibility']/Bool")
        obj = doc.getObject(data.get("name", "")) if value is not None else None
        if obj is not None and getattr(obj, "ViewObject", None) is not None:
            obj.ViewObject.Visibility = value.get("value") == "true"


def install():
    """Let the CAD layer attach these view providers and show a document saved without a GUI
    as it was saved (it does not import the GUI)."""
    from ..cad import features

    features.view_provider = attach
    features.show_saved_visibility = show_saved_visibility
    from . import beam_preview  # each scanner's beam drawn from the moment it is tagged

    beam_preview.install()
