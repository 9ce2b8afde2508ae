"""A block start to finish (drawn, scanned and compared with what was placed) and a partition's
tally of its blocks: the confusion counts, the per-layout moments the intervals need, the
weakest peak of a beam spot and the margins, counted block by block."""

from __future__ import annotations

from .. import mapping
from ..mapping import CROSS, DOUBLE, POSITION_ERROR, PRESENT, THIN
from .block_scan import UNSCANNED, needs_scalar_path, scalar_block, scan_block, spot_block
from .draws import block_size, draw_block
from .margins import MARGINS_KEPT, MarginTally

# Summary names, indexed by state code (SPEC §12).
STATE_KEYS = ("empty", "present", "cross", "double", "thin", "position_error", "protruding",
              "unscanned")


# --- a block, start to finish ----------------------------------------------------------------

def sweep_block(base, tolerances, seed, block, count, scalar=False):
    """Draw, scan and map block ``block`` (``count`` layouts). Returns a dict of arrays:
    ``truth``, ``reported`` (m, S codes), ``thickness``, ``bottom`` (m, S, nan without a run).
    ``scalar``: through the scalar path (the oracle)."""
    draws = draw_block(base, tolerances, seed, block, count)
    peaks = []
    spot = base.layout.spot
    if scalar:
        states, thickness, bottom = scalar_block(base, draws, peaks)
    elif spot is not None and not spot.ideal:
        # The block at once (core/sweep/spot_scan.py): the scalar path's answers, bit for bit.
        states, thickness, bottom = spot_block(base, draws, peaks)
    elif needs_scalar_path(base.layout):
        states, thickness, bottom = scalar_block(base, draws, peaks)
    else:
        states, thickness, bottom = scan_block(base, draws)
    # The weakest signal a wafer gave: a beam spot's smallest peak blocked fraction over the
    # groups of wafers it saw; the ideal beam blocks all or nothing (1).
    weakest = min(peaks) if peaks else 1.0
    result = {"truth": draws.truth, "reported": states, "thickness": thickness,
              "bottom": bottom, "weakest_peak": weakest}
    if base.clearance is not None:  # the [clearance] report (core/sweep/clearance.py)
        from .clearance import block_clearance

        result["clearance"] = block_clearance(base.clearance, draws, base.carrier.slot_count)
    return result


# The columns of ``layout_moments``' per-layout vector of each state.
TRUE_SLOTS, REPORTED_SLOTS, CORRECT_SLOTS, HOLDS_STATE, LACKS_STATE, ONE_LAYOUT = range(6)


def layout_moments(truth, reported):
    """What the rates' intervals need of the layouts (rows of ``truth`` and ``reported``, state
    codes (m, S)): for each state s (0..7) the sums over layouts of v vᵀ, v the layout's vector
    (slots truly s, slots reported s, slots truly and reported s, 1 if it holds a slot truly s,
    1 if it holds a slot not truly s, 1), an (8, 6, 6) integer array. A rate's count and its
    trials in one layout are differences of these counts, so the sums of their squares and
    products over layouts are sums of these entries (``rate_intervals``). Integers: partitions
    add them up in any order to the same numbers."""
    import numpy as np

    m, S = truth.shape
    rows = np.arange(m, dtype=np.int64)[:, None] * 8
    cells = 8 * m
    at = rows + truth
    slots_true = np.bincount(at.ravel(), minlength=cells).reshape(m, 8).T
    v = np.empty((8, m, 6))
    v[..., TRUE_SLOTS] = slots_true
    v[..., REPORTED_SLOTS] = np.bincount((rows + reported).ravel(), minlength=cells).reshape(m, 8).T
    v[..., CORRECT_SLOTS] = np.bincount(at[truth == reported], minlength=cells).reshape(m, 8).T
    v[..., HOLDS_STATE] = slots_true > 0
    v[..., LACKS_STATE] = slots_true < S
    v[..., ONE_LAYOUT] = 1.0
    # In floats for the speed of a matrix product; every entry is a whole number below
    # 2**53 (a block's layouts x S²), so every sum of products is exact, in any order.
    return np.matmul(v.transpose(0, 2, 1), v).astype(np.int64)


