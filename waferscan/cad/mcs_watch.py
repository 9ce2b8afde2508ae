"""The headless MCS link on a FreeCAD document: each SCF/SCS reads parameters.txt afresh and
scans the document, checking for STOP while it runs."""

from __future__ import annotations

from pathlib import Path

from ..core.mcs import PARAMETERS, Parameters, read_parameters
from .document_scan import scan_document


def document_scanner(doc, folder, engine="analytic"):
    """The ``scan`` function of an ``McsLink`` for a document."""
    folder = Path(folder)

    def scan(command, should_stop):
        should_stop()
        path = folder / PARAMETERS
        parameters = read_parameters(path) if path.exists() else Parameters({}, {}, str(path))
        mode = "fast" if command.name == "SCF" else "slow"
        parameters = Parameters({**parameters.values, "mode": mode}, parameters.lines,
                                parameters.source)
        return scan_document(doc, engine, progress=lambda done, total: should_stop(),
                             parameters=parameters)

    return scan
