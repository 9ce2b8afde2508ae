"""Random layouts for the engine and geometry tests: several carriers with random loads
(cross-slotted wafers, stacks, thin, raised, protruding), free wafers tilted every way, tilted
beams, tilted lift axes, and slot seats that sometimes fall exactly on the step grid."""

import math

from waferscan.core.files.scenario import seated_wafers
from waferscan.core.model import (
    Beam,
    Carrier,
    Layout,
    MappingTolerances,
    ScanParameters,
    Wafer,
    unit,
)

STEPS = (0.05, 0.1, 0.013, 0.25, 0.5, 1.0)


def _random_load(rng, slots):
    digits = []
    while len(digits) < slots:
        roll = rng.random()
        if roll < 0.12 and len(digits) + 2 <= slots:
            digits += ["cross", None]
        else:
            digits.append(rng.choice(["absent", "present", "present", "double", "thin",
                                      "misplaced", "protruding"]))
    return {slot: state for slot, state in enumerate(digits, start=1) if state is not None}


def random_layout(rng, max_steps=2000):
    """A random but plausible layout; ``rng`` is a ``random.Random``."""
    step = rng.choice(STEPS)
    carriers, wafers = [], []
    for index in range(rng.randint(1, 4)):
        diameter = rng.choice([150.0, 200.0, 300.0])
        pitch = rng.choice([4.76, 6.35, 10.0])
        slots = rng.randint(1, 13)
        first = 100.0 + rng.uniform(0.0, 30.0)
        if rng.random() < 0.3:
            first = 100.0 + step * rng.randint(0, int(30 / step))  # seats on the grid
        angle = rng.uniform(-0.3, 0.3)
        carrier = Carrier(
            name=f"C{index + 1}", slot_count=slots, pitch=pitch, first_slot_z=first,
            center=(index * 420.0 + rng.uniform(-5, 5), 400.0 + rng.uniform(-5, 5)),
            wafer_diameter=diameter, wafer_thickness=rng.uniform(0.3, 1.2),
            front=(math.sin(angle), -math.cos(angle)),
            support_span=diameter - rng.uniform(2.0, 12.0))
        carriers.append(carrier)
        n = 1
        for slot, state in sorted(_random_load(rng, slots).items()):
            made = seated_wafers(carrier, slot, state, n)
            wafers += made
            n += len(made)
    scanned = carriers[0]
    r = scanned.wafer_diameter / 2.0
    depth = rng.uniform(2.0, 40.0)
    y_beam = scanned.center[1] - (r - depth)
    heading = rng.uniform(-0.35, 0.35)
    tilt = rng.choice([0.0, 0.0, rng.uniform(-0.15, 0.15)])
    direction = unit((math.cos(heading), math.sin(heading), tilt))
    length = rng.uniform(0.8, 1.6) * 2.0 * math.sqrt(r * r - (r - depth) ** 2) + 40.0
    top = scanned.seat_z(scanned.slot_count) + 2 * scanned.pitch
    start = scanned.first_slot_z - rng.uniform(5.0, 20.0)
    count = int((top - start) / step)
    final = start + min(count, max_steps) * step + rng.choice([0.0, step / 3])
    emitter = (scanned.center[0] - length / 2.0 * direction[0], y_beam, start)
    for k in range(rng.randint(0, 6)):  # free wafers, tilted every way, some in stacks
        normal = unit((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0.05, 1.0)))
        base = (scanned.center[0] + rng.uniform(-60, 60), scanned.center[1] + rng.uniform(-60, 60),
                rng.uniform(start - 5.0, final + 5.0))
        thickness = rng.uniform(0.2, 2.0)
        wafers.append(Wafer(f"F{k}", base, normal, rng.uniform(100.0, 300.0), thickness))
        if rng.random() < 0.3:  # a second wafer lying on the first
            on_top = tuple(b + thickness * c for b, c in zip(base, normal))
            wafers.append(Wafer(f"F{k}s", on_top, normal, rng.uniform(100.0, 300.0), thickness))
    lift = (0.0, 0.0, 1.0) if rng.random() < 0.7 else unit((rng.uniform(-0.08, 0.08),
                                                             rng.uniform(-0.08, 0.08), 1.0))
    scan = ScanParameters(start_z=start, final_z=final, z_step=step)
    return Layout(carriers=tuple(carriers), wafers=tuple(wafers),
                  beam=Beam(emitter, direction, length), scan=scan, lift_axis=lift,
                  mapping=MappingTolerances(), carrier=scanned.name)


