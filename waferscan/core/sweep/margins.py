"""A partition's margins in memory that does not grow with N (issue 25).

A partition keeps each kind of margin as its distinct values with their counts while they are
few (readings on the step grid repeat: a block's ~11,000 thickness margins hold ~26 values),
which answers every order statistic exactly. When they are too many (readings off the grid:
latching in motion, a beam spot, a thickness correction), it keeps a histogram over the
values' order keys instead and, asked later for the margins between two values, draws and
scans its blocks again: block b's draws are SeedSequence(seed, spawn_key=(b,))'s, so the
second pass sees the same margins, in the same floats, as the first. A sweep of no more than
MARGINS_KEPT slots keeps them all instead, sorted (tally.py), and needs no second pass.

Order keys: the float64 values as unsigned 64-bit integers in the same order (-0.0 as 0.0),
so that a histogram's bins can be halved down to single values in a bounded number of steps.
"""

from __future__ import annotations

import math

# Distinct values of one kind of margin a partition keeps (or sends for one bracket) before it
# falls back on a histogram: 16 bytes each, 4 MB (~10,000 layouts of 25 slots whose margins
# are all different: smaller sweeps are never drawn twice).
DISTINCT_LIMIT = 1 << 18
# A sweep of at most this many slots (N layouts x slots) keeps its margins whole besides their
# MarginTally (8 bytes each, at most 32 MB a kind over all its partitions), so that a kind that
# falls back on a histogram is not drawn and scanned again: a 100,000-layout sweep of 25 slots
# (~2.3 million margins off the step grid, latched in motion) took twice its first pass
# before. A larger sweep keeps none: its memory does not grow with N.
MARGINS_KEPT = 1 << 22
# The first pass's histogram: the top COARSE_BITS bits of the order key (sign, exponent and
# 6 bits of mantissa: 64 bins a binade), 262,144 bins (2 MB).
COARSE_BITS = 18
COARSE_SHIFT = 64 - COARSE_BITS
# A bracket holding too many distinct values is cut into this many bins of keys: each pass
# narrows it 2**14-fold, so at most 4 passes reach single values from a coarse bin.
FINE_BINS = 1 << 14

_TOP = 1 << 63
_ALL = (1 << 64) - 1


def order_keys(values):
    """uint64 keys in the order of the float64 ``values`` (a key per value; -0.0 as 0.0)."""
    import numpy as np

    bits = (np.asarray(values, dtype=np.float64) + 0.0).view(np.uint64)
    negative = (bits >> np.uint64(63)).astype(bool)
    return np.where(negative, ~bits, bits | np.uint64(_TOP))


def order_key(value):
    """The order key of one float (a Python int)."""
    return int(order_keys([value])[0])


def key_value(key):
    """The float whose order key is ``key``."""
    import numpy as np

    key = int(key)
    bits = (key ^ _TOP) if key & _TOP else (~key & _ALL)
    return float(np.array([bits], dtype=np.uint64).view(np.float64)[0])


class DistinctCounts:
    """Distinct values with their counts, blocks' values gathered and merged once they are as
    many as those already held (a merge at every block would sort the whole set again each
    time: ~15 ms a block at 250,000 values)."""

    def __init__(self):
        import numpy as np

        self._values = np.empty(0)
        self._counts = np.empty(0, dtype=np.int64)
        self._pending = []
        self._pending_size = 0

    def add(self, values):
        """Gather ``values`` (an array); returns how many distinct values there may be."""
        import numpy as np

        more, more_counts = np.unique(values, return_counts=True)
        self._pending.append((more, more_counts))
        self._pending_size += len(more)
        if self._pending_size > max(len(self._values), 1 << 12):
            self._merge()
        return len(self._values) + self._pending_size

    def _merge(self):
        import numpy as np

        if not self._pending:
            return
        values = np.concatenate([self._values, *(v for v, _ in self._pending)])
        counts = np.concatenate([self._counts, *(c for _, c in self._pending)])
        self._pending, self._pending_size = [], 0
        self._values, where = np.unique(values, return_inverse=True)
        self._counts = np.zeros(len(self._values), dtype=np.int64)
        np.add.at(self._counts, where.ravel(), counts)

    def merged(self):
        """(distinct sorted values, their counts)."""
        self._merge()
        return self._values, self._counts


