"""Rounds and timing: what is compared runs in interleaved rounds, each figure the median over
the rounds, a ratio the median of the per-round ratios; a figure becomes a result row.

Exports ``interleaved``, ``median_ratio``, ``per_minute`` and ``row``."""

from __future__ import annotations

import gc
import statistics
import time

__all__ = ["interleaved", "median_ratio", "per_minute", "row"]


def interleaved(tasks, rounds, batch=None):
    """Run each of ``tasks`` (name -> callable) once a round, in turn, the order turned by one
    each round. ``batch[name]`` calls a quick task that many times in a row and counts the mean,
    below the timer's and the scheduler's noise. Returns ({name: [seconds per round]},
    {name: last result})."""
    batch = batch or {}
    names = list(tasks)
    times = {name: [] for name in names}
    results = {}
    for index in range(rounds):
        turn = index % len(names)
        for name in names[turn:] + names[:turn]:
            calls = batch.get(name, 1)
            # Each task starts on a collected heap, untimed: none pays the garbage collection of
            # another's garbage (after a brep round on fab, a batch of analytic scans took 2-4x
            # as long, a full collection of the brep's objects falling into it).
            gc.collect()
            start = time.perf_counter()
            for _ in range(calls):
                results[name] = tasks[name]()
            times[name].append((time.perf_counter() - start) / calls)
    return times, results


def median_ratio(numerator, denominator):
    """Median over rounds of numerator / denominator, round by round."""
    return statistics.median(a / b for a, b in zip(numerator, denominator))


def per_minute(count, times):
    """How many of ``count`` things done in each round (``times``, seconds) make a minute, at
    the median round."""
    return count / statistics.median(times) * 60.0


def row(workload, engine, layout, times, sampled_steps=None, **extra):
    """One result row; ``seconds`` is the median over the rounds."""
    steps = layout.scan.position_count
    seconds = statistics.median(times)
    if sampled_steps is not None:
        seconds *= steps / sampled_steps
    return {"workload": workload, "engine": engine, "steps": steps, "wafers": len(layout.wafers),
            "seconds": seconds, "rounds": len(times), "sampled_steps": sampled_steps,
            "extrapolated": sampled_steps is not None, **extra}
