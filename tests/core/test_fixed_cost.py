"""The analytic scan's per-wafer fast paths (issue 15: the fixed cost of ``scan_layout`` on a
fab) give exactly what their plain definitions give: the level wafer's edges written out in one
body against ``translation_range``, the settled steps with the scan's values worked out once
against the formula wafer by wafer, and the carrier's wafers against ``Wafer.mid_center`` and
their protrusion against the solid's frontmost point. Bit for bit (``==`` on floats),
degenerate beams included."""

import math
import random

from random_layouts import random_layout

from waferscan.core.geometry.beam import TOUCH_TOLERANCE, accessible, accessible_wafers
from waferscan.core.mapping import LIMIT_SLACK, SlotPlan, unscanned_slots
from waferscan.core.model import Beam, Carrier, Layout, ScanParameters, Wafer
from waferscan.core.scan.engines import SETTLED_MARGIN, level_edger, settler, wafer_edges
from waferscan.core.scan.scan_result import carrier_protrusions, carrier_wafers, protrusion


def _level_layout(rng, emitter, heading, length, step=0.05):
    direction = (math.cos(heading), math.sin(heading), 0.0)
    if rng.random() < 0.2:  # along an axis: exact zeros in the direction
        direction = rng.choice([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0)])
    carrier = Carrier("C1", 25, 10.0, 100.0, (0.0, 0.0), 300.0, 0.775)
    return Layout((carrier,), (), Beam(emitter, direction, length),
                  ScanParameters(emitter[2], emitter[2] + 300.0, step))


def _level_wafer(rng, near):
    x, y = near
    return Wafer("W", (x + rng.uniform(-200, 200), y + rng.uniform(-200, 200),
                       rng.uniform(-50.0, 400.0)),
                 (0.0, 0.0, 1.0), rng.choice([150.0, 200.0, 300.0, rng.uniform(1.0, 450.0)]),
                 rng.uniform(0.1, 2.0))


def test_level_edges_are_translation_ranges_bit_for_bit():
    met = missed = 0
    for seed in range(3000):
        rng = random.Random(seed)
        emitter = (rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(0, 300))
        layout = _level_layout(rng, emitter, rng.uniform(-math.pi, math.pi),
                               rng.choice([rng.uniform(1.0, 600.0), 160.0]))
        wafer = _level_wafer(rng, emitter[:2])
        if seed % 5 == 0:
            # The beam's line through the wafer's axis, or beside it at right angles (p.q = 0),
            # or just grazing the rim: the roots' degenerate and boundary cases.
            ex, ey, _ = layout.beam.direction
            side = rng.choice([0.0, wafer.radius, wafer.radius + 1e-9, wafer.radius * 0.5])
            center = (emitter[0] - ey * side, emitter[1] + ex * side, wafer.center[2])
            wafer = Wafer("W", center, (0.0, 0.0, 1.0), wafer.diameter, wafer.thickness)
        for tol in (1e-9, 0.0):
            expected = wafer_edges(layout, wafer, tol)
            assert level_edger(layout, tol)(wafer) == expected, (seed, tol)
            met += expected is not None
            missed += expected is None
    assert met > 1000 and missed > 1000  # both answers exercised


def _settled_by_definition(layout, edges):
    """The settled steps as SPEC'd in engines.settled_steps, term by term, wafer by wafer."""
    scan = layout.scan
    size = max(1.0, abs(scan.start_z), abs(scan.final_z), abs(layout.beam.emitter[2]),
               abs(edges[0]), abs(edges[1]))
    margin = SETTLED_MARGIN * size / scan.z_step
    x0 = (edges[0] - scan.start_z) / scan.z_step
    x1 = (edges[1] - scan.start_z) / scan.z_step
    lo, hi = math.ceil(x0), math.floor(x1)
    if min(lo - x0, x0 - lo + 1, x1 - hi, hi + 1 - x1) <= margin:
        return None
    lo, hi = max(0, lo), min(scan.last_step, hi)
    return (lo, hi) if lo <= hi else None


