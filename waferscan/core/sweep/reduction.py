"""The partitions' tallies reduced to one, wherever they ran: the counts added and the margins'
order statistics found exactly from small digests (``LocalPartitions`` runs them here, one after
another; a Dask runner elsewhere)."""

from __future__ import annotations

from .draws import block_count

import math

# The percentiles the summary gives of each kind of margin.
PERCENTILES = (1, 5, 50, 95, 99)


# --- reducing the partitions ------------------------------------------------------------------
#
# The summary needs the margins' order statistics (min, percentiles, max) over every partition,
# exactly. Rather than bring every partition's margins to one place (40 MB for 100,000
# layouts, and a sort there that no worker shares), each partition sends every
# DIGEST_STRIDE-th of its sorted margins; those bound each wanted order statistic between two
# values, and each partition then sends the few of its margins between them and how many lie
# below. Two small round trips, the same numbers as sorting everything in one place.

DIGEST_STRIDE = 256
MARGIN_BINS = 60


def partition_digest(part, stride=None):
    """A partition without its margins: its counts and extremes, and of each kind of margin the
    count, the largest and every ``stride``-th value from the smallest (a sorted sample;
    default DIGEST_STRIDE)."""
    stride = stride or DIGEST_STRIDE
    out = {k: part[k] for k in ("confusion", "moments", "weakest_peak", "extremes")}
    out["margins"] = {key: {"count": len(values), "stride": stride,
                            "samples": values[::stride].copy(),
                            "max": float(values[-1]) if len(values) else None}
                      for key, values in part["margins"].items()}
    return out


def _brackets(digests, key, ranks):
    """For each 0-based rank r of the margins ``key`` of every partition together, values
    (low, high) with low <= the r-th smallest <= high, from the partitions' samples. A
    partition's k samples below a value v (every stride-th margin from the smallest) say that
    between (k - 1) * stride + 1 and k * stride of its margins lie below v (all of them when
    every sample does)."""
    import numpy as np

    kinds = [d["margins"][key] for d in digests]
    candidates = np.unique(np.concatenate([kind["samples"] for kind in kinds]))
    below_at_most = np.zeros(len(candidates), dtype=np.int64)   # margins < v, at most
    up_to_at_least = np.zeros(len(candidates), dtype=np.int64)  # margins <= v, at least
    for kind in kinds:
        sample, count, stride = kind["samples"], kind["count"], kind["stride"]
        a = np.searchsorted(sample, candidates, side="left")
        below_at_most += np.where(a < len(sample), a * stride, count)
        b = np.searchsorted(sample, candidates, side="right")
        up_to_at_least += np.where(b > 0, (b - 1) * stride + 1, 0)
    out = []
    for r in ranks:
        i = int(np.searchsorted(below_at_most, r, side="right")) - 1
        j = int(np.searchsorted(up_to_at_least, r + 1, side="left"))
        out.append((float(candidates[i]) if i >= 0 else -math.inf,
                    float(candidates[j]) if j < len(candidates) else math.inf))
    return out


def partition_details(part, brackets, edges):
    """What a partition adds to the order statistics and histograms: for each kind of margin
    and each (low, high) of ``brackets[key]``, how many of its margins lie below low and those
    from low to high as distinct values with their counts (readings on the step grid repeat:
    a block's ~11,000 thickness margins hold ~26 values); and its histogram over
    ``edges[key]`` (numpy.histogram's bins), where ``edges`` has the key."""
    import numpy as np

    out = {}
    for key, values in part["margins"].items():
        pieces = []
        for low, high in brackets.get(key, ()):
            a = int(np.searchsorted(values, low, side="left"))
            b = int(np.searchsorted(values, high, side="right"))
            pieces.append((a, *np.unique(values[a:b], return_counts=True)))
        hist = None
        if edges.get(key) is not None:
            hist = np.histogram(values, bins=edges[key])[0]
        out[key] = {"selected": pieces, "histogram": hist}
    return out


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
    counts, ends, ranks, around, brackets, edges = {}, {}, {}, {}, {}, {}
    for key in digests[0]["margins"]:
        held = [d["margins"][key] for d in digests if d["margins"][key]["count"]]
        counts[key] = sum(h["count"] for h in held)
        if not held:
            continue
        ends[key] = (min(float(h["samples"][0]) for h in held), max(h["max"] for h in held))
        ranks[key] = _wanted_ranks(counts[key])
        around[key] = _brackets(digests, key, ranks[key])  # one for each rank
        # Neighbouring ranks (a percentile's two) mostly share a bracket: each asked once.
        brackets[key] = sorted(set(around[key]))
        if histograms:
            edges[key] = np.histogram_bin_edges(ends[key], bins=MARGIN_BINS)
    details = runner.apply(partition_details, handles, brackets, edges) if brackets else []
    margins, hists = {}, {}
    for key, count in counts.items():
        if count == 0:
            margins[key] = None
            continue
        asked = {bracket: i for i, bracket in enumerate(brackets[key])}
        nth = {r: _nth_between([d[key]["selected"][asked[b]] for d in details], r)
               for r, b in zip(ranks[key], around[key])}
        dist = {"count": int(count), "min": ends[key][0]}
        for p in PERCENTILES:
            dist[f"p{p}"] = float(linear_percentile(count, p, nth.__getitem__))
        dist["max"] = ends[key][1]
        margins[key] = dist
        if histograms:
            hists[key] = (sum(d[key]["histogram"] for d in details), edges[key])
    return {"confusion": confusion, "moments": moments, "weakest_peak": weakest,
            "extremes": extremes,
            "margins": margins, "histograms": hists}


def partitions(n, count):
    """The blocks of an N-layout sweep split into ``count`` contiguous partitions (fewer when
    there are fewer blocks)."""
    blocks = list(range(block_count(n)))
    count = max(1, min(count, len(blocks)))
    size, extra = divmod(len(blocks), count)
    out, start = [], 0
    for i in range(count):
        end = start + size + (1 if i < extra else 0)
        out.append(blocks[start:end])
        start = end
    return out
