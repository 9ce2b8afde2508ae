"""Issue 30, SPEC §9: the client's merge of a sweep's partitions is O(candidates log
candidates), not O(partitions x candidates). Each partition's bounds at every candidate
(``_bounds`` here, the old way) summed over the partitions equal the partitions' steps merged
once (``_summed``), integer for integer, for all three kinds of digest; the brackets are the
same ones."""

import time

import numpy as np
import pytest

from waferscan.core.sweep import reduction
from waferscan.core.sweep.margins import COARSE_BITS, COARSE_SHIFT, order_keys


def _samples(rng, count, stride):
    values = np.sort(np.round(rng.normal(0.2, 0.05, count), 3))  # readings repeat: ties
    return {"count": count, "stride": stride, "samples": values[::stride].copy(),
            "min": float(values[0]), "max": float(values[-1])}


def _values(rng, count):
    values, counts = np.unique(np.round(rng.normal(0.2, 0.05, count), 2), return_counts=True)
    return {"count": count, "values": values, "counts": counts, "min": float(values[0]),
            "max": float(values[-1])}


def _bins(rng, count):
    values = rng.normal(0.2, 0.05, count)
    bins, counts = np.unique((order_keys(values) >> np.uint64(COARSE_SHIFT)).astype(np.int64),
                             return_counts=True)
    return {"count": count, "bins": bins, "bin_counts": counts, "min": float(values.min()),
            "max": float(values.max())}


def _bounds(kind, candidates):
    """The merge's bounds as they were computed before, kept as the reference: (at most how
    many margins lie below each candidate, at least how many lie at or below it), one
    partition's digest looked up at every candidate."""
    count = kind["count"]
    if "samples" in kind:
        # k samples below v (every stride-th margin from the smallest): between
        # (k - 1) * stride + 1 and k * stride of the margins lie below v (all when every
        # sample does).
        sample, stride = kind["samples"], kind["stride"]
        a = np.searchsorted(sample, candidates, side="left")
        b = np.searchsorted(sample, candidates, side="right")
        return (np.where(a < len(sample), a * stride, count),
                np.where(b > 0, (b - 1) * stride + 1, 0))
    if "values" in kind:
        cum = np.concatenate([[0], np.cumsum(kind["counts"])])
        return (cum[np.searchsorted(kind["values"], candidates, side="left")],
                cum[np.searchsorted(kind["values"], candidates, side="right")])
    # A histogram of order keys: below v at most the margins of the bins starting below v's
    # key; at or below v at least those of the bins ending at or below it.
    keys = order_keys(candidates)
    cum = np.zeros((1 << COARSE_BITS) + 1, dtype=np.int64)
    cum[kind["bins"] + 1] = kind["bin_counts"]
    cum = np.cumsum(cum)
    start = (keys >> np.uint64(COARSE_SHIFT)).astype(np.int64)
    starts_below = start + (keys & np.uint64((1 << COARSE_SHIFT) - 1) != 0)
    ends_within = ((keys >> np.uint64(COARSE_SHIFT)) + ((keys & np.uint64(
        (1 << COARSE_SHIFT) - 1)) == np.uint64((1 << COARSE_SHIFT) - 1))).astype(np.int64)
    return cum[starts_below], cum[ends_within]


def _old_brackets(kinds, ranks):
    """reduction._brackets as it was: every partition's bounds at every candidate."""
    candidates = np.unique(np.concatenate([reduction._candidates(k) for k in kinds]))
    most = sum(_bounds(k, candidates)[0] for k in kinds)
    least = sum(_bounds(k, candidates)[1] for k in kinds)
    return candidates, most, least