def test_settled_steps_worked_out_once_a_scan_are_the_formula():
    settled = unsettled = 0
    for seed in range(2000):
        rng = random.Random(seed)
        step = rng.choice([0.001, 0.05, 0.013, 1.0])
        start = rng.choice([0.0, 280.0, -5.0, 1500.0])
        emitter = (0.0, 0.0, start)
        layout = _level_layout(rng, emitter, 0.0, 160.0, step).with_scan(
            final_z=start + rng.uniform(0.0, 400.0))
        low = start + rng.uniform(-20.0, 420.0)
        if rng.random() < 0.3:  # an edge on the grid, or a hair off it
            low = start + step * rng.randint(0, 400) + rng.choice([0.0, 1e-13, -1e-13])
        high = low + rng.uniform(0.0, 2.0)
        if rng.random() < 0.3:
            high = start + step * rng.randint(0, 400) + rng.choice([0.0, 1e-13, -1e-13])
        edges = (low, max(low, high))
        expected = _settled_by_definition(layout, edges)
        assert settler(layout)(edges) == expected, seed
        settled += expected is not None
        unsettled += expected is None
    assert settled > 300 and unsettled > 300


def test_carrier_wafers_are_the_mid_centre_definition_and_protrusion_the_solids_front():
    found = left = 0
    for seed in range(300):
        layout = random_layout(random.Random(seed))
        for carrier in layout.carriers:
            r = 0.5 * carrier.wafer_diameter
            z_lo = carrier.seat_z(1) - carrier.pitch
            z_hi = carrier.seat_z(carrier.slot_count) + carrier.pitch
            expected = [w for w in layout.wafers
                        if math.hypot(w.mid_center[0] - carrier.center[0],
                                      w.mid_center[1] - carrier.center[1]) < r
                        and z_lo <= w.mid_center[2] <= z_hi]
            assert list(carrier_wafers(carrier, layout.wafers)) == expected, seed
            found += len(expected)
            left += len(layout.wafers) - len(expected)
            for wafer in layout.wafers:
                # the solid's frontmost point (issue 24): its rim's, the top rim's when the
                # wafer is tilted towards the front (random layouts' bows are too small for a
                # frontmost point inside the rim: scan_result.front_reach)
                cx, cy, _ = wafer.center
                nx, ny, _ = wafer.normal
                along = nx * carrier.front[0] + ny * carrier.front[1]
                assert wafer.bow * along <= 0.0 or math.sqrt(1.0 - along * along) * \
                    wafer.radius ** 2 / (2.0 * wafer.bow * along) >= wafer.radius
                reach = ((cx - carrier.center[0]) * carrier.front[0]
                         + (cy - carrier.center[1]) * carrier.front[1])
                reach += wafer.radius * math.sqrt(max(0.0, 1.0 - along * along)) \
                    + max(0.0, wafer.thickness * along)
                assert protrusion(carrier, wafer) == reach - 0.5 * carrier.wafer_diameter
    assert found > 500 and left > 500


def test_carrier_protrusions_are_protrusion_of_the_carrier_wafers():
    """The one pass of protruding_slots (level wafers without their zero terms, and left out by
    X or Y alone) gives each carrier wafer's ``protrusion`` bit for bit, also for level wafers
    placed a hair inside and outside the carrier's circle along X and Y, where the box around
    the circle is tight."""
    inside = outside = 0
    for seed in range(300):
        rng = random.Random(seed)
        layout = random_layout(rng)
        for carrier in layout.carriers:
            r = 0.5 * carrier.wafer_diameter
            edge_wafers = []
            for k in range(8):
                offset = r + rng.choice([0.0, 1e-9, -1e-9, 1e-7, -1e-7, 2e-6, -2e-6, 1e-3])
                dx, dy = rng.choice([(offset, 0.0), (-offset, 0.0), (0.0, offset),
                                     (0.0, -offset)])
                edge_wafers.append(Wafer(f"E{k}", (carrier.center[0] + dx, carrier.center[1] + dy,
                                                   carrier.seat_z(1)),
                                         (0.0, 0.0, 1.0), carrier.wafer_diameter, 0.775))
            wafers = layout.wafers + tuple(edge_wafers)
            expected = [(w, protrusion(carrier, w)) for w in wafers
                        if math.hypot(w.mid_center[0] - carrier.center[0],
                                      w.mid_center[1] - carrier.center[1]) < r
                        and carrier.seat_z(1) - carrier.pitch <= w.mid_center[2]
                        <= carrier.seat_z(carrier.slot_count) + carrier.pitch]
            assert carrier_protrusions(carrier, wafers) == expected, seed
            inside += sum(1 for w, _ in expected if w.name.startswith("E"))
            outside += len(edge_wafers) - sum(1 for w, _ in expected if w.name.startswith("E"))
    assert inside > 300 and outside > 300


