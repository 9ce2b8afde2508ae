"""SPEC §9 amended: `waferscan scan X.toml` against the `freecadcmd` floor when nothing needs the
document (robot.scenario_scan), process to process, interleaved.

Exports ``bench_scenario_scan``."""

from __future__ import annotations

import statistics

from ..addon import paper_scenario
from .processes import cli, timed_run
from .rounds import interleaved, median_ratio

__all__ = ["bench_scenario_scan"]

FLOOR = ["freecadcmd", "-c", "import Part, numpy"]


def bench_scenario_scan(rounds, scenario=None):
    """`waferscan scan` of a scenario (default: the paper's, resources/examples/paper.toml)
    and `freecadcmd -c "import Part, numpy"`, each a whole process, ``rounds`` interleaved
    rounds: {"scan": median s, "floor": median s, "ratio": median of per-round ratios}."""
    scan = cli("scan", scenario or paper_scenario())
    times, _ = interleaved({"scan": lambda: timed_run(scan), "floor": lambda: timed_run(FLOOR)},
                           rounds)
    return {"scan": statistics.median(times["scan"]),
            "floor": statistics.median(times["floor"]),
            "ratio": median_ratio(times["scan"], times["floor"])}
