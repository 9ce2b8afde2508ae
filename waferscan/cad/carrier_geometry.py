"""A carrier's slots read off a cell's geometry, so that a user need not compute them: slot
count, pitch and slot 1's seat from the carrier's support ledges (the upward faces a wafer rests
on, repeated at every slot) and the wafers' own seats (their bottom faces), in global
coordinates; and the frames a user picks in the 3D view (slot 1's seat, the beam's emitter and
receiver) written into each object's own frame, where its role's properties keep them.

How the proposal is made (``propose_slots``):

- Seats are heights along the carrier's axis, global Z (the axis a scan lifts the sensor along).
- The wafers are those whose centre lies within the carrier's bounding box seen from above
  (X and Y: wafers may stand above a plate or an open cassette; another carrier's say nothing
  of this one). Level wafers (their normal along Z within 0.1 degree) give
  seats: their bottom faces' Z. A tilted wafer (cross-slotted) sits between two seats and is left
  out.
- Support levels: the carrier's upward-facing flat faces grouped by height. The levels that look
  like the one under the lowest level wafer (as many faces, as much area) are the slots' ledges.
  Without wafers, the look that repeats most often is taken.
- The pitch is the common step of the seats: the largest step of which every seat's height
  above the lowest is a whole multiple (within ``TOLERANCE``), refined by least squares.
- With ledges: slot 1 is the lowest ledge level, the slot count the levels from it to the top
  one. With wafers only: slot 1 is the lowest level wafer's seat, and the slot count is how many
  pitches fit between it and the carrier's top (each slot needs a pitch of room above its seat),
  at least up to the top wafer.
- The seat's centre is the level wafers' mean centre (else the ledges' middle); the carrier's
  front (out of its opening, towards the robot) points from that centre to the beam.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import FreeCAD as App
import Part

from ..core.errors import InputError
from . import roles
from .disc import NotADisc, disc_of
from .reader import DocumentScene, document_source
from .scene import scene_instances

TOLERANCE = 0.05  # mm: two seats this close are one; a seat this far off a multiple is off
LEVEL_COSINE = math.cos(math.radians(0.1))  # a wafer whose normal is this close to Z is level
BOUNDS_MARGIN = 1.0  # mm around a carrier's bounding box (X, Y) that its wafers' centres lie within


@dataclass(frozen=True)
class SlotProposal:
    """What the geometry says of a carrier's slots, in global coordinates (mm). ``slot_count``
    and ``pitch`` are None when nothing could be derived; ``how`` says how, in words."""

    slot_count: int | None
    pitch: float | None
    seat: tuple | None  # slot 1's seat centre (x, y, z)
    front: tuple | None  # unit (x, y) out of the opening, towards the beam
    how: str


def common_step(heights, tolerance=TOLERANCE):
    """The largest step of which every height's distance above the lowest is a whole multiple
    (within ``tolerance``), refined by least squares; None for fewer than two distinct
    heights."""
    distinct = []
    for z in sorted(heights):
        if not distinct or z - distinct[-1] > tolerance:
            distinct.append(z)
    if len(distinct) < 2:
        return None
    offsets = [z - distinct[0] for z in distinct[1:]]
    gap = min(b - a for a, b in zip(distinct, distinct[1:]))
    for divisor in range(1, 1 + int(gap / (2 * tolerance))):
        step = gap / divisor
        multiples = [round(d / step) for d in offsets]
        if all(abs(d - n * step) <= tolerance for d, n in zip(offsets, multiples)):
            return sum(n * d for n, d in zip(multiples, offsets)) / sum(n * n for n in multiples)
    return None


def instance_of(obj):
    """The scene instance (global placement and shape) of ``obj`` as the 3D view shows it."""
    for instance in scene_instances(obj.Document):
        if instance.obj is obj:
            return instance
    raise InputError(document_source(obj.Document), None,
                     f"{obj.Label} is not shown in the 3D view: show it first")


def _upward_levels(shape):
    """{height: [face area, ...]} of the shape's flat faces that face up (+Z)."""
    levels = {}
    for face in shape.Faces:
        if not isinstance(face.Surface, Part.Plane):
            continue
        u0, u1, v0, v1 = face.ParameterRange
        if face.normalAt((u0 + u1) / 2, (v0 + v1) / 2).z < LEVEL_COSINE:
            continue
        z = face.BoundBox.ZMin
        key = next((k for k in levels if abs(k - z) <= 1e-6), z)
        levels.setdefault(key, []).append(face)
    return levels


def _look(faces):
    return len(faces), round(sum(f.Area for f in faces), 3)


def _ledge_levels(shape, lowest_seat):
    """The heights of the carrier's support ledges (sorted) and their faces, or ([], {})."""
    levels = _upward_levels(shape)
    if lowest_seat is not None:
        under = [z for z in levels if abs(z - lowest_seat) <= TOLERANCE]
        if not under:
            return [], {}
        look = _look(levels[under[0]])
    else:
        looks = [_look(faces) for faces in levels.values()]
        look = max(set(looks), key=looks.count) if looks else None
        if look is None or looks.count(look) < 2:
            return [], {}
    ledges = sorted(z for z, faces in levels.items() if _look(faces) == look)
    return ledges, levels


