"""The sensor amplifier (SPEC §10): from the blocked fraction b to the ON/OFF output.

The output turns ON when b >= threshold_on and back OFF when b < threshold_off (<= threshold_on).
With hysteresis (threshold_off < threshold_on) where it switches depends on the direction of
motion: moving up, it turns ON at the bottom of a stretch where b >= threshold_on and OFF at the
top of the stretch where b >= threshold_off that holds it; moving down, the other way round.
Both are given here for a continuous stroke (edges found by bisection to ``EDGE_TOLERANCE``) and
for positions on a grid (the output read at each step, in the order of motion).
"""

from __future__ import annotations

import math

from .spot import EDGE_TOLERANCE

# Samples of b per spot height when looking for threshold crossings: a crossing pair closer
# than 1/64 of the spot's height apart (a peak just touching the threshold) may be missed.
SAMPLES_PER_SPOT = 64
MAX_SAMPLES = 200_000


def level_intervals(fraction, lo, hi, level, spacing):
    """Where ``fraction(tau) >= level`` on [lo, hi]: sorted disjoint (a, b) intervals, ends found
    to EDGE_TOLERANCE, and the largest fraction sampled. ``spacing`` is the sampling step that
    brackets the crossings."""
    found, peaks = grouped_level_intervals(lambda tau, group: fraction(tau), [(lo, hi)], level,
                                           spacing)
    return found[0], peaks[0]


def grouped_level_intervals(fraction, spans, level, spacing):
    """``level_intervals`` for several groups at once: ``fraction(tau, group)`` evaluates b at
    arrays of translations and group indices; ``spans`` the (lo, hi) of each group. Every
    group's samples and every crossing's refinement go through one call per round."""
    import numpy as np

    taus, groups, counts = [], [], []
    for g, (lo, hi) in enumerate(spans):
        counts.append(0)
        if hi < lo:
            continue
        count = int(min(MAX_SAMPLES, max(2, math.ceil((hi - lo) / spacing) + 1)))
        taus.append(np.linspace(lo, hi, count))
        groups.append(np.full(count, g))
        counts[g] = count
    found = [[] for _ in spans]
    peaks = [0.0 for _ in spans]
    if not taus:
        return found, peaks
    tau = np.concatenate(taus)
    group = np.concatenate(groups)
    values = fraction(tau, group)
    above = values >= level
    same = group[1:] == group[:-1]
    change = np.flatnonzero((above[1:] != above[:-1]) & same)
    # Refine every crossing between samples i and i+1 at once: the end where b >= level
    # (``yes``) and the one where b < level (``no``), by the Illinois variant of regula falsi
    # (b is smooth between the samples: a few evaluations reach EDGE_TOLERANCE, where
    # bisection takes some 25).
    rising = ~above[change]
    which = group[change]
    yes = np.where(rising, tau[change + 1], tau[change])
    no = np.where(rising, tau[change], tau[change + 1])
    f_yes = np.where(rising, values[change + 1], values[change]) - level
    f_no = np.where(rising, values[change], values[change + 1]) - level
    last_side = np.zeros(yes.shape, dtype=int)
    for _ in range(100):
        if not yes.size or float(np.abs(yes - no).max()) <= EDGE_TOLERANCE:
            break
        denominator = f_yes - f_no
        guess = np.where(denominator > 0.0, (yes * -f_no + no * f_yes) / np.where(
            denominator > 0.0, denominator, 1.0), 0.5 * (yes + no))
        # Keep each guess strictly inside its bracket, a little away from the ends, so the
        # bracket always shrinks.
        width = np.abs(yes - no)
        guess = np.clip(guess, np.minimum(yes, no) + 0.01 * width,
                        np.maximum(yes, no) - 0.01 * width)
        f_guess = fraction(guess, which) - level
        hit = f_guess >= 0.0
        # Illinois: when the same end moves twice, halve the other end's value.
        f_no = np.where(hit & (last_side == 1), 0.5 * f_no, f_no)
        f_yes = np.where(~hit & (last_side == -1), 0.5 * f_yes, f_yes)
        yes = np.where(hit, guess, yes)
        f_yes = np.where(hit, f_guess, f_yes)
        no = np.where(hit, no, guess)
        f_no = np.where(hit, f_no, f_guess)
        last_side = np.where(hit, 1, -1)
    crossings = {}
    for i, g in enumerate(which):
        crossings.setdefault(int(g), []).append((bool(rising[i]), float(yes[i])))
    offset = 0
    for g, (lo, hi) in enumerate(spans):
        if hi < lo:
            continue
        count = counts[g]
        part = values[offset:offset + count]
        peaks[g] = float(part.max())
        start = lo if part[0] >= level else None
        for rise, x in crossings.get(g, []):
            if rise:
                start = x  # the first point at or above the level
            else:
                found[g].append((start, x))  # the last point at or above it
                start = None
        if start is not None:
            found[g].append((start, hi))
        offset += count
    return found, peaks


def output_intervals(on_intervals, off_intervals, moving_up):
    """The stretches where the output is ON, as ascending (bottom, top) pairs, for a continuous
    stroke: each stretch where b >= threshold_off that holds a stretch where b >= threshold_on,
    from where the first (moving up) or the last (moving down) such ON stretch begins."""
    out = []
    for lo, hi in off_intervals:
        inside = [(a, b) for a, b in on_intervals if a >= lo - EDGE_TOLERANCE
                  and b <= hi + EDGE_TOLERANCE]
        if not inside:
            continue
        if moving_up:
            out.append((inside[0][0], hi))
        else:
            out.append((lo, inside[-1][1]))
    return out


def stepped_output(values, threshold_on, threshold_off, moving_up):
    """ON runs of the output read at each step: ``values`` are b at ascending steps; the steps
    are visited upwards or downwards. Returns (first, last) step indices, ascending."""
    count = len(values)
    order = range(count) if moving_up else range(count - 1, -1, -1)
    state = False
    runs = []
    start = None
    for k in order:
        b = values[k]
        if not state and b >= threshold_on:
            state, start = True, k
        elif state and b < threshold_off:
            state = False
            last = k - 1 if moving_up else k + 1
            runs.append((min(start, last), max(start, last)))
    if state:
        last = count - 1 if moving_up else 0
        runs.append((min(start, last), max(start, last)))
    return sorted(runs)
