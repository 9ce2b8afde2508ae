"""The partitions' tallies reduced to one, wherever they ran: the counts added and the margins'
order statistics found exactly from small digests (``LocalPartitions`` runs them here, one after
another; a Dask runner elsewhere)."""

from __future__ import annotations

import math

from .draws import block_count
from .margins import (
    COARSE_SHIFT,
    BracketTally,
    MarginTally,
    fine_bin_bracket,
    fine_bins,
    key_value,
    order_keys,
)
from .tally import partition_margins

# The percentiles the summary gives of each kind of margin.
PERCENTILES = (1, 5, 50, 95, 99)


# --- reducing the partitions ------------------------------------------------------------------
#
# The summary needs the margins' order statistics (min, percentiles, max) over every partition,
# exactly. Rather than bring every partition's margins to one place (40 MB for 100,000
# layouts, and a sort there that no worker shares), each partition sends a digest of bounded
# size; the digests bound each wanted order statistic between two values (a bracket), and each
# partition then sends how many of its margins lie below the bracket and those inside it, as
# distinct values with counts. A partition with too many distinct values there sends a
# histogram of the bracket instead, which narrows the bracket for another round (at most four:
# core/sweep/margins.py). The same numbers as sorting everything in one place.
#
# A partition's margins take one of three forms: a sorted array (a partition that kept them
# all), a MarginTally of distinct values with counts, or a MarginTally's histogram, whose
# partition draws and scans its blocks again to answer (partition_margins).

DIGEST_STRIDE = 256
MARGIN_BINS = 60


def _sorted(margins):
    return not isinstance(margins, MarginTally)


def partition_digest(part, stride=None):
    """A partition without its margins: its counts and extremes, and of each kind of margin the
    count, the smallest, the largest and a digest of bounded size: of a sorted array every
    ``stride``-th value from the smallest (default DIGEST_STRIDE); of a MarginTally its
    distinct values with counts, or the non-empty bins of its histogram."""
    import numpy as np

    stride = stride or DIGEST_STRIDE
    out = {k: part[k] for k in ("confusion", "moments", "weakest_peak", "extremes")}
    if "clearance" in part:
        out["clearance"] = part["clearance"]
    out["margins"] = {}
    for key, values in part["margins"].items():
        if _sorted(values):
            digest = {"count": len(values), "stride": stride,
                      "samples": values[::stride].copy(),
                      "min": float(values[0]) if len(values) else None,
                      "max": float(values[-1]) if len(values) else None}
        else:
            digest = {"count": values.count, "min": values.low if values.count else None,
                      "max": values.high if values.count else None}
            if values.exact and len(values.values) > values.count // stride + 1:
                # Many distinct values (readings off the step grid, up to DISTINCT_LIMIT): the
                # stride-th values of them all, as of a sorted array, not every one with its
                # count (8 partitions of a 100,000-layout sweep sent ~2 million to the client,
                # 0.6 s of a 3 s sweep on two workers). A digest only brackets the ranks.
                distinct, counts = values.values, values.counts
                at = np.searchsorted(np.cumsum(counts), np.arange(0, values.count, stride),
                                     side="right")
                digest.update(stride=stride, samples=distinct[at])
            elif values.exact:
                digest.update(values=values.values, counts=values.counts)
            else:
                bins = np.flatnonzero(values.coarse)
                digest.update(bins=bins, bin_counts=values.coarse[bins])
        out["margins"][key] = digest
    return out


def _candidates(kind):
    """The values at which a digest bounds how many margins lie below."""
    import numpy as np

    if "samples" in kind:
        return kind["samples"]
    if "values" in kind:
        return kind["values"]
    bins = kind["bins"].astype(np.uint64)
    keys = np.concatenate([bins << np.uint64(COARSE_SHIFT),
                           ((bins + np.uint64(1)) << np.uint64(COARSE_SHIFT)) - np.uint64(1)])
    return np.array([key_value(k) for k in keys])