def _wafer_seats(doc, bounds):
    """(level wafers' bottom centres, how many tilted ones) of the document's wafers whose
    centre lies within ``bounds`` (the carrier's bounding box) seen from above: another
    carrier's wafers say nothing of this one's slots."""
    level, tilted = [], 0
    for instance in DocumentScene.of(doc).wafers:
        shape = instance.shape()
        centre = shape.BoundBox.Center
        # Seen from above: a carrier's wafers may stand above it (a plate, an open cassette)
        if not (bounds.XMin - BOUNDS_MARGIN <= centre.x <= bounds.XMax + BOUNDS_MARGIN
                and bounds.YMin - BOUNDS_MARGIN <= centre.y <= bounds.YMax + BOUNDS_MARGIN):
            continue
        try:
            center, normal, _, _ = disc_of(shape)
        except NotADisc:
            continue  # a bowed wafer: its rim's seat is not a flat disc's
        if normal[2] >= LEVEL_COSINE:
            level.append(center)
        else:
            tilted += 1
    return level, tilted


def _document_beam(doc):
    scanners = DocumentScene.of(doc).scanners
    if len(scanners) != 1:
        return None
    holder = roles.role_holder(scanners[0].obj)
    placement = scanners[0].placement()
    return placement.multVec(App.Vector(holder.Emitter)), \
        placement.multVec(App.Vector(holder.Receiver))


def front_towards(center, beam):
    """The unit XY direction from ``center`` (x, y, ...) to the nearest point of the line of
    ``beam`` (emitter, receiver: App.Vectors), or None when the beam runs through it."""
    if beam is None:
        return None
    emitter, receiver = beam
    ex, ey = emitter.x, emitter.y
    dx, dy = receiver.x - ex, receiver.y - ey
    length2 = dx * dx + dy * dy
    if length2 == 0.0:
        return None
    t = ((center[0] - ex) * dx + (center[1] - ey) * dy) / length2
    fx, fy = ex + t * dx - center[0], ey + t * dy - center[1]
    norm = math.hypot(fx, fy)
    return None if norm <= TOLERANCE else (fx / norm, fy / norm)


def propose_slots(carrier, beam=None):
    """What ``carrier``'s geometry and the document's wafers say of its slots (a
    SlotProposal, global coordinates); ``beam`` is (emitter, receiver) global, by default the
    document's scanner's. The module's docstring says how."""
    doc = carrier.Document
    shape = instance_of(carrier).shape()
    seats, tilted = _wafer_seats(doc, shape.BoundBox)
    seats.sort(key=lambda c: c[2])
    wafers_said = (f"{len(seats)} level wafers" +
                   (f" ({tilted} tilted left out)" if tilted else ""))
    ledges, levels = _ledge_levels(shape, seats[0][2] if seats else None)
    if len(ledges) >= 2:
        pitch = common_step(ledges)
    else:
        ledges, pitch = [], common_step([c[2] for c in seats])
    if pitch is None:
        what = "no wafers" if not seats else "one seat only"
        return SlotProposal(None, None, None, None,
                            f"{what}, no repeated support ledges: give them by hand")
    if ledges:
        bottom = ledges[0]
        count = round((ledges[-1] - bottom) / pitch) + 1
        how = f"{count} support levels of {carrier.Label}, {pitch:g} mm apart"
        if seats:
            how += f"; {wafers_said} sit on them"
    else:
        bottom = seats[0][2]
        top = round((seats[-1][2] - bottom) / pitch) + 1
        count = max(top, math.floor((shape.BoundBox.ZMax - bottom) / pitch + 1e-6))
        how = (f"the seats of {wafers_said}, {pitch:g} mm apart; slot count from "
               f"{carrier.Label}'s height")
    if seats:
        cx = sum(c[0] for c in seats) / len(seats)
        cy = sum(c[1] for c in seats) / len(seats)
    else:
        middle = Part.makeCompound(levels[bottom]).BoundBox.Center
        cx, cy = middle.x, middle.y
    seat = (cx, cy, bottom)
    front = front_towards(seat, beam if beam is not None else _document_beam(doc))
    return SlotProposal(count, pitch, seat, front, how)


def set_slot_frame(carrier, slot_count, pitch, seat, front=None):
    """Set the carrier's slots: ``slot_count``, ``pitch`` (mm) and slot 1's seat centre
    ``seat`` (a global App.Vector), written into the object's own frame (``SlotOrigin``).
    ``front`` (a global unit XY direction out of the opening) turns the slot frame so that its
    -Y points along it; without it the slot frame keeps its own turn."""
    holder = roles.role_holder(carrier)
    placement = instance_of(carrier).placement()
    inverse = placement.inverse()
    rotation = App.Rotation(holder.SlotOrigin.Rotation)
    if front is not None:
        angle = math.degrees(math.atan2(front[0], -front[1]))
        rotation = inverse.Rotation.multiply(App.Rotation(App.Vector(0, 0, 1), angle))
    holder.SlotCount = int(slot_count)
    holder.Pitch = float(pitch)
    holder.SlotOrigin = App.Placement(inverse.multVec(App.Vector(seat)), rotation)


def set_beam_ends(scanner, emitter, receiver):
    """Set the scanner's beam from ``emitter`` to ``receiver`` (global App.Vectors), written into
    the object's own frame (``Emitter``, ``Receiver``)."""
    holder = roles.role_holder(scanner)
    inverse = instance_of(scanner).placement().inverse()
    holder.Emitter = inverse.multVec(App.Vector(emitter))
    holder.Receiver = inverse.multVec(App.Vector(receiver))