def test_the_box_around_the_beam_leaves_out_only_what_the_accessibility_check_does():
    """accessible_wafers leaves a level wafer out by X or Y alone when its centre lies further
    from the beam's box than its reach: wafers a hair either side of that reach, beside each
    end of the beam and along its sides, are kept exactly when ``accessible`` keeps them."""
    kept = dropped = 0
    for seed in range(1500):
        rng = random.Random(seed)
        emitter = (rng.uniform(-300, 300), rng.uniform(-300, 300), 280.0)
        layout = _level_layout(rng, emitter, rng.uniform(-math.pi, math.pi),
                               rng.choice([rng.uniform(1.0, 600.0), 160.0]))
        beam = layout.beam
        ends = [emitter, tuple(o + beam.length * d for o, d in zip(emitter, beam.direction))]
        wafers = []
        for k in range(12):
            diameter = rng.choice([150.0, 300.0, rng.uniform(1.0, 450.0)])
            reach = diameter / 2.0 + 10.0 * TOUCH_TOLERANCE
            end = rng.choice(ends)
            offset = reach + rng.choice([0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6, -1e-6, 3e-6])
            dx, dy = rng.choice([(offset, 0.0), (-offset, 0.0), (0.0, offset), (0.0, -offset)])
            wafers.append(Wafer(f"W{k}", (end[0] + dx, end[1] + dy, rng.uniform(275.0, 285.0)),
                                (0.0, 0.0, 1.0), diameter, 0.775))
        scan = layout.scan
        expected = [i for i, w in enumerate(wafers)
                    if accessible(layout, w, scan.start_z, scan.final_z)]
        assert accessible_wafers(layout, wafers, scan.start_z, scan.final_z) == expected, seed
        kept += len(expected)
        dropped += len(wafers) - len(expected)
    assert kept > 3000 and dropped > 3000


def test_unscanned_slots_are_the_windows_outside_the_scanned_range():
    """unscanned_slots answers "none" at once when the first and last windows are inside (the
    windows rise with the slot): the same slots as testing every window, ranges a hair inside
    and outside the windows' ends included."""
    for seed in range(3000):
        rng = random.Random(seed)
        plan = SlotPlan(rng.randint(1, 30), rng.choice([4.76, 6.35, 10.0, 10.02]),
                        rng.uniform(50.0, 400.0), 0.775, 0.3, 0.5)
        bottom, top = plan.window(1)[0], plan.window(plan.slot_count)[1]
        hair = rng.choice([0.0, 1e-12, -1e-12, 1e-9, -1e-9, 2e-9, -2e-9, 1.0, -1.0])
        low = rng.choice([bottom - hair, bottom + rng.uniform(-30.0, 30.0)])
        high = rng.choice([top + hair, top + rng.uniform(-30.0, 30.0)])
        expected = [slot for slot in range(1, plan.slot_count + 1)
                    if plan.window(slot)[0] < low - LIMIT_SLACK
                    or plan.window(slot)[1] > high + LIMIT_SLACK]
        assert unscanned_slots(plan, (low, high)) == expected, seed
