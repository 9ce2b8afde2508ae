"""Sweeps (SPEC §12): layouts drawn from a tolerance file (``distributions``, ``draws``), scanned
in blocks over arrays (``block_scan``; ``spot_scan`` with a beam spot), tallied per partition
block by block (``tally``, ``margins``: in memory that does not grow with N), the partitions
reduced to one (``reduction``) and summarised (``summary``); ``run`` holds the entry points;
``clearance`` the ``[clearance]`` report (SPEC §15: the rate of layouts with a contact).
What scripts and the other layers use is exported here."""

from .block_scan import (
    SWEEP_CHUNK,
    UNSCANNED,
    needs_scalar_path,
    scalar_block,
    scan_block,
    spot_block,
)
from .draws import (
    BLOCK_SIZE,
    PLACED,
    Draws,
    SweepBase,
    block_count,
    block_size,
    block_sizes,
    draw_block,
    layouts_in,
    sample_layout,
    sweep_base,
)
from .margins import MarginTally
from .reduction import (
    DIGEST_STRIDE,
    MARGIN_BINS,
    PERCENTILES,
    Blocks,
    LocalPartitions,
    linear_percentile,
    partition_details,
    partition_digest,
    partitions,
    reduce_partitions,
)
from .run import run_sweep, sweep_tally
from .summary import INTERVALS, Z95, layout_interval, rate_intervals, summarise, wilson
from .tally import (
    STATE_KEYS,
    block_tally,
    combine_tallies,
    layout_moments,
    margin_values,
    partition_margins,
    partition_tally,
    sweep_block,
)

__all__ = [
    "BLOCK_SIZE", "DIGEST_STRIDE", "INTERVALS", "MARGIN_BINS", "PERCENTILES", "PLACED",
    "STATE_KEYS", "SWEEP_CHUNK", "UNSCANNED", "Z95", "Blocks", "Draws", "LocalPartitions",
    "MarginTally", "SweepBase", "block_count", "block_size", "block_sizes", "block_tally",
    "combine_tallies", "draw_block", "layout_interval", "layout_moments", "layouts_in",
    "linear_percentile", "margin_values", "needs_scalar_path", "partition_details",
    "partition_digest", "partition_margins", "partition_tally", "partitions", "rate_intervals", "reduce_partitions", "run_sweep", "sample_layout",
    "scalar_block", "scan_block", "spot_block", "summarise", "sweep_base", "sweep_block",
    "sweep_tally", "wilson",
]
