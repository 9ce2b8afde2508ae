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
