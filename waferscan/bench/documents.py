"""Documents (SPEC §9 amended): `waferscan scan X.FCStd` of a stack of FOUPs against its floor,
FreeCAD's own open of the same file and a read of every object's Placement, process to process,
interleaved. Both run in this interpreter, which is the one `waferscan` runs in (its console
script imports FreeCAD through the venv's path to FreeCAD's library, not through freecadcmd).

Exports ``floor_command`` and ``bench_document_floor``."""

from __future__ import annotations

import statistics
import sys
import tempfile
from pathlib import Path

from .processes import cli, timed_run
from .rounds import interleaved, median_ratio
from .workloads import stack_scenario

__all__ = ["floor_command", "bench_document_floor"]

SLOTS = 25  # wafers a FOUP of the stack holds (workloads.stack_scenario)

# What any FreeCAD user's script does first with a layout: open it, and read where every object
# is. ``getattr``: an App::FeaturePython (the scan settings) has no Placement.
FLOOR_SCRIPT = """\
import sys
import FreeCAD
doc = FreeCAD.openDocument(sys.argv[1])
placements = [getattr(obj, "Placement", None) for obj in doc.Objects]
"""


def floor_command(path):
    """The floor as a process: FreeCAD opens ``path`` and reads every object's Placement."""
    return [sys.executable, "-c", FLOOR_SCRIPT, str(path)]


def bench_document_floor(rounds, wafers=10_000, quick=False, folder=None):
    """`waferscan scan X.FCStd` against FreeCAD's open + placement read of X, ``wafers`` wafers
    (a multiple of 25; ``quick``: 1,000) stacked in FOUPs (workloads.stack_scenario). The
    layout is made once by `waferscan layout`, untimed, in ``folder`` (a temporary folder when
    None, removed afterwards); then both processes run once a round, interleaved. Returns
    {"scan": median seconds, "floor": median seconds, "ratio": median of the per-round
    ratios, "wafers": n, "file_bytes": the .FCStd's size}."""
    if quick:
        wafers = 1_000
    if wafers <= 0 or wafers % SLOTS:
        raise ValueError(f"wafers must be a positive multiple of {SLOTS}, not {wafers}")
    if folder is None:
        with tempfile.TemporaryDirectory(prefix="waferscan-documents-") as temporary:
            return bench_document_floor(rounds, wafers, folder=temporary)
    scenario = Path(folder) / f"stack-{wafers}.toml"
    scenario.write_text(stack_scenario(wafers // SLOTS), encoding="utf-8")
    layout = Path(folder) / f"stack-{wafers}.FCStd"
    timed_run(cli("layout", scenario, "-o", layout))  # untimed: made once
    commands = {"scan": cli("scan", layout), "floor": floor_command(layout)}
    times, _ = interleaved({name: (lambda c=command: timed_run(c))
                            for name, command in commands.items()}, rounds)
    return {"scan": statistics.median(times["scan"]),
            "floor": statistics.median(times["floor"]),
            "ratio": median_ratio(times["scan"], times["floor"]),
            "wafers": wafers, "file_bytes": layout.stat().st_size}
