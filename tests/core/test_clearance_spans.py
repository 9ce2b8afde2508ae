"""A long translation's clearance search leaves out the spans its body sweeps clear by more than
the search can reach (core/scan/clearance.py ``_clear_spans``): the same Closest, to the last
bit, as sampling every millimetre, with far fewer distances asked. The bodies here are made of
cones along the motion (the distance at s is the least of a_k + |s - c_k|: what a part passing
an obstacle sees, one millimetre a millimetre), whose sweep over a span is its exact minimum.
The robot's bodies (coal): tests/robot/test_clearance_band.py."""

import heapq
import math
import random

import pytest

from waferscan.core.scan import clearance as core
from waferscan.core.scan.clearance import Closest, Motion


def reference_least_along(body, motion, clearance_min, tolerance=core.TOLERANCE,
                          per_unit=core.SAMPLES_PER_MM, budget=core.MAX_EVALUATIONS):
    """The search as it was before spans (issue 30): every first sample taken."""
    swept = body.swept(motion)
    if swept is not None:
        return swept
    a, b = motion.start, motion.end
    count = max(1, int(math.ceil(abs(b - a) * per_unit)))
    grid = [a + (b - a) * i / count for i in range(count + 1)]
    values = [body.nearest(motion, s) for s in grid]
    best_s, best = min(zip(grid, values), key=lambda sv: sv[1][0])
    heap = []

    def push(s0, v0, s1, v1):
        heapq.heappush(heap, (0.5 * (v0[0] + v1[0] - body.path(motion, s0, s1)), s0, s1, v0, v1))

    for (s0, v0), (s1, v1) in zip(zip(grid, values), zip(grid[1:], values[1:])):
        push(s0, v0, s1, v1)
    evaluations = len(grid)
    exact = True
    while heap:
        bound, s0, s1, v0, v1 = heap[0]
        fraction = core.CONTACT_RELATIVE if best[0] < clearance_min else core.RELATIVE
        slack = max(tolerance, fraction * abs(best[0] - clearance_min))
        if (bound >= best[0] - slack and (bound >= clearance_min or best[0] < clearance_min)) \
                or abs(s1 - s0) < 1e-12:
            break
        if evaluations >= budget:
            exact = False
            break
        heapq.heappop(heap)
        mid = 0.5 * (s0 + s1)
        vm = body.nearest(motion, mid)
        evaluations += 1
        if vm[0] < best[0]:
            best_s, best = mid, vm
        push(s0, v0, mid, vm)
        push(mid, vm, s1, v1)
    distance, part, obstacle, slot = best
    if not exact:
        distance = min(distance, heap[0][0])
    return Closest(motion, float(distance), float(best_s), part, obstacle,
                   motion.slot if slot is None else slot, exact)


class Cones:
    """A body whose distance at s is min_k a_k + |s - c_k| (obstacle k, in slot k + 1), bent
    a little so that samples are not all on round values; it sweeps a span to that span's
    exact minimum, and the whole motion only when ``whole`` (a robot's body sweeps it whole
    when nothing overlaps)."""

    def __init__(self, cones, whole=True, bend=0.0):
        self.cones = cones
        self.whole = whole
        self.bend = bend
        self.asked = 0
        self.motion = None

    def _at(self, s, k):
        a, c = self.cones[k]
        return a + abs(s - c) + self.bend * math.sin(s) ** 2

    def nearest(self, motion, s):
        self.asked += 1
        k = min(range(len(self.cones)), key=lambda k: self._at(s, k))
        return (self._at(s, k), "tine", f"wafer_{k}", k + 1)

    def path(self, motion, s0, s1):
        return abs(s1 - s0) * (1.0 + 2.0 * self.bend)  # bend: sin² moves at most 1 a mm

    def swept(self, motion):
        lo, hi = sorted((motion.start, motion.end))
        if (lo, hi) == tuple(sorted((self.motion.start, self.motion.end))) and not self.whole:
            return None
        least = min(a + max(lo - c, 0.0, c - hi) for a, c in self.cones)  # bend >= 0
        if least <= 0.0:
            return None
        return Closest(motion, least, lo, "tine", "swept", None)


def _stroke(length, up=True):
    start, end = (280.0, 280.0 + length) if up else (280.0 + length, 280.0)
    return Motion(core.STROKE, "fast stroke up" if up else "fast stroke down", None, start, end)


def _both(body, motion, clearance_min):
    body.motion = motion
    body.asked = 0
    reference = reference_least_along(body, motion, clearance_min)
    asked = body.asked
    body.asked = 0
    found = core.least_along(body, motion, clearance_min)
    return reference, asked, found, body.asked


@pytest.mark.parametrize("seed", range(40))
def test_spans_give_every_samples_answer(seed):
    """Random cones along strokes of 300 to 6,000 mm, up and down, with contacts or without,
    clearance_min from 0.2 to 5 mm: the same Closest as sampling every millimetre."""
    rng = random.Random(seed)
    length = rng.uniform(300.0, 6000.0)
    cones = [(rng.uniform(-3.0, 8.0) if rng.random() < 0.3 else rng.uniform(0.5, 8.0),
              280.0 + rng.uniform(0.0, length)) for _ in range(rng.randint(1, 40))]
    body = Cones(cones, whole=rng.random() < 0.5, bend=rng.choice([0.0, 0.0, 0.3]))
    motion = _stroke(length, up=rng.random() < 0.5)
    reference, asked, found, asked_now = _both(body, motion, rng.uniform(0.2, 5.0))
    assert found == reference
    assert asked_now <= asked


def test_a_stroke_through_one_contact_asks_few_distances():
    """A 20 m stroke that meets one obstacle (a roof it runs into) and passes 2.5 mm from
    wafers every 10 mm: the first samples of the clear spans are left out."""
    cones = [(2.5, 280.0 + 10.0 * k) for k in range(2000)] + [(-4.9, 9000.0)]
    body = Cones(cones)
    reference, asked, found, asked_now = _both(body, _stroke(20_000.0), 1.0)
    assert found == reference and found.distance == -4.9 and found.obstacle == "wafer_2000"
    assert asked > 20_000 and asked_now < asked / 10


def test_a_span_the_search_reaches_means_every_sample():
    """Should the refinement ever reach a span's bound, every sample is taken and the search
    made again (the spans the search keeps cannot be reached; spans given a bound too low
    are)."""
    cones = [(2.5, 280.0 + 10.0 * k) for k in range(300)] + [(1.2, 1500.0)]
    body = Cones(cones, whole=False)
    motion = _stroke(3000.0)
    body.motion = motion
    reference = reference_least_along(body, motion, 1.0)
    count = 3000
    grid = [motion.start + (motion.end - motion.start) * i / count for i in range(count + 1)]
    low = [(0, 64, -10.0), (64, 128, -10.0)]  # bounds any interval's would pass
    assert core._refined(body, motion, 1.0, core.TOLERANCE, core.MAX_EVALUATIONS, grid, {},
                         low) is None
    saved = core._clear_spans
    core._clear_spans = lambda *args: low
    try:
        assert core.least_along(body, motion, 1.0) == reference
    finally:
        core._clear_spans = saved


def test_a_turn_is_never_cut_into_spans():
    """Spans are a translation's: a jab or a sweep is sampled as before."""
    body = Cones([(3.0, 0.0)], whole=False)
    motion = Motion(core.SWEEP, "sweep", 4, -400.0, 400.0, z=300.0, advance=10.0)
    body.motion = motion
    assert core._clear_spans(body, motion, [float(s) for s in range(-400, 401)], 1.0, {}) == []