def block_tally(base, result):
    """What a block adds to a sweep's summary: the confusion counts (8 x 8: truth x reported),
    and the measured thickness and offset from the seat of the slots by their true state (under
    "boundary" rules the offset of the run's centre from the slot's reference, seat + t/2, as
    those rules judge position)."""
    import numpy as np

    truth = result["truth"].astype(np.int64)
    reported = result["reported"].astype(np.int64)
    # (np.add.at's counts by a bincount of the cells: integers, the same numbers)
    confusion = np.bincount((truth * 8 + reported).ravel(), minlength=64).reshape(8, 8)
    moments = layout_moments(truth, reported)
    plan = base.plan
    seats = np.array([plan.seat_z(s) for s in range(1, plan.slot_count + 1)])
    thickness = result["thickness"]
    if plan.rules == mapping.BOUNDARY:
        # The position those rules judge: the run's centre against the slot's reference.
        offset = (result["bottom"] + 0.5 * thickness) - (seats[None, :]
                                                         + 0.5 * plan.wafer_thickness)
    else:
        offset = result["bottom"] - seats[None, :]
    if plan.thickness_correction != 1.0:
        thickness = thickness / plan.thickness_correction
    measured = {}
    # A slot's own run: not a cross-slotted run from a neighbour, not half a pitch off its seat.
    own = ~np.isnan(thickness) & (reported != CROSS) & (reported != UNSCANNED) & \
        (np.abs(offset) < 0.5 * plan.pitch)
    for code in (PRESENT, THIN, DOUBLE, POSITION_ERROR):
        sel = (truth == code) & own
        measured[STATE_KEYS[code]] = (thickness[sel], offset[sel])
    out = {"confusion": confusion, "moments": moments, "measured": measured,
           "weakest_peak": result.get("weakest_peak", 1.0)}
    if "clearance" in result:
        out["clearance"] = result["clearance"]
    return out


def combine_tallies(tallies):
    """The tallies of blocks (in block order) as one: counts added, measures concatenated in
    block order, so the result does not depend on how the blocks were grouped."""
    import numpy as np

    confusion = sum(t["confusion"] for t in tallies)
    moments = sum(t["moments"] for t in tallies)
    weakest = min(t.get("weakest_peak", 1.0) for t in tallies)
    measured = {}
    for key in tallies[0]["measured"]:
        measured[key] = (np.concatenate([t["measured"][key][0] for t in tallies]),
                         np.concatenate([t["measured"][key][1] for t in tallies]))
    return {"confusion": confusion, "moments": moments, "measured": measured,
            "weakest_peak": weakest}


def block_tallies(base, tolerances, seed, n, blocks):
    """The ``block_tally`` of each of ``blocks``, one block at a time (drawn, scanned and
    dropped: a partition's memory does not grow with its blocks)."""
    for b in blocks:
        yield block_tally(base, sweep_block(base, tolerances, seed, b, block_size(n, b)))


def _ends(values, ends):
    """(min, max) of ``values`` and the earlier ``ends`` (None: none yet)."""
    if not len(values):
        return ends
    low, high = float(values.min()), float(values.max())
    return (low, high) if ends is None else (min(ends[0], low), max(ends[1], high))


