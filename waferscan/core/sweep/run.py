"""Monte Carlo sweeps (SPEC §12): does a recipe hold under real tolerances?

N layouts are drawn from an INPUT layout by a tolerance file (core/sweep/distributions.py); each is
scanned and mapped with the recipe, and the reported state of every slot is compared with the
state that was placed. The draws, the scan and the mapping run in numpy over blocks of layouts
at once (layouts x wafers), not as N scans in a Python loop:

- exact edges per wafer, in closed form (``geometry.ranges.translation_ranges``: the scalar
  ``translation_range`` over arrays, the same floats: a level wafer's faces, a tilted disc's
  extent along the lift through the corners of its region, a level bowed wafer's lowest bottom
  and highest top over the beam's chord);
- onto the step grid, where a grid position lies clearly inside or outside the edges; the rare
  wafer with an edge within ``GRID_MARGIN`` of a grid position, and the geometry the array
  formulas do not cover (a tilted bowed wafer), go through the scalar engine, so that the
  result is the scalar path's exactly (a test holds them equal on hundreds of layouts);
- runs per layout (overlapping intervals merged), latched as the scan latches them;
- the mapping, by either rule set, scattered per slot with the worst finding kept.

A beam spot, latching in motion or exact edges (z_step = 0) take the scalar path layout by
layout (``scalar_block``): slower, the same answers by construction. A beam spot read on the
step grid goes through core/sweep/spot_scan.py instead: the spot's column ranges of the whole block
over arrays, bit for bit the floats the scalar spot engine computes, then its strips and its
blocked fraction at every step for the whole block at once, the same floats again, and the
runs, latching and mapping layout by layout as the scalar path does them (tests hold every
state, reading and peak equal to the scalar path's).

Reproducibility: layouts are drawn in blocks of ``BLOCK_SIZE``; block b's generator is
SeedSequence(seed, spawn_key=(b,)). The samples depend only on the seed and N, whatever the
partitions the blocks are grouped into and the workers that run them.
"""

from __future__ import annotations

from .clearance import clearance_check
from .draws import sweep_base
from .reduction import LocalPartitions, partitions, reduce_partitions
from .summary import summarise
from .tally import partition_tally

def sweep_tally(layout, tolerances, n, seed=0, plan=None, rules=None, partition_count=1,
                runner=None, progress=None, histograms=False, clearance_body=None):
    """Run the sweep and return (base, tally): ``run_sweep`` before its summary (the tally of
    ``reduce_partitions``, with the margins' histograms when asked)."""
    if n < 1:
        raise ValueError(f"a sweep needs at least one layout, got n = {n}")
    base = sweep_base(layout, plan, rules, clearance_check(layout, tolerances, clearance_body))
    parts = partitions(n, partition_count)
    runner = runner or LocalPartitions()
    handles = runner.run(partition_tally, [(base, tolerances, seed, n, blocks)
                                           for blocks in parts], progress)
    return base, reduce_partitions(runner, handles, histograms)


def run_sweep(layout, tolerances, n, seed=0, plan=None, rules=None, partition_count=1,
              runner=None, progress=None, clearance_body=None):
    """Sweep N layouts drawn from ``layout`` by ``tolerances`` (core.sweep.distributions.Tolerances) and
    return the summary dict (summary.json's content). ``plan`` / ``rules``: the recipe
    (default: the layout's own). The blocks are grouped into ``partition_count`` partitions,
    which ``runner`` runs (default: ``LocalPartitions``, here one after another; the Dask
    runner is waferscan.sweep's); ``progress(done, total)`` after each. The result depends
    only on the layout, the tolerances, N and the seed. From a script:

        layout = read_scenario("resources/examples/paper.toml")
        summary = run_sweep(layout, read_tolerances("fab_tolerances.toml"), 10_000, seed=1)

    With a ``[clearance]`` table in the tolerances the summary has a ``clearance`` report
    (core/sweep/clearance.py); ``clearance_body`` is the robot's StrokeBody
    (waferscan.robot.sweep_clearance.stroke_body(layout)), None for the scanner's heads.
    """
    base, tally = sweep_tally(layout, tolerances, n, seed, plan, rules, partition_count,
                              runner, progress, clearance_body=clearance_body)
    return summarise(base, tolerances, n, seed, tally)