def _steps(kind):
    """One partition's digest as the steps of its two bounds: ((values, steps) by
    which "how many margins lie below v, at most" rises as v passes each value, (values, steps)
    by which "how many lie at or below v, at least" rises as v reaches each)."""
    import numpy as np

    count = kind["count"]
    if "samples" in kind:
        sample, stride = np.asarray(kind["samples"], dtype=float), kind["stride"]
        # Below v at most k * stride (k samples below v), all of them past the last sample;
        # at or below v at least (k - 1) * stride + 1 (k samples up to v), 0 before the first.
        most = np.full(len(sample), stride, dtype=np.int64)
        most[-1] = count - (len(sample) - 1) * stride
        least = np.full(len(sample), stride, dtype=np.int64)
        least[0] = 1
        return (sample, most), (sample, least)
    if "values" in kind:
        values = np.asarray(kind["values"], dtype=float)
        counts = np.asarray(kind["counts"], dtype=np.int64)
        return (values, counts), (values, counts)
    # A histogram of order keys: a bin counts below v (at most) once v passes its first key,
    # at or below v (at least) once v reaches its last.
    bins = np.asarray(kind["bins"]).astype(np.uint64)
    counts = np.asarray(kind["bin_counts"], dtype=np.int64)
    starts = np.array([key_value(k) for k in bins << np.uint64(COARSE_SHIFT)], dtype=float)
    ends = np.array([key_value(k) for k in ((bins + np.uint64(1)) << np.uint64(COARSE_SHIFT))
                     - np.uint64(1)], dtype=float)
    return (starts, counts), (ends, counts)


def _summed(pieces, candidates, side):
    """The sum over the partitions of a bound at each candidate: every partition's steps
    merged into one sorted list and added up once (O(candidates log candidates), however many
    partitions), instead of each partition's bound looked up at every candidate (O(partitions
    x candidates): 7.2 s a kind of margin for 10 M layouts over 400 partitions)."""
    import numpy as np

    values = np.concatenate([v for v, _ in pieces])
    steps = np.concatenate([c for _, c in pieces])
    order = np.argsort(values, kind="stable")
    values = values[order]
    total = np.concatenate([[0], np.cumsum(steps[order])])
    return total[np.searchsorted(values, candidates, side=side)]


def _brackets(digests, key, ranks):
    """For each 0-based rank r of the margins ``key`` of every partition together, values
    (low, high) with low <= the r-th smallest <= high, from the partitions' digests, within
    the margins' smallest and largest. The bounds are each partition's summed over the partitions
    (``_summed``: the same integers)."""
    import numpy as np

    kinds = [d["margins"][key] for d in digests if d["margins"][key]["count"]]
    smallest = min(kind["min"] for kind in kinds)
    largest = max(kind["max"] for kind in kinds)
    candidates = np.unique(np.concatenate([_candidates(kind) for kind in kinds]))
    steps = [_steps(kind) for kind in kinds]
    below_at_most = _summed([most for most, _ in steps], candidates, "left")   # margins < v
    up_to_at_least = _summed([least for _, least in steps], candidates, "right")  # <= v
    out = []
    for r in ranks:
        i = int(np.searchsorted(below_at_most, r, side="right")) - 1
        j = int(np.searchsorted(up_to_at_least, r + 1, side="left"))
        low = float(candidates[i]) if i >= 0 else -math.inf
        high = float(candidates[j]) if j < len(candidates) else math.inf
        out.append((max(low, smallest), min(high, largest)))
    return out


def partition_details(part, brackets, edges):
    """What a partition adds to the order statistics and histograms: for each kind of margin
    and each (low, high) of ``brackets[key]``, (how many of its margins lie below low, those
    from low to high as distinct values, their counts) — readings on the step grid repeat: a
    block's ~11,000 thickness margins hold ~26 values — or, with more distinct values there
    than a MarginTally keeps, (below, None, their histogram over ``margins.fine_bins(low,
    high)``); and its histogram over ``edges[key]`` (numpy.histogram's bins), where ``edges``
    has the key. A partition that keeps only a histogram of its margins draws its blocks
    again (``tally.partition_margins``)."""
    import numpy as np

    out = {}
    redrawn = {}
    for key, values in part["margins"].items():
        pieces = []
        hist = None
        if _sorted(values):
            for low, high in brackets.get(key, ()):
                a = int(np.searchsorted(values, low, side="left"))
                b = int(np.searchsorted(values, high, side="right"))
                pieces.append((a, *np.unique(values[a:b], return_counts=True)))
            if edges.get(key) is not None:
                hist = np.histogram(values, bins=edges[key])[0]
        elif values.exact:
            cum = np.concatenate([[0], np.cumsum(values.counts)])
            for low, high in brackets.get(key, ()):
                a = int(np.searchsorted(values.values, low, side="left"))
                b = int(np.searchsorted(values.values, high, side="right"))
                pieces.append((int(cum[a]), values.values[a:b], values.counts[a:b]))
            if edges.get(key) is not None:
                hist = np.histogram(values.values, bins=edges[key], weights=values.counts)[0]
        else:
            redrawn[key] = [BracketTally(low, high) for low, high in brackets.get(key, ())]
            if edges.get(key) is not None:
                hist = np.zeros(len(edges[key]) - 1, dtype=np.int64)
        out[key] = {"selected": pieces, "histogram": hist}
    if redrawn:
        for block in partition_margins(part["source"]):
            for key, tallies in redrawn.items():
                for tally in tallies:
                    tally.add(block[key])
                if out[key]["histogram"] is not None:
                    out[key]["histogram"] += np.histogram(block[key], bins=edges[key])[0]
        for key, tallies in redrawn.items():
            out[key]["selected"] = [tally.piece() for tally in tallies]
    return out


