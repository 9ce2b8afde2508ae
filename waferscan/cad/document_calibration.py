"""Auto-calibration (SPEC §11, core/scan/calibration.py) of a FreeCAD document's layout: the command
line's ``waferscan calibrate``, the MCS link's ``CAL`` and the GUI's Calibrate command all read
the document's layout, put a parameters.txt's values over it, and calibrate with the core scan
of the layout read."""

from __future__ import annotations

from ..core.errors import InputError
from ..core.files.mcs import apply_parameters
from ..core.scan.calibration import calibrate
from ..core.scan.engine_choice import check_engine
from ..core.scan.layout_scan import scan_layout
from .reader import DocumentScene, read_layout


def calibrate_document(doc, parameters=None, engine="analytic", progress=None, read=None,
                       source=None):
    """Calibrate the document's layout (with ``parameters``, a core ``mcs.Parameters``, over
    it). ``read``: (scene, layout) already read from this document (the MCS link's cache);
    ``progress(done, total)`` is called during both scans; ``source`` names the layout in an
    error (default: the document's file). Returns a core Calibration or raises
    CalibrationError (InputError for bad input, an engine that cannot scan the layout too)."""
    if read is not None:
        layout = read[1]
    else:
        layout = read_layout(doc, DocumentScene.of(doc))
    if parameters is not None:
        layout = apply_parameters(layout, parameters)
    source = source or doc.FileName or doc.Label
    check_engine(layout, engine, source, parameters)
    try:
        return calibrate(layout, lambda scanned: scan_layout(scanned, engine, progress=progress))
    except InputError as exc:
        if exc.source != "z_step":
            raise
        # The core names the key only: the file and line that set z_step are named here.
        if parameters is not None and "z_step" in parameters.values:
            raise InputError(parameters.source, parameters.lines.get("z_step"),
                             f"z_step: {exc.message}") from None
        line = None
        if str(source).lower().endswith(".toml"):
            from ..core.files.scenario import key_line
            from ..core.files.text_files import read_text

            try:
                line = key_line(read_text(source), "scan", "z_step")
            except InputError:
                pass
        raise InputError(source, line, f"z_step: {exc.message}") from None


def calibrate_input(path, parameters=None, engine="analytic"):
    """Calibrate a scenario .toml or a layout .FCStd, as ``waferscan scan`` scans one: an
    engine that cannot scan the layout is refused as ``scan`` refuses it (InputError)."""
    from .layout_files import opened_layout

    with opened_layout(path) as doc:
        return calibrate_document(doc, parameters, engine, source=path)