class MarginTally:
    """One kind of margin of one partition: its count, smallest and largest, and either its
    distinct values with their counts (``exact``) or a histogram of their order keys' top
    COARSE_BITS bits (``coarse``)."""

    def __init__(self):
        self.count = 0
        self.low = math.inf
        self.high = -math.inf
        self._distinct = DistinctCounts()
        self.coarse = None

    @property
    def exact(self):
        return self.coarse is None

    @property
    def values(self):
        return self._distinct.merged()[0] if self.exact else None

    @property
    def counts(self):
        return self._distinct.merged()[1] if self.exact else None

    def add(self, values):
        """Count a block's margins in."""
        if not len(values):
            return
        self.count += len(values)
        self.low = min(self.low, float(values.min()))
        self.high = max(self.high, float(values.max()))
        if self.coarse is not None:
            _count_coarse(self.coarse, values)
        elif self._distinct.add(values) > DISTINCT_LIMIT:
            values, counts = self._distinct.merged()
            if len(values) > DISTINCT_LIMIT:
                self.coarse = coarse_histogram(values, counts)
                self._distinct = None


def _coarse_bins(values):
    """The bin (of 2**COARSE_BITS) of each of ``values``: the top bits of its order key."""
    import numpy as np

    return (order_keys(values) >> np.uint64(COARSE_SHIFT)).astype(np.int64)


def coarse_histogram(values, counts=None):
    """How many of ``values`` (each ``counts`` times) fall in each of the 2**COARSE_BITS bins
    of order keys."""
    import numpy as np

    return np.bincount(_coarse_bins(values), weights=counts,
                       minlength=1 << COARSE_BITS).astype(np.int64, copy=False)


def _count_coarse(histogram, values):
    """Add ``values`` into ``histogram`` (``coarse_histogram``'s bins) in place: over the
    bins from the lowest to the highest that they fill (a block's margins fill a few hundred),
    not a new array of all 2**COARSE_BITS bins a block (2 MB, made, converted and added)."""
    import numpy as np

    bins = _coarse_bins(values)
    first = int(bins.min())
    counts = np.bincount(bins - first)
    histogram[first:first + len(counts)] += counts


class BracketTally:
    """What a partition holds of its margins from ``low`` to ``high`` (both included), counted
    block by block: how many lie below ``low``, and those in the bracket as distinct values
    with counts, or, past DISTINCT_LIMIT, as a histogram over ``fine_bins(low, high)``."""

    def __init__(self, low, high):
        self.low, self.high = low, high
        self.below = 0
        self._distinct = DistinctCounts()
        self.fine = None
        # A bracket of one value always sends it: the rounds end there.
        self.limit = max(1, DISTINCT_LIMIT)

    def add(self, ordered):
        """Count a block's margins (sorted) in."""
        import numpy as np

        a = int(np.searchsorted(ordered, self.low, side="left"))
        b = int(np.searchsorted(ordered, self.high, side="right"))
        self.below += a
        inside = ordered[a:b]
        if not len(inside):
            return
        if self.fine is not None:
            self.fine += fine_histogram(self.low, self.high, inside)
        elif self._distinct.add(inside) > self.limit:
            values, counts = self._distinct.merged()
            if len(values) > self.limit:
                self.fine = fine_histogram(self.low, self.high, values, counts)
                self._distinct = None

    def piece(self):
        """(below, distinct values, counts), or (below, None, the fine histogram)."""
        if self.fine is not None:
            return (self.below, None, self.fine)
        return (self.below, *self._distinct.merged())


def fine_bins(low, high):
    """The bins a bracket is cut into: (the low key, the keys a bin spans, how many bins)."""
    first, last = order_key(low), order_key(high)
    span = last - first + 1
    width = -(-span // FINE_BINS)
    return first, width, -(-span // width)


def fine_histogram(low, high, values, counts=None):
    """How many of ``values`` (all from ``low`` to ``high``; each ``counts`` times) fall in
    each of ``fine_bins(low, high)``."""
    import numpy as np

    first, width, bins = fine_bins(low, high)
    at = ((order_keys(values) - np.uint64(first)) // np.uint64(width)).astype(np.int64)
    return np.bincount(at, weights=counts, minlength=bins).astype(np.int64)


def fine_bin_bracket(low, high, index):
    """The (low, high) values of bin ``index`` of ``fine_bins(low, high)``."""
    first, width, _ = fine_bins(low, high)
    last = order_key(high)
    return (key_value(first + index * width),
            key_value(min(first + (index + 1) * width - 1, last)))
