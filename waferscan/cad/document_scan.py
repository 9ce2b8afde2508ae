"""Scans through the FreeCAD document, as the paper does through the CAD API.

``scan_document(doc, engine)`` reads the document into a core ``Layout`` and scans it. With the
``document`` engine every step goes through the document: move the scanner (or set the robot's
lift joint), then read the scanner's and every wafer's global placement back and test. With the
``brep`` engine the test is OpenCASCADE's (see ``brep``). Other engines scan the layout read.
"""

from __future__ import annotations

from ..core.errors import InputError
from ..core.files.mcs import apply_parameters
from ..core.geometry.beam import beam_hits_wafer
from ..core.scan.engines import CAD_ENGINES
from ..core.scan.layout_scan import scan_layout
from .reader import DocumentScene, read_layout
from .stepping import framed_wafers, mover_for, per_scene, stepper_through_document


def document_stepper(scene, mover):
    """The ``document`` engine: the paper's procedure through the document API, every wafer's
    placement read back at every step and tested exactly."""

    def prepare(layout, reachable):
        framed = framed_wafers(scene, layout, reachable)
        return lambda beam: [i for i, wafer in framed.items()
                             if beam_hits_wafer(beam.emitter, beam, wafer.wafer_now())]

    return stepper_through_document(scene, mover, prepare)


def scan_document(doc, engine="analytic", progress=None, parameters=None, check=None,
                  read=None, clearance=True):
    """Read the document and scan it. ``parameters`` (a core ``mcs.Parameters``) override the
    document's own scan settings; ``check(layout)`` may refuse the layout before the scan;
    ``read`` is (scene, layout) already read from this document, unchanged since (the MCS
    link's cache); ``clearance``: check SPEC §15's clearance of the scan's motions
    (``with_clearance``). Returns the core ``ScanResult``."""
    if read is not None:
        scene, layout = read
    else:
        scene = DocumentScene.of(doc)
        # The scanner's LiftAxis says how the scan moves it (the robot's builder writes its
        # lift joint's axis there): reading needs no kinematics, so pinocchio stays unimported.
        layout = read_layout(doc, scene)
    if parameters is not None:
        layout = apply_parameters(layout, parameters)
    if check is not None:
        check(layout)
    stepper = measure = None
    if engine in CAD_ENGINES:
        mover = mover_for(scene, layout)
        from .pocket_probe import for_document  # SPEC §13: a slow scan's jab and sweep

        mover, measure = for_document(scene, mover, layout, engine)
        if engine == "document":
            stepper = document_stepper(scene, mover)
        else:
            from .brep import brep_stepper  # Part's B-rep tools load only for this engine
            stepper = brep_stepper(scene, mover)
    result = scan_layout(layout, engine, progress=progress, stepper=stepper, measure=measure)
    return with_clearance(scene, result) if clearance else result


def with_clearance(scene, result):
    """The result with SPEC §15's clearance check of its motions: by the document's robot
    (its URDF's collision geometry, in its taught start pose) or, without one, the scanner's
    heads; each contact a warning. Unchanged when coal (which ships with pin) is missing."""
    from dataclasses import replace

    from ..addon import pinocchio_available

    if not pinocchio_available():
        return result
    from ..core.mapping import UNSCANNED
    from ..robot.clearance import RobotBody, ScannerBody, clearance_for

    layout = result.layout
    if scene.robots:
        urdf, base, start, label = per_scene(scene, "robot for clearance",
                                             lambda: _robot_read(scene))
        try:
            body = RobotBody(layout, urdf=urdf, base=base, start=start)
        except (ValueError, KeyError, RuntimeError, OSError) as exc:
            from .robot import load_robot

            load_robot(urdf, label)  # names a URDF it cannot read, as a scan does
            raise InputError(label, None, f"cannot check the robot's clearance: "
                             f"{str(exc).strip()[:200]}") from None
    else:
        body = ScannerBody(layout)
    pockets = [s.slot for s in result.slot_map.slots if s.state != UNSCANNED]
    report = clearance_for(layout, body, pockets)
    return replace(result, clearance=report, warnings=result.warnings + report.warnings())


def _robot_read(scene):
    """(URDF path, base, start pose, label) of the scene's robot: read once a scene, as the
    MCS link's commands must not read the same placements again (``stepping.per_scene``)."""
    from . import roles
    from .robot import _joint_dict, _urdf, base_of

    instance = scene.robots[0]  # a scan moves one robot (stepping.mover_for says so)
    holder = roles.role_holder(instance.obj)
    return _urdf(holder), base_of(instance.placement()), _joint_dict(holder), holder.Label
