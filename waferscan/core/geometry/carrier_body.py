"""A built carrier's body (a FOUP-like box of walls, floor, roof and slot ledges) as plain boxes:
what the CAD layer draws (``cad.features.carrier_solids``) and what the clearance check takes
for obstacles when a scenario is scanned without its document (SPEC §15). One description, so
the drawn solids and the checked ones are the same numbers."""

from __future__ import annotations

import math

WALL = 4.0  # mm: walls, floor and roof
RIM_CLEARANCE = 6.0  # mm from the wafer's rim to a side wall
LEDGE_THICKNESS = 1.5  # mm: a slot's support ledge, its top at the slot's seat


def carrier_boxes(slot_count, pitch, wafer_diameter, support_span):
    """[(name, corner (x, y, z), size (dx, dy, dz))] in the carrier's frame (origin at slot 1's
    seat centre, X across, -Y out of the opening, Z up), each box from its lowest corner: the
    side walls, the back wall, the floor, the roof, then a left and a right support ledge under
    every slot, their inner edges ``support_span`` apart. Names as the clearance report gives
    them (``wall_left``, ``slot 3 ledge_right``)."""
    r = wafer_diameter / 2.0
    wall = WALL
    inner = r + RIM_CLEARANCE
    front, back = -r - 5.0, r + 10.0
    # The opening leaves the fork room above the top slot and below the first: a stroke from
    # 1.4 pitches under slot 1's seat to 1.6 over the top slot's (the paper's 280 to 550, its
    # tines 4 mm tall) stays 5 mm or more from the floor and the roof (SPEC §15).
    bottom, top = -2.0 * pitch - wall, (slot_count + 1.5) * pitch
    height = top - bottom
    boxes = [
        ("wall_left", (-inner - wall, front, bottom), (wall, back - front, height)),
        ("wall_right", (inner, front, bottom), (wall, back - front, height)),
        ("wall_back", (-inner - wall, back, bottom), (2 * (inner + wall), wall, height)),
        ("floor", (-inner - wall, front, bottom), (2 * (inner + wall), back - front + wall, wall)),
        ("roof", (-inner - wall, front, top), (2 * (inner + wall), back - front + wall, wall)),
    ]
    ledge_depth, ledge_thickness = 1.1 * r, LEDGE_THICKNESS
    ledge_width = inner - support_span / 2.0
    for slot in range(slot_count):
        seat = slot * pitch
        for side, x in (("left", -inner), ("right", support_span / 2.0)):
            boxes.append((f"slot {slot + 1} ledge_{side}",
                          (x, -ledge_depth / 2.0, seat - ledge_thickness),
                          (ledge_width, ledge_depth, ledge_thickness)))
    return boxes


def box_corners(corner, size):
    """A box's eight corners in the order OpenCASCADE lists a ``Part.makeBox``'s vertices (x
    low then high; within each, y low then high; within each, z high then low), each far side
    as the corner plus the size: the same numbers a built carrier's solids read back."""
    (x, y, z), (dx, dy, dz) = corner, size
    return [(a, b, c) for a in (x, x + dx) for b in (y, y + dy) for c in (z + dz, z)]


def carrier_box_corners(carrier):
    """[(corners, name)] of the carrier's body in the world: ``carrier_boxes`` turned to the
    carrier's ``front`` and moved to its slot 1 seat centre, named ``<carrier> <box>`` as the
    document's are (``cad.document_scan.carrier_shapes``). A carrier facing -Y (unturned) gives
    exactly its document's numbers; a turned one agrees with them to rounding."""
    fx, fy = carrier.front
    # The frame turns local -Y onto ``front`` (cad.builder.carrier_placement).
    angle = math.atan2(fx, -fy)
    c, s = math.cos(angle), math.sin(angle)
    cx, cy = carrier.center
    cz = carrier.first_slot_z
    solids = []
    for name, corner, size in carrier_boxes(carrier.slot_count, carrier.pitch,
                                            carrier.wafer_diameter, carrier.support_span):
        if angle == 0.0:
            corners = [(x + cx, y + cy, z + cz) for x, y, z in box_corners(corner, size)]
        else:
            corners = [(c * x - s * y + cx, s * x + c * y + cy, z + cz)
                       for x, y, z in box_corners(corner, size)]
        solids.append((corners, f"{carrier.name} {name}"))
    return solids
