"""``waferscan bench``: SPEC §9's figures measured in one run and checked against its contract.

``rounds`` times (interleaved rounds, medians); ``workloads``, ``processes``, ``mcs_link`` and
``animation`` are what is timed; ``targets`` is the contract; ``report`` the whole run; its
plot is ``waferscan.plots.bench``'s. Exports (``__all__``) what `waferscan bench` and the tests call."""

from ..plots.bench import plot
from .animation import gui_animation
from .mcs_link import (answered_histories, bench_mcs, mcs_idle, mcs_latency, mcs_poll_cost,
                       mcs_soak)
from .processes import bench_processes, bench_startup, saved_layout
from .report import format_row, run_bench
from .rounds import interleaved, median_ratio, row
from .targets import contract, format_contract
from .workloads import (bench_fab, bench_paper, bench_spot, bench_steps, bench_sweep,
                        bench_wafers, fab_layout, paper_layout, sampled, stack_layout,
                        stack_scenario, vector_peak_memory, with_positions)

__all__ = [
    # the whole run, as `waferscan bench` calls it
    "run_bench", "format_row", "contract", "format_contract", "plot",
    # rounds and timing
    "interleaved", "median_ratio", "row",
    # the layouts measured
    "paper_layout", "fab_layout", "stack_scenario", "stack_layout", "with_positions", "sampled",
    # the measures
    "bench_paper", "bench_spot", "bench_fab", "vector_peak_memory", "bench_steps",
    "bench_wafers", "bench_sweep", "bench_processes", "bench_startup", "saved_layout",
    "bench_mcs", "mcs_latency", "answered_histories", "mcs_idle", "mcs_poll_cost", "mcs_soak",
    "gui_animation",
]