@pytest.mark.parametrize("seed", range(5))
def test_the_merged_steps_are_the_summed_bounds_for_every_kind_of_digest(seed):
    rng = np.random.default_rng(seed)
    kinds = ([_samples(rng, int(rng.integers(1, 3000)), int(rng.choice([1, 7, 256])))
              for _ in range(6)] + [_values(rng, int(rng.integers(1, 3000))) for _ in range(3)]
             + [_bins(rng, int(rng.integers(1, 3000))) for _ in range(3)])
    candidates, most, least = _old_brackets(kinds, [])
    steps = [reduction._steps(k) for k in kinds]
    assert np.array_equal(reduction._summed([m for m, _ in steps], candidates, "left"), most)
    assert np.array_equal(reduction._summed([s for _, s in steps], candidates, "right"), least)
    total = sum(k["count"] for k in kinds)
    ranks = sorted({0, total - 1, total // 2, *rng.integers(0, total, 20).tolist()})
    digests = [{"margins": {"m": k}} for k in kinds]
    new = reduction._brackets(digests, "m", ranks)
    for r, (low, high) in zip(ranks, new):
        i = int(np.searchsorted(most, r, side="right")) - 1
        j = int(np.searchsorted(least, r + 1, side="left"))
        smallest = min(k["min"] for k in kinds)
        largest = max(k["max"] for k in kinds)
        assert low == max(float(candidates[i]) if i >= 0 else -np.inf, smallest)
        assert high == min(float(candidates[j]) if j < len(candidates) else np.inf, largest)


def test_a_thousand_partitions_of_a_hundred_million_layouts_merge(capsys):
    # Synthetic digests as a sweep of 10^8 layouts in 1,000 partitions sends them: 10^5
    # margins each, every 256th as a sample (391 a partition). The figure is printed, not
    # judged here (the bench times it: docs/performance.md).
    rng = np.random.default_rng(1)
    count, stride = 100_000, 256
    kinds = []
    for _ in range(1000):
        samples = np.sort(rng.normal(0.2, 0.05, count // stride + 1))
        kinds.append({"count": count, "stride": stride, "samples": samples,
                      "min": float(samples[0]), "max": float(samples[-1])})
    digests = [{"margins": {"m": k}} for k in kinds]
    ranks = [0, 10**6, 5 * 10**7, 10**8 - 1]
    start = time.perf_counter()
    brackets = reduction._brackets(digests, "m", ranks)
    took = time.perf_counter() - start
    with capsys.disabled():
        print(f"\n1,000 partitions of 10^8 layouts: brackets of one kind in {took:.3f} s")
    assert all(low <= high for low, high in brackets)


@pytest.mark.parametrize("seed", range(4))
def test_a_tally_of_many_distinct_margins_sends_every_stride_th_of_them(seed):
    """A partition's MarginTally of many distinct values (readings off the step grid) is
    digested as a sorted array of them all would be: its stride-th values from the smallest,
    not each value with its count; and every rank is found exactly from such digests (the
    reduction's order statistics against numpy's sort of all the partitions' margins)."""
    from waferscan.core.sweep.margins import MarginTally
    from waferscan.core.sweep.reduction import LocalPartitions, reduce_partitions

    rng = np.random.default_rng(seed)
    parts, every, sampled = [], [], []
    for _ in range(int(rng.integers(2, 6))):
        tally = MarginTally()
        held = []
        for _ in range(int(rng.integers(1, 5))):
            block = np.round(rng.normal(0.2, 0.05, int(rng.integers(1, 4000))), 5)  # ties too
            tally.add(block)
            held.append(block)
        margins = np.sort(np.concatenate(held))
        every.append(margins)
        stride = int(rng.choice([1, 7, 256, 256]))
        digest = reduction.partition_digest(
            {"confusion": 0, "moments": 0, "weakest_peak": 1.0, "extremes": {},
             "margins": {"m": tally}}, stride)["margins"]["m"]
        assert tally.exact
        if len(tally.values) > tally.count // stride + 1:  # more values than samples
            assert "values" not in digest
            assert np.array_equal(digest["samples"], margins[::stride])
            sampled.append(stride)
        else:
            assert np.array_equal(np.repeat(digest["values"], digest["counts"]), margins)
        parts.append({"confusion": np.zeros((8, 8), dtype=np.int64), "moments": 0,
                      "weakest_peak": 1.0, "extremes": {}, "margins": {"m": tally}})
    assert sampled  # the digest of many distinct values was met
    reduced = reduce_partitions(LocalPartitions(), parts)["margins"]["m"]
    together = np.sort(np.concatenate(every))
    assert reduced["count"] == len(together)
    assert reduced["min"] == together[0] and reduced["max"] == together[-1]
    for p in reduction.PERCENTILES:
        assert reduced[f"p{p}"] == float(np.percentile(together, p))
