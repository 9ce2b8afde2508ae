"""``waferscan sweep`` (SPEC §12): the sweep of ``waferscan.core.sweep`` run on a Dask cluster
(``cluster``) and its outputs written (``outputs``). The numbers are core's; nothing here
computes one."""

from .cluster import DaskPartitions, ProgressLine, load_layout, local_cluster, run
from .outputs import OUTPUT_NAMES, format_summary, output_folder, write_outputs

__all__ = ["OUTPUT_NAMES", "DaskPartitions", "ProgressLine", "format_summary", "load_layout",
           "local_cluster", "output_folder", "run", "write_outputs"]