# Shared by tests/core/test_fab_fast_paths.py and tests/core/test_fab_shared_pass.py.
LEVEL = (0.0, 0.0, 1.0)
HAIRS = (0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-8, -1e-8, 1.1e-8, -1.1e-8, 1e-6, -1e-6, 3e-6)


def shared_stacks(rng):
    """A level scan and wafers in stacks whose members share their centre's X and Y and their
    diameter (the objects), the stacks interleaved: at the beam's box, the beam's ends, grazing
    the rim, at the carrier's circle, and inside, and stacks that share some of these objects
    with another; members above, inside and below the scan's range, some bowed, some tilted
    (sharing the stack's X and Y too)."""
    heading = rng.uniform(-math.pi, math.pi)
    direction = rng.choice([(math.cos(heading), math.sin(heading), 0.0), (1.0, 0.0, 0.0),
                            (0.0, -1.0, 0.0)])
    length = rng.choice([160.0, rng.uniform(1.0, 400.0)])
    emitter = (rng.uniform(-100, 100), rng.uniform(150, 300), 280.0)
    start, final = 280.0, 280.0 + rng.choice([30.0, 270.0])
    carrier = Carrier("C1", 25, 10.0, 290.0, (rng.uniform(-50, 50), 400.0 + rng.uniform(-50, 50)),
                      300.0, 0.775, front=unit((rng.uniform(-0.3, 0.3), -1.0, 0.0))[:2])
    ex, ey, _ = direction
    ends = [emitter[:2], (emitter[0] + length * ex, emitter[1] + length * ey)]
    stacks = []
    for _ in range(rng.randint(3, 8)):
        diameter = rng.choice([300.0, 200.0, rng.uniform(1.0, 450.0)])
        r = diameter / 2.0
        hair = rng.choice(HAIRS)
        where = rng.choice(["box", "end", "rim", "circle", "inside"])
        if where == "box":  # beside an end, off along X or Y by its reach (+ the check's 1e-8)
            x, y = rng.choice(ends)
            off = r + 1e-8 + 1e-6 * rng.choice([0, 1]) + hair
            dx, dy = rng.choice([(off, 0.0), (-off, 0.0), (0.0, off), (0.0, -off)])
            x, y = x + dx, y + dy
        elif where == "end":  # beyond an end, along the beam
            (x, y), sign = rng.choice([(ends[0], -1.0), (ends[1], 1.0)])
            x, y = x + sign * (r + hair) * ex, y + sign * (r + hair) * ey
        elif where == "rim":  # beside the beam's middle, by its radius (+ the touch tolerance)
            side = r + rng.choice([0.0, 1e-9]) + hair
            x = emitter[0] + 0.5 * length * ex - ey * side
            y = emitter[1] + 0.5 * length * ey + ex * side
        elif where == "circle":  # at the carrier's circle, along X or Y
            off = 150.0 + rng.choice([0.0, 1e-6]) + hair
            dx, dy = rng.choice([(off, 0.0), (-off, 0.0), (0.0, off), (0.0, -off)])
            x, y = carrier.center[0] + dx, carrier.center[1] + dy
        else:
            x, y = carrier.center[0] + rng.uniform(-3, 3), carrier.center[1] + rng.uniform(-3, 3)
        stacks.append((float(x), float(y), float(diameter)))
    # stacks that share some of another's objects (its X, its Y or its diameter), not all
    for _ in range(rng.randint(1, 4)):
        x, y, diameter = rng.choice(stacks)
        other = rng.choice(["x", "y", "diameter"])
        if other == "x":
            x = float(x + rng.choice([1e-9, 20.0, -0.5]))
        elif other == "y":
            y = float(y + rng.choice([1e-9, 20.0, -0.5]))
        else:
            diameter = float(diameter + rng.choice([1e-9, 40.0, -0.5]))
        stacks.append((x, y, diameter))
    tilted = unit((0.02, -0.01, 1.0))
    wafers = []
    for k in range(rng.randint(10, 60)):
        x, y, diameter = rng.choice(stacks)
        z = rng.choice([rng.uniform(start - 3.0, final + 3.0), start - 1.0, final + 0.5,
                        290.0 + 10.0 * rng.randint(0, 24)])
        normal = tilted if rng.random() < 0.1 else LEVEL
        bow = rng.choice([0.0] * 8 + [0.05, -0.05])
        wafers.append(Wafer(f"W{k}", (x, y, z), normal, diameter, rng.choice([0.775, 0.3, 1.5]),
                            rng.choice(["C1", "C1", None, "C2"]), bow=bow))
    scan = ScanParameters(start, final, rng.choice([0.05, 0.013, 0.001, 0.5]))
    return Layout((carrier,), tuple(wafers), Beam(emitter, direction, length), scan)
