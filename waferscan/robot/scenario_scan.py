"""A scenario (.toml) scanned without building its FreeCAD document, and the scan-with-clearance
steps that the document's scan (``cad.document_scan.scan_document``) takes too.

``waferscan scan X.toml`` with an engine that reads the layout (not ``document`` or ``brep``)
and no ``--store`` needs nothing from a document: the scan is the core's, and SPEC §15's
clearance check takes its robot's pose and the carrier's solids from the same numbers the
document's builder draws them from (``robot.kinematics.WaferRobot.teach_start_pose``,
``core.geometry.carrier_body.carrier_boxes``). The layout is the one its document reads back
(``as_document_reads``): no wafer keeps the slot it was loaded into, no robot spec, so every
report counts and names as the document's scan does. What reads back from the document differs
only in rounding (a wafer's thickness from its solid, the beam from the robot's forward
kinematics: ~1e-14 mm), below every printed figure but not below JSON's full floats (the
command keeps --json on the document).

A figure found by a search to a tolerance is another matter: a search that decides one step
differently on numbers 1e-14 apart stops elsewhere, 1e-4° or 1e-3 mm away, and that is printed.
So only a fast scan whose every stroke's clearance is coal's exact distance of the swept parts
goes without the document; a slow scan (its jabs', sweeps' and turn limits' searches), a stroke
that overlaps something (searched), parameters or a robot the document refuses (its own
messages) raise ``NeedsDocument``, and the document's path answers as it always has. FreeCAD is
never imported here; pinocchio and coal only when the clearance check runs.
"""

from __future__ import annotations

from dataclasses import replace

from ..core.scan.layout_scan import scan_layout


class NeedsDocument(Exception):
    """The scenario needs its document to be scanned as ``waferscan scan`` always scanned it:
    building the document reports what is wrong (a robot it cannot build) in its own words."""


def seated_layout(layout):
    """The layout with a wafer seated in every slot of its scanned carrier, and no other: what
    a recipe (a sweep's turn limits) is judged against."""
    from ..core.scan.slow_scan import seated_wafer

    carrier = layout.scanned_carrier
    return replace(layout, wafers=tuple(seated_wafer(carrier, slot)
                                        for slot in range(1, carrier.slot_count + 1)))


def scan_with_clearance(layout, engine, make_body, clearance=True, **options):
    """``scan_layout(layout, engine, **options)`` with SPEC §15's clearance: a slow scan's sweeps
    turn only as far as the fork stays clear (SPEC §13 amended), and every motion is checked
    (``clearance_added``). ``make_body(layout)``: the clearance body of a layout (its robot's
    collision geometry, or the scanner's heads, with the carrier's solids), None without coal."""
    sweeping = clearance and layout.scan.mode == "slow" and layout.scan.sweep > 0.0
    body = limits = None
    if sweeping:
        from ..core.scan.clearance import turn_limits

        body = make_body(layout)
        if body is not None:
            limits = turn_limits(body, layout.mapping.clearance_min,
                                 seated=lambda: make_body(seated_layout(layout)))
    result = scan_layout(layout, engine, turn_limits=limits, **options)
    if sweeping and body is None:
        from ..addon import missing_pinocchio_message

        result = replace(result, warnings=result.warnings + (
            f"the sweeps turned the whole ±{layout.scan.sweep:g}°, their clearance unchecked: "
            f"{missing_pinocchio_message()}",))
    if not clearance:
        return result
    body = body or make_body(result.layout)
    return result if body is None else clearance_added(result, body)


def clearance_added(result, body):
    """The result with SPEC §15's clearance check of its motions by ``body``, each contact a
    warning; a sweep's motion is the one it made (its pockets' reached angles)."""
    from ..core.mapping import UNSCANNED
    from .clearance import clearance_for

    probes = {p.slot: p for p in result.pockets}
    pockets = [probes.get(s.slot, s.slot) for s in result.slot_map.slots
               if s.state != UNSCANNED]
    report = clearance_for(result.layout, body, pockets)
    return replace(result, clearance=report, warnings=result.warnings + report.warnings())


def as_document_reads(layout):
    """The scenario's layout as its built document reads back: wafers without the carrier and
    slot they were loaded into (a document's wafer is only its solid), no robot spec (the
    robot is in the document, its pose taught)."""
    return replace(layout, robot=None,
                   wafers=tuple(replace(w, carrier=None, slot=None) for w in layout.wafers))


