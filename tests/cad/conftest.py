"""FreeCAD for the CAD tests: its Python library folder on sys.path. No skip when FreeCAD is
missing: the set-up installs it, so its absence is a failure."""

import sys

# This checkout's package, imported before FreeCAD: FreeCAD's start puts its user Mod folders
# first on sys.path, and a Mod/WaferScan symlink to another checkout (FREECAD-NOTES) would
# otherwise be the waferscan these tests import.
import waferscan  # noqa: E402,F401

FREECAD_LIB = "/usr/lib/freecad-python3/lib"
if FREECAD_LIB not in sys.path:
    sys.path.append(FREECAD_LIB)


import pytest  # noqa: E402 (after FreeCAD's path)


@pytest.fixture(scope="session")
def paper_layout_read():
    """The paper's scenario read into a core Layout (resources/examples/paper.toml)."""
    from waferscan.addon import paper_scenario
    from waferscan.core.files.scenario import read_scenario

    return read_scenario(paper_scenario())


@pytest.fixture
def built():
    """``built(layout, name)``: a fresh FreeCAD document of ``layout``, closed after the test
    (unless the test closed it)."""
    import FreeCAD as App

    from waferscan.cad.builder import build_document

    names = []

    def build(layout, name):
        doc = build_document(layout, name)
        names.append(doc.Name)
        return doc

    yield build
    for name in names:
        if name in App.listDocuments():
            App.closeDocument(name)


@pytest.fixture
def paper_doc(paper_layout_read, built):
    """A fresh FreeCAD document of the paper's layout, closed after the test (unless the test
    closed it)."""
    return built(paper_layout_read, "PaperTest")