def partition_tally(base, tolerances, seed, n, blocks):
    """The given blocks (a partition) of an N-layout sweep, reduced to what the summary reads:
    the confusion counts, the weakest peak, the extremes of the readings the suggested recipe
    is built from, and the margins of the truly present wafers (core/sweep/margins.py's
    MarginTally: their distinct values with counts, or a histogram of them), counted block by
    block in memory that does not grow with N: a kind of margin whose distinct values outgrow
    its MarginTally is kept whole, sorted, in a sweep of at most MARGINS_KEPT slots.
    ``source`` is what draws the blocks again when the reduction needs margins a histogram does
    not hold (``reduce_partitions``)."""
    import numpy as np

    confusion = np.zeros((8, 8), dtype=np.int64)
    moments = np.zeros((8, 6, 6), dtype=np.int64)
    weakest = None
    extremes = dict.fromkeys(("thickness", "offset", "thin_thickness", "double_thickness",
                              "misplaced_offset"))
    margins = {"thickness": MarginTally(), "position": MarginTally()}
    clearance = None
    if base.clearance is not None:  # the layouts' least distances: one more kind of margin
        margins["clearance"] = MarginTally()
        clearance = {"layouts": 0, "contacts": 0,
                     "by_part": np.zeros(len(base.clearance.body.parts), dtype=np.int64),
                     "by_slot": np.zeros(base.carrier.slot_count, dtype=np.int64)}
    # Each block's margins, kept when the whole sweep cannot hold more than MARGINS_KEPT of a
    # kind (one per slot and layout): a kind whose distinct values outgrow its MarginTally then
    # needs no second pass over the blocks (margins.py). Decided by N before the first block,
    # so that neither a partition's memory nor all partitions' together (held until the
    # reduction) grows past it, however many partitions there are.
    keep = n * base.carrier.slot_count <= MARGINS_KEPT
    kept = {key: [] if keep else None for key in margins}
    for tally in block_tallies(base, tolerances, seed, n, blocks):
        confusion += tally["confusion"]
        moments += tally["moments"]
        if clearance is not None:
            for key in clearance:
                clearance[key] = clearance[key] + tally["clearance"][key]
        peak = tally.get("weakest_peak", 1.0)
        weakest = peak if weakest is None else min(weakest, peak)
        measured = tally["measured"]
        th, off = measured["present"]
        for name, values in (("thickness", th), ("offset", off),
                             ("thin_thickness", measured["thin"][0]),
                             ("double_thickness", measured["double"][0]),
                             ("misplaced_offset", np.abs(measured["position_error"][1]))):
            extremes[name] = _ends(values, extremes[name])
        for key, values in margin_values(base.plan, tally).items():
            margins[key].add(values)
            if kept[key] is not None:
                kept[key].append(values)
    for key, held in kept.items():
        if held is not None and not margins[key].exact:
            # Every margin of this kind, sorted: what reduction.py reads of a partition that
            # kept them all, the same order statistics as the histogram's second pass.
            margins[key] = np.sort(np.concatenate(held)) if held else np.empty(0)
    out = {"confusion": confusion, "moments": moments,
           "weakest_peak": 1.0 if weakest is None else weakest,
           "extremes": extremes, "margins": margins,
           "source": (base, tolerances, seed, n, blocks)}
    if clearance is not None:
        out["clearance"] = clearance
    return out


def partition_margins(source):
    """A partition's margins again, block by block, from its ``source`` (``partition_tally``'s):
    for each block {"thickness": sorted array, "position": sorted array}, the same floats as
    the first time (each block's draws depend only on the seed and its index)."""
    import numpy as np

    base = source[0]
    for tally in block_tallies(*source):
        yield {key: np.sort(values) for key, values in margin_values(base.plan, tally).items()}


def margin_values(plan, tally):
    """The thickness and position margins (mm, > 0 inside the recipe's windows) of every truly
    present wafer the scan saw: {"thickness": array, "position": array}."""
    import numpy as np

    low, high = plan.thickness_window()
    below, above = plan.position_window()
    th, off = tally["measured"]["present"]
    out = {"thickness": np.minimum(th - low, high - th),
           "position": np.minimum(off + below, above - off)}
    if "clearance" in tally:  # each layout's least distance to the body (mm)
        out["clearance"] = tally["clearance"]["least"]
    return out
