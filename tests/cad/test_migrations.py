"""Documents saved today open after the model changes: each WaferScan object carries the
version of its proxy's properties, and opening a document runs the migrations it needs
(features._Proxy, freecad.gears' pattern)."""

import FreeCAD as App
import pytest
from scenarios import PAPER

from waferscan.cad import features
from waferscan.cad.builder import build_document
from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import save_document
from waferscan.core.files.scenario import read_scenario

PROXIES = (features.CarrierBody, features.ScannerBeam, features.ScanSettings)


def _ours(doc):
    return [o for o in doc.Objects if isinstance(getattr(o, "Proxy", None), PROXIES)]


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """The paper's layout as today's code saves it, and its scan's code."""
    doc = build_document(read_scenario(PAPER), name="MigrationPaper")
    try:
        code = scan_document(doc).code
        path = tmp_path_factory.mktemp("saved") / "paper.FCStd"
        save_document(doc, path)
    finally:
        App.closeDocument(doc.Name)
    return path, code


def _open(path):
    doc = App.openDocument(str(path))
    return doc


def test_every_object_is_saved_with_its_version(saved):
    doc = _open(saved[0])
    try:
        objects = _ours(doc)
        assert {type(o.Proxy) for o in objects} == set(PROXIES)
        assert all(o.WaferScanVersion == type(o.Proxy).version for o in objects)
        assert features.ScanSettings.version == 2  # issue 27 item 13: units, explicit "not set"
        assert not doc.isTouched()  # nothing to migrate: the document opens unchanged
    finally:
        App.closeDocument(doc.Name)


def test_a_renamed_property_is_migrated_on_open(saved, monkeypatch):
    path, _ = saved
    doc = _open(path)
    try:
        settings = next(o for o in doc.Objects if isinstance(o.Proxy, features.ScanSettings))
        response, step, mode = settings.SensorResponseMs, float(settings.ZStep), settings.Mode
    finally:
        App.closeDocument(doc.Name)
    # The next version renames SensorResponseMs to ResponseTime and Mode (an enumeration) to
    # ScanMode; ScanSettings' version 2 -> 3 says so.
    monkeypatch.setattr(features.ScanSettings, "version", 3)
    monkeypatch.setattr(features.ScanSettings, "migrations", {2: lambda obj: (
        features.rename_property(obj, "SensorResponseMs", "ResponseTime"),
        features.rename_property(obj, "Mode", "ScanMode"))})
    doc = _open(path)
    try:
        settings = next(o for o in doc.Objects if isinstance(o.Proxy, features.ScanSettings))
        assert "SensorResponseMs" not in settings.PropertiesList
        assert settings.ResponseTime == response
        assert settings.getGroupOfProperty("ResponseTime") == "WaferScan"
        assert "Mode" not in settings.PropertiesList and settings.ScanMode == mode
        assert settings.getEnumerationsOfProperty("ScanMode") == ["fast", "slow"]
        assert float(settings.ZStep) == step  # the others as they were
        assert settings.WaferScanVersion == 3
        others = [o for o in _ours(doc) if o is not settings]
        assert others and all(o.WaferScanVersion == 1 for o in others)
    finally:
        App.closeDocument(doc.Name)


def test_a_document_saved_before_versions_opens_at_today_s_version(saved, tmp_path):
    path, code = saved
    doc = _open(path)
    try:
        for obj in _ours(doc):
            obj.removeProperty("WaferScanVersion")
        older = tmp_path / "older.FCStd"
        save_document(doc, older)
    finally:
        App.closeDocument(doc.Name)
    doc = _open(older)
    try:
        assert all(o.WaferScanVersion == type(o.Proxy).version for o in _ours(doc))
        assert scan_document(doc).code == code
    finally:
        App.closeDocument(doc.Name)


def test_the_role_tables_list_what_every_role_object_carries(saved):
    """cad/role_properties.py is the one listing: each role object of a built layout (robot
    included) carries exactly its table's properties in the WaferScan group, of those types."""
    from waferscan.cad import role_properties, roles

    doc = _open(saved[0])
    try:
        seen = set()
        for obj in doc.Objects:
            role = roles.role_of(obj)
            if role is None or obj.getLinkedObject(True) is not obj:
                continue
            seen.add(role)
            carried = {name: obj.getTypeIdOfProperty(name) for name in obj.PropertiesList
                       if obj.getGroupOfProperty(name) == roles.GROUP
                       and name not in (roles.ROLE, features.VERSION_PROPERTY)}
            listed = {p.name: p.kind for p in role_properties.BY_ROLE[role]}
            assert carried == listed, role
            for prop in role_properties.BY_ROLE[role]:
                assert obj.getDocumentationOfProperty(prop.name) == prop.tip
        assert seen == set(role_properties.BY_ROLE)
    finally:
        App.closeDocument(doc.Name)