def robot_pose(spec, beam, lift_axis):
    """(URDF or None, base ((x, y, z) mm, yaw deg), start joint values) of a scenario's
    [robot], as the document's builder teaches and stores it (``cad.robot.build_robot``: its
    start pose puts the beam on ``beam``). ``NeedsDocument`` where the builder would refuse
    it: the builder's message is the one to give."""
    from ..addon import pinocchio_available

    if not pinocchio_available():
        raise NeedsDocument("pinocchio is missing")
    try:
        from .clearance import collision_model

        robot = collision_model(spec.urdf)[0]
        robot.limits[robot.lift_joint]  # noqa: B018 (the builder refuses a robot without one)
        base = (tuple(spec.base), spec.base_yaw)
        joints = robot.teach_start_pose(base, beam.emitter, beam.direction)
        _, _, length = robot.beam(joints, base)
        axis = robot.lift_axis(base)
    except Exception as exc:  # noqa: BLE001 (whatever it is, the builder reports it)
        raise NeedsDocument(str(exc)) from None
    # The builder's own refusals (cad.robot.check_sensor): a beam the fork cannot hold, a lift
    # axis the robot does not move along.
    if abs(length - beam.length) > 1e-6 or (
            lift_axis is not None and max(abs(a - b) for a, b in zip(axis, lift_axis)) > 1e-9):
        raise NeedsDocument("the [sensor] contradicts the [robot]")
    # Stored in the document as a float list, one value per joint in the model's order.
    start = {name: float(joints.get(name, 0.0)) for name in robot.joint_names}
    return spec.urdf, base, start


def scenario_body(layout, pose, carrier):
    """SPEC §15's clearance body of a scenario's layout (``as_document_reads``): its robot at
    ``pose`` (``robot_pose``) or, without one, the scanner's heads; the scanned carrier's body
    (``core.geometry.carrier_body``) as obstacles. None without coal (it ships with pin)."""
    from ..addon import pinocchio_available

    if not pinocchio_available():
        return None
    from .clearance import RobotBody, ScannerBody

    if pose is not None:
        urdf, base, start = pose
        try:
            body = RobotBody(layout, urdf=urdf, base=base, start=start)
        except (ValueError, KeyError, RuntimeError, OSError) as exc:
            raise NeedsDocument(str(exc)) from None  # named by the document's robot there
    else:
        body = ScannerBody(layout)
    body.add_carrier(carrier)
    return body


_BOXES = []  # [(the scanned carrier, its solids)]: the same tuple for the same carrier


def carrier_solids(layout):
    """The scanned carrier's built body in the world as the clearance check takes a carrier's
    solids ([(corners, None, name)]: a box given by its eight corners), the same tuple again for
    the same carrier (the robot layer then makes its coal boxes once)."""
    from ..core.geometry.carrier_body import carrier_box_corners

    carrier = layout.scanned_carrier
    if not _BOXES or _BOXES[0][0] != carrier:
        _BOXES[:] = [(carrier, tuple((corners, None, name)
                                     for corners, name in carrier_box_corners(carrier)))]
    return _BOXES[0][1]


def scan_scenario(path, engine, parameters=None, progress=None, check=None):
    """Scan the scenario ``path`` as ``cad.document_scan.scan_document`` scans its built document,
    without building it: ``parameters`` (a core ``mcs.Parameters``) override its scan settings,
    ``check(layout)`` may refuse the layout before the scan. Returns the core ``ScanResult``.

    ``NeedsDocument`` where only the document's path answers as it always has: parameters or a
    robot the document refuses (its messages), and a scan whose printed figures depend on more
    than rounding: a slow scan (its jabs' and sweeps' clearance, and how far a sweep turns, are
    searched to a tolerance, and a search that decides one step differently stops elsewhere),
    or a fast stroke that overlaps something (searched the same way). What stays is a fast scan
    whose every stroke's clearance is coal's exact distance of the swept parts."""
    from ..core.errors import InputError
    from ..core.files.mcs import apply_parameters
    from ..core.files.scenario import read_scenario

    scenario = read_scenario(path)
    layout = as_document_reads(scenario)
    if parameters is not None:
        try:
            layout = apply_parameters(layout, parameters)
        except InputError:
            raise NeedsDocument("parameters") from None  # after the document's own errors
    if layout.scan.mode != "fast":
        raise NeedsDocument("a slow scan")
    pose = None
    if scenario.robot is not None:
        pose = robot_pose(scenario.robot, scenario.beam, scenario.lift_axis)
    if check is not None:
        check(layout)
    carrier = carrier_solids(layout)
    return scan_with_clearance(layout, engine,
                               lambda chosen: _swept_only(scenario_body(chosen, pose, carrier)),
                               progress=progress)


def _swept_only(body):
    """``body``, its clearance answered by swept shapes only (``NeedsDocument`` where a motion
    is not: a stroke that overlaps a wafer or a solid is searched instead)."""
    if body is None:
        return None
    swept = body.swept

    def in_one_piece(motion):
        closest = swept(motion)
        if closest is None:
            raise NeedsDocument("a motion's clearance searched, not swept")
        return closest

    body.swept = in_one_piece
    return body