def _narrowed(pieces, bracket, r):
    """A narrower bracket of the r-th smallest margin from pieces of which one at least is a
    histogram over ``margins.fine_bins(*bracket)``: the bin holding it."""
    import numpy as np

    low, high = bracket
    first, width, bins = fine_bins(low, high)
    totals = np.zeros(bins, dtype=np.int64)
    for piece in pieces:
        if piece[1] is None:
            totals += piece[2]
        elif len(piece[1]):
            at = ((order_keys(piece[1]) - np.uint64(first)) // np.uint64(width)).astype(np.int64)
            np.add.at(totals, at, piece[2])
    below = sum(p[0] for p in pieces)
    index = int(np.searchsorted(np.cumsum(totals), r - below, side="right"))
    return fine_bin_bracket(low, high, index)


def _nth_between(pieces, r):
    """The r-th smallest margin (0-based, of every partition) from the partitions' pieces of
    one bracket: (how many lie below it, its distinct values, their counts)."""
    import numpy as np

    below = sum(p[0] for p in pieces)
    values = np.concatenate([p[1] for p in pieces])
    counts = np.concatenate([p[2] for p in pieces])
    distinct, where = np.unique(values, return_inverse=True)
    totals = np.zeros(len(distinct), dtype=np.int64)
    np.add.at(totals, where.ravel(), counts)
    return float(distinct[np.searchsorted(np.cumsum(totals), r - below, side="right")])


def linear_percentile(count, p, nth):
    """The p-th percentile of ``count`` values whose k-th smallest (0-based) is ``nth(k)``, by
    linear interpolation between the order statistics at (count - 1) p / 100 (numpy's default
    method, with its rounding: the same floats as numpy.percentile of the values)."""
    g = (count - 1) * (p / 100)
    if g >= count - 1:
        return nth(count - 1)
    k = math.floor(g)
    t = g - k
    low, high = nth(k), nth(k + 1)
    step = high - low
    return high - step * (1 - t) if t >= 0.5 else low + step * t


def _wanted_ranks(count):
    """The 0-based ranks linear_percentile reads for PERCENTILES of ``count`` values."""
    ranks = set()
    for p in PERCENTILES:
        linear_percentile(count, p, lambda k: ranks.add(k) or 0.0)
    return sorted(ranks)


class LocalPartitions:
    """Runs a sweep's partitions in this process, one after the other (a sweep's ``runner``;
    waferscan.sweep has the Dask one). ``run`` returns handles to the partitions' results, kept
    where they were computed; ``apply`` calls a function on each and brings back its answers."""

    def run(self, function, args, progress=None):
        results = []
        for i, a in enumerate(args):
            results.append(function(*a))
            if progress:
                progress(i + 1, len(args))
        return results

    def apply(self, function, handles, *extra):
        return [function(h, *extra) for h in handles]


def reduce_partitions(runner, handles, histograms=False):
    """The partitions' results (``runner``'s handles) as one tally: counts added, extremes
    taken, and of each kind of margin its distribution (count, min, PERCENTILES, max) and,
    with ``histograms``, its histogram in MARGIN_BINS equal bins from min to max (counts,
    edges). Exact whatever the partitions: the order statistics are the margins' own."""
    import numpy as np

    digests = runner.apply(partition_digest, handles)
    confusion = sum(d["confusion"] for d in digests)
    moments = sum(d["moments"] for d in digests)
    weakest = min(d["weakest_peak"] for d in digests)
    extremes = {}
    for name in digests[0]["extremes"]:
        found = [d["extremes"][name] for d in digests if d["extremes"][name] is not None]
        extremes[name] = ((min(f[0] for f in found), max(f[1] for f in found)) if found
                          else None)
    counts, ends, ranks, around, edges = {}, {}, {}, {}, {}
    for key in digests[0]["margins"]:
        held = [d["margins"][key] for d in digests if d["margins"][key]["count"]]
        counts[key] = sum(h["count"] for h in held)
        if not held:
            continue
        ends[key] = (min(h["min"] for h in held), max(h["max"] for h in held))
        ranks[key] = _wanted_ranks(counts[key])
        around[key] = _brackets(digests, key, ranks[key])  # one for each rank
        if histograms:
            edges[key] = np.histogram_bin_edges(ends[key], bins=MARGIN_BINS)
    nth, hists = _order_statistics(runner, handles, ranks, around, edges)
    clearance = None
    if "clearance" in digests[0]:  # integer counts: the same sums in any order
        clearance = {key: sum(d["clearance"][key] for d in digests)
                     for key in digests[0]["clearance"]}
    margins = {}
    for key, count in counts.items():
        if count == 0:
            margins[key] = None
            continue
        dist = {"count": int(count), "min": ends[key][0]}
        for p in PERCENTILES:
            dist[f"p{p}"] = float(linear_percentile(count, p,
                                                    lambda r, key=key: nth[key, r]))
        dist["max"] = ends[key][1]
        margins[key] = dist
    out = {"confusion": confusion, "moments": moments, "weakest_peak": weakest,
           "extremes": extremes,
           "margins": margins, "histograms": hists}
    if clearance is not None:
        out["clearance"] = clearance
    return out


def _order_statistics(runner, handles, ranks, around, edges):
    """{(key, rank): the rank-th smallest margin ``key``} from the partitions, starting from
    the brackets ``around[key]`` (one for each of ``ranks[key]``), and the histograms over
    ``edges`` (counts, edges). Round by round: a bracket whose margins some partition sent as a
    histogram is narrowed to the bin holding the rank and asked again."""
    open_ = {(key, r): b for key in ranks for r, b in zip(ranks[key], around[key])}
    nth, hists = {}, {}
    while open_:
        # Neighbouring ranks (a percentile's two) mostly share a bracket: each asked once.
        brackets = {}
        for (key, _), b in open_.items():
            brackets.setdefault(key, set()).add(b)
        brackets = {key: sorted(b) for key, b in brackets.items()}
        details = runner.apply(partition_details, handles, brackets, edges)
        for key, key_edges in edges.items():
            hists[key] = (sum(d[key]["histogram"] for d in details), key_edges)
        edges = {}
        asked = {key: {b: i for i, b in enumerate(b_list)} for key, b_list in brackets.items()}
        narrowed = {}
        for (key, r), b in open_.items():
            pieces = [d[key]["selected"][asked[key][b]] for d in details]
            if all(piece[1] is not None for piece in pieces):
                nth[key, r] = _nth_between(pieces, r)
            else:
                narrowed[key, r] = _narrowed(pieces, b, r)
        open_ = narrowed
    return nth, hists


class Blocks:
    """Contiguous blocks ``start`` to ``stop`` - 1 of a sweep, held as their ends (a list of
    N / 500 block numbers would grow with N): iterated, indexed, measured and compared as the
    list of them."""

    __slots__ = ("start", "stop")

    def __init__(self, start, stop):
        self.start, self.stop = start, stop

    def __len__(self):
        return self.stop - self.start

    def __iter__(self):
        return iter(range(self.start, self.stop))

    def __getitem__(self, index):
        return range(self.start, self.stop)[index]

    def __eq__(self, other):
        if isinstance(other, Blocks):
            return (self.start, self.stop) == (other.start, other.stop)
        try:
            return len(other) == len(self) and list(other) == list(self)
        except TypeError:
            return NotImplemented

    def __hash__(self):
        return hash((self.start, self.stop))

    def __repr__(self):
        return f"Blocks({self.start}, {self.stop})"


def partitions(n, count):
    """The blocks of an N-layout sweep split into ``count`` contiguous partitions (fewer when
    there are fewer blocks), each a ``Blocks``."""
    total = block_count(n)
    count = max(1, min(count, total))
    size, extra = divmod(total, count)
    out, start = [], 0
    for i in range(count):
        end = start + size + (1 if i < extra else 0)
        out.append(Blocks(start, end))
        start = end
    return out
