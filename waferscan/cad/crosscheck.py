"""The CAD measurement cross-check: a scan's runs and every wafer's closed-form edges confirmed
with OpenCASCADE's B-rep distance (brep.py), as the paper confirmed its numbers with the CAD
measure tool."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..core.scan.engines import geometric_edges, wafer_edges
from ..core.scan.slow_scan import stepping_layout
from .bowed_solid import bowed_blocked, bowed_wafer_solid
from .brep import TOUCH, brep_blocked
from .clearance_brep import crosscheck_clearance
from .document_scan import scan_document
from .reader import DocumentScene

# The allowed deviation where the beam meets a wafer squarely: OpenCASCADE's touching
# tolerance moves such an edge by about 1e-7 mm.
DEVIATION_FLOOR = 1e-6


@dataclass(frozen=True)
class EdgeCheck:
    wafer: str
    edges: tuple  # closed-form (z_first, z_last), the solid's geometric edges
    brep: tuple  # the same edges found by bisection on OpenCASCADE's distance
    # How far (mm) OpenCASCADE's touching tolerance (TOUCH, 1e-7 mm of distance) moves each
    # edge, in closed form: 1e-7 where the beam meets the wafer squarely, 1e-7 / slope where it
    # grazes the rim (the distance then grows with the slope times the scan travel).
    touch_shift: tuple = (TOUCH, TOUCH)

    @property
    def allowed(self):
        """The largest deviation that still confirms the edges (mm): twice the larger touching
        shift, never below DEVIATION_FLOOR; so only grazing edges get more than 1e-6 mm."""
        return max(DEVIATION_FLOOR, 2.0 * max(self.touch_shift))

    @property
    def ok(self):
        return self.deviation <= self.allowed

    @property
    def deviation(self):
        """Largest difference (mm); infinite when OpenCASCADE did not find the wafer at all."""
        if any(math.isnan(b) for b in self.brep):
            return math.inf
        return max(abs(a - b) for a, b in zip(self.edges, self.brep))


@dataclass(frozen=True)
class RunCheck:
    z_in: float
    z_out: float
    blocked_at_edges: bool  # B-rep: blocked at IN and at OUT
    clear_outside: bool  # B-rep: clear one step below and one step above

    @property
    def ok(self):
        return self.blocked_at_edges and self.clear_outside


@dataclass(frozen=True)
class CrossCheck:
    result: object  # the analytic ScanResult checked
    runs: tuple
    wafers: tuple
    # SPEC §15: each motion's least distance confirmed (clearance_brep.ClearanceCrossCheck);
    # None when not asked for.
    clearance: object = None

    @property
    def largest_deviation(self):
        return max((w.deviation for w in self.wafers), default=0.0)

    @property
    def largest_allowed(self):
        """The allowed deviation of the wafer with the largest deviation (mm)."""
        worst = max(self.wafers, key=lambda w: w.deviation, default=None)
        return DEVIATION_FLOOR if worst is None else worst.allowed

    @property
    def ok(self):
        return (all(r.ok for r in self.runs) and all(w.ok for w in self.wafers)
                and (self.clearance is None or self.clearance.ok))


def _bisect(blocked_at, clear, hit, iterations=60):
    """The scan position between ``clear`` (not blocked) and ``hit`` (blocked) where the beam
    starts to touch, to below 1e-12 mm."""
    for _ in range(iterations):
        middle = 0.5 * (clear + hit)
        if blocked_at(middle):
            hit = middle
        else:
            clear = middle
        if abs(hit - clear) < 1e-12:
            break
    return hit


def crosscheck(doc, result=None, clearance=True):
    """Confirm a stepped analytic scan of the document with OpenCASCADE: every run blocked at its
    first and last step and clear one step outside them, every wafer's closed-form edges
    found again by bisection on the B-rep distance, within the deviation OpenCASCADE's touching
    tolerance explains at that edge (``EdgeCheck.allowed``), and (``clearance``) every motion's
    least distance of SPEC §15 measured again between Part solids (clearance_brep.py).

    The runs are checked at the positions the beam was blocked at, before latching: a latched
    IN/OUT trails them by scan_speed x sensor_response, where the beam need not be blocked."""
    scene = DocumentScene.of(doc)
    result = result or scan_document(doc, "analytic")
    motions = crosscheck_clearance(scene, result) if clearance else None
    if result.layout.spot is not None and not result.layout.spot.ideal:
        # SPEC §10: OpenCASCADE judges geometry, the line beam's edges; a spot's runs are
        # threshold crossings of b(z), which the tests check against closed forms and rays.
        from dataclasses import replace

        from ..core.scan.layout_scan import scan_layout

        result = scan_layout(replace(result.layout, spot=None, amplifier=None))
    # A slow scan's Z steps are made with the fork in, advanced by its jab (SPEC §13): the beam
    # the runs were read with.
    layout = stepping_layout(result.layout)
    scan = layout.scan
    step = scan.z_step if scan.z_step > 0 else 0.01
    solids = [i.shape() for i in scene.wafers]
    tests = [brep_blocked] * len(solids)
    for i, wafer in enumerate(layout.wafers):
        if wafer.bow:  # SPEC §10: the solid of revolution, not the document's disc
            solids[i], tests[i] = bowed_wafer_solid(wafer), bowed_blocked

    def blocked(z, only=None):
        emitter = layout.emitter_at(z)
        chosen = range(len(solids)) if only is None else [only]
        return any(tests[i](solids[i], emitter, layout.beam) for i in chosen)

    runs = []
    for run in result.runs:
        bottom, top = run.unlatched or (run.bottom, run.top)
        at_edges = blocked(bottom) and blocked(top)
        below = bottom - step < scan.start_z or not blocked(bottom - step)
        above = top + step > scan.final_z or not blocked(top + step)
        runs.append(RunCheck(run.z_in, run.z_out, at_edges, below and above))
    wafers = []
    for i, wafer in enumerate(layout.wafers):
        touching = wafer_edges(layout, wafer)
        if touching is None or touching[1] < scan.start_z or touching[0] > scan.final_z:
            continue
        edges = geometric_edges(layout, wafer, touching)
        grown = wafer_edges(layout, wafer, tol=TOUCH)
        shift = (abs(edges[0] - grown[0]), abs(grown[1] - edges[1]))
        lo, hi = edges
        reach = min(step, 0.5 * (hi - lo)) if hi > lo else step
        inside = 0.5 * (lo + hi)
        if not blocked(inside, i):
            wafers.append(EdgeCheck(wafer.name, edges, (float("nan"), float("nan")), shift))
            continue
        brep_lo = _bisect(lambda z: blocked(z, i), lo - reach, inside)
        brep_hi = _bisect(lambda z: blocked(z, i), hi + reach, inside)
        wafers.append(EdgeCheck(wafer.name, edges, (brep_lo, brep_hi), shift))
    return CrossCheck(result, tuple(runs), tuple(wafers), motions)
