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
from ..robot.scenario_scan import clearance_added, scan_with_clearance
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
    return scan_with_clearance(layout, engine, lambda chosen: clearance_body(scene, chosen),
                               clearance=clearance, progress=progress, stepper=stepper,
                               measure=measure)


def clearance_body(scene, layout):
    """The body whose clearance SPEC §15 checks: the document's robot (its URDF's collision
    geometry, in its taught start pose) or, without one, the scanner's heads. None when coal
    (which ships with pin) is missing."""
    from ..addon import pinocchio_available

    if not pinocchio_available():
        return None
    from ..robot.clearance import RobotBody, ScannerBody

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
    body.add_carrier(per_scene(scene, ("carrier solids", layout.carrier),
                               lambda: _carrier_solids(scene, layout)))
    return body


def with_clearance(scene, result, body=None):
    """The result with SPEC §15's clearance check of its motions (by ``body``, default
    ``clearance_body``) against the wafers and the scanned carrier's solids, each contact a
    warning; a sweep's motion is the one it made (its pockets' reached angles). Unchanged when
    coal is missing."""
    body = body or clearance_body(scene, result.layout)
    if body is None:  # without pinocchio (and coal): nothing to check with
        return result
    return clearance_added(result, body)


_CONVERTED = []  # [(the carrier's shapes last converted, what names them, their matrices, what
#                    they became)]


def _carrier_solids(scene, layout):
    """The scanned carrier's solids in the world as the robot layer takes them, [(vertices,
    triangles, name)] (``carrier_shapes``): a solid of 6 plane faces and 8 corners goes as its
    corners, triangles None (the robot layer makes a box of a box's, else their hull); any other
    (a curved face bulges beyond its corners' hull) is tessellated to 0.1 mm.

    Each scan reads the document afresh. The same shapes as the last time give the same tuple
    back without reading their corners again (1.3 ms of the paper's 2.5 ms scan), nor their
    solids (the 55 solids of the paper's carrier and their placements, read one by one to
    compare, were a fifth of its clearance check): each shape the carrier shows
    (``_carrier_found``: a built carrier's one compound) OpenCASCADE's partner of the last one
    (the same geometry, its solids and their places in it included) at the same matrix,
    under the same names. Its solids are then the same solids at the same placements, so
    their corners and triangles are the same floats."""
    found = _carrier_found(scene, layout)
    named = _names_key(layout, found)
    # Each location's own matrix (not Placement.Matrix: a matrix made again from a rotation).
    matrices = [shape.Matrix.A for _, shape, _ in found]
    if _CONVERTED:
        known, names, where, converted = _CONVERTED[0]
        if names == named and where == matrices and all(
                shape.isPartner(before) for (_, shape, _), (_, before, _) in zip(found, known)):
            return converted
    solids = []
    for name, solid in _named_solids(layout, found):
        if len(solid.Faces) == 6 and len(solid.Vertexes) == 8 and all(
                type(face.Surface).__name__ == "Plane" for face in solid.Faces):
            solids.append(([(v.X, v.Y, v.Z) for v in solid.Vertexes], None, name))
        else:
            points, triangles = solid.tessellate(0.1)
            solids.append(([(v.x, v.y, v.z) for v in points], triangles, name))
    solids = tuple(solids)
    _CONVERTED[:] = [(found, named, matrices, solids)]
    return solids


def carrier_shapes(scene, layout):
    """[(name, Part solid in the world)] of the scanned carrier: its own shape's solids, or
    those of the untagged objects it holds (not its wafers), as the 3D view shows them. A built
    carrier's are named as ``features.carrier_solids`` makes them (``LP1 wall_left``, ``LP1
    slot 3 ledge_right``), others by their object's label (``FOUP Base``)."""
    return _named_solids(layout, _carrier_found(scene, layout))


def _carrier_found(scene, layout):
    """[(label, the object's shape in the world, whether a built CarrierBody)]: the shapes of
    the scanned carrier that ``carrier_shapes`` takes the solids of."""
    import Part

    from . import roles
    from .features import CarrierBody
    from .reader import carrier_from

    instance = next((i for i in scene.carriers if carrier_from(i).name == layout.carrier),
                    None)
    found = []  # (label, the object's shape in the world, whether a built CarrierBody)

    def walk(sub, obj, depth):
        children = obj.getSubObjects()
        if not children:  # a solid of its own (a link's target's, as the 3D view shows)
            if depth == 0 or roles.role_of(obj) is None:
                holder = roles.role_holder(obj) if depth == 0 else obj
                found.append((obj.Label, Part.getShape(instance.root, sub),
                              isinstance(getattr(holder, "Proxy", None), CarrierBody)))
            return
        for child_sub in children:
            child = obj.getSubObject(child_sub, retType=1)
            if child is not None and depth < 32 and getattr(child, "Visibility", True):
                walk(sub + child_sub, child, depth + 1)

    if instance is not None:
        walk(instance.sub, instance.obj, 0)
    return found


def _names_key(layout, found):
    """What ``_named_solids`` names the solids of ``found`` by, but their count (the same
    shapes have as many): the carrier's name, each shape's label and whether built, and the
    scanned carrier's slot count when one is built."""
    built = any(b for _, _, b in found)
    return (layout.carrier, [(label, b) for label, _, b in found],
            layout.scanned_carrier.slot_count if built else None)


def _named_solids(layout, found):
    """[(name, Part solid in the world)] of the shapes ``found`` (``_carrier_found``), named as
    ``carrier_shapes`` says."""
    shapes = []
    for label, shape, built in found:
        shape_solids = shape.Solids
        names = [f"solid {k}" for k in range(1, len(shape_solids) + 1)]
        if built and len(shape_solids) == 5 + 2 * layout.scanned_carrier.slot_count:
            names = ["wall_left", "wall_right", "wall_back", "floor", "roof"] + [
                f"slot {k} ledge_{side}" for k in range(1, len(shape_solids) // 2 - 1)
                for side in ("left", "right")]  # features.carrier_solids' order
        elif len(shape_solids) == 1:
            names = [""]
        prefix = layout.carrier if built or label == layout.carrier \
            else f"{layout.carrier} {label}"
        shapes += [(f"{prefix} {name}".strip(), solid)
                   for solid, name in zip(shape_solids, names)]
    return shapes


def _robot_read(scene):
    """(URDF path, base, start pose, label) of the scene's robot: read once a scene, as the
    MCS link's commands must not read the same placements again (``stepping.per_scene``)."""
    from . import roles
    from .robot import _joint_dict, _urdf, base_of

    instance = scene.robots[0]  # a scan moves one robot (stepping.mover_for says so)
    holder = roles.role_holder(instance.obj)
    return _urdf(holder), base_of(instance.placement()), _joint_dict(holder), holder.Label
