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
from .layout_files import setting_error
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
        raise setting_error(exc.message, source, parameters, "scan", "z_step") from None


def calibrate_input(path, parameters=None, engine="analytic"):
    """Calibrate a scenario .toml or a layout .FCStd, as ``waferscan scan`` scans one: an
    engine that cannot scan the layout is refused as ``scan`` refuses it (InputError)."""
    from .layout_files import opened_layout

    with opened_layout(path) as doc:
        return calibrate_document(doc, parameters, engine, source=path)


def apply_calibration(doc, calibration, scene=None):
    """Write a calibration's recipe into the document it was made of (no transaction: the GUI
    makes it one undo step): the scanned carrier's taught slot-1 seat (its ``SlotOrigin``,
    moved along the global Z so that the seat lands at the calibrated Z) and ``Pitch``, and on
    ScanSettings the scan range (``StartZ``, ``FinalZ``) and the recipe (the windows, the rule
    set, ``ThicknessCorrection``). A document without ScanSettings gets one, from the
    calibrated layout. The wafers, the scanner and the robot are left where they are: they are
    what the sensor measured. Returns the objects written, by role."""
    import FreeCAD as App

    from . import features, recipe_properties, roles
    from .reader import carrier_from
    from .sensor_properties import add_sensor_properties

    scene = scene or DocumentScene.of(doc)
    after = calibration.after
    carrier = after.scanned_carrier
    instance = next((i for i in scene.carriers if carrier_from(i).name == carrier.name), None)
    if instance is None:
        raise InputError(doc.FileName or doc.Label, None,
                         f"the carrier {carrier.name} is no longer in the document")
    holder = roles.role_holder(instance.obj)
    now = carrier_from(instance).first_slot_z
    # The seat is the global Z of (the instance's placement × SlotOrigin): a global move by dz
    # is the same move in the holder's own frame, turned back by the instance's rotation.
    rise = instance.placement().Rotation.inverted().multVec(
        App.Vector(0.0, 0.0, carrier.first_slot_z - now))
    origin = App.Placement(holder.SlotOrigin)
    origin.Base = origin.Base + rise
    holder.SlotOrigin = origin
    holder.Pitch = carrier.pitch
    if scene.settings:
        settings = roles.role_holder(scene.settings[0].obj)
        settings.StartZ = after.scan.start_z
        settings.FinalZ = after.scan.final_z
        if all(prop in settings.PropertiesList
               for prop, _, _, _ in recipe_properties.RECIPE_PROPERTIES):
            recipe_properties.set_values(settings, after.mapping)
        else:
            recipe_properties.add_to(settings, after.mapping)
    else:
        several = len(scene.carriers) > 1
        settings = features.make_settings(doc, after.scan, after.mapping,
                                          carrier.name if several else None)
        add_sensor_properties(settings, after)
    doc.recompute()
    return {"Carrier": holder, "ScanSettings": settings}
