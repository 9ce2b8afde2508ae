"""The bench's SPEC §10 figure: the paper's layout scanned with a 1 mm round beam spot at the
default accuracy (threshold 0.5), on the step grid and with exact edges, beside the ideal beam,
``scan_layout`` end to end, interleaved (rows in bench.py's form)."""

from __future__ import annotations

from dataclasses import replace

from .core.scan import scan_layout
from .core.spot import BeamSpot


def bench_spot(paper, rounds, add):
    """Rows ``paper-spot``; returns the medians in seconds (the contract: <= 20 ms)."""
    from .bench import interleaved, row  # bench.py's own timing, one way to measure

    spot = replace(paper, spot=BeamSpot(diameter=1.0))
    exact = spot.with_scan(z_step=0.0)
    tasks = {
        "ideal scan_layout": lambda: scan_layout(paper),
        "1 mm spot scan_layout": lambda: scan_layout(spot),
        "1 mm spot exact scan_layout": lambda: scan_layout(exact),
    }
    times, results = interleaved(tasks, rounds, batch={name: 10 for name in tasks})
    if results["1 mm spot scan_layout"].code != results["ideal scan_layout"].code:
        raise AssertionError("the 1 mm spot changes the paper's code")
    # The exact scan has no grid: its row counts the paper's steps, marked exact.
    rows = [row("paper-spot", name, paper if name.startswith("ideal") else spot, times[name],
                exact_edges=name.endswith("exact scan_layout")) for name in tasks]
    for entry in rows:
        add(entry)
    return {entry["engine"]: entry["seconds"] for entry in rows}
