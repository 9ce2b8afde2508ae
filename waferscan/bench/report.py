"""The whole run of `waferscan bench`: every workload in its order, the report it builds (a
JSON-able dict) and the table line of each result row.

Exports ``run_bench`` and ``format_row``."""

from __future__ import annotations

import subprocess
import tempfile

from .animation import gui_animation
from .host_link import bench_host
from .mcs_link import bench_mcs
from .processes import bench_processes, bench_startup, saved_layout
from .targets import contract_entries
from .workloads import (bench_fab, bench_paper, bench_spot, bench_steps, bench_sweep,
                        bench_wafers, paper_layout, vector_peak_memory)

__all__ = ["run_bench", "bench_floors", "format_row"]


def run_bench(scenario_path, quick=False, gui=True, mcs=True, progress=print, only=None):
    """Every workload; returns the report (a JSON-able dict): ``results`` (rows), ``ratios``,
    ``memory``, ``mcs``, ``gui_animation`` and ``contract``."""
    rows = []

    def add(entry):
        rows.append(entry)
        progress(entry)

    rounds = 3 if quick else 9
    paper = paper_layout(scenario_path)
    report = {"quick": quick, "results": rows}
    if only == "sweep":  # `waferscan bench --only sweep`: the sweeps' figures alone
        report["sweep"] = bench_sweep(paper, rounds, add, quick)
        report["contract"] = contract_entries(report, only="sweep")
        return report
    if only == "floors":  # `waferscan bench --only floors`: the figures beside their floors
        measure_floors(report, rounds, quick, add)
        report["contract"] = contract_entries(report, only="floor")
        return report
    if only == "host":  # `waferscan bench --only host`: the host link's figures alone
        report["host"] = bench_host(scenario_path, 20 if quick else 100, add)
        return report
    report["ratios"] = bench_paper(scenario_path, rounds, add)
    report["spot"] = bench_spot(paper, rounds, add)
    report["ratios"]["brep/analytic scan_layout on fab"] = bench_fab(
        paper, 1 if quick else 3, add, brep_every=100 if quick else 1)
    report["memory"] = {"vector_fab_peak_bytes": vector_peak_memory(paper)}
    bench_steps(paper, (1_000, 10_000, 100_000) if quick else
                (1_000, 10_000, 100_000, 1_000_000), 1 if quick else 3, add)
    foups = (4, 40, 400) if quick else (4, 12, 40, 120, 400)
    bench_wafers(paper, foups, 3 if quick else 5, 1_000 if quick else 10_000, add)
    with tempfile.TemporaryDirectory() as folder:
        bench_processes(folder, (4, 40) if quick else (4, 40, 400), add)
        layout_path = saved_layout(scenario_path, folder)
        bench_startup(layout_path, paper, 3 if quick else 7, add)
        # A measure that fails (a watcher that stops answering, a GUI that does not start) is
        # reported as failed, with the other figures kept.
        report["mcs"] = report["gui_animation"] = None
        try:
            if mcs:
                report["mcs"] = bench_mcs(layout_path, quick, (10, 100_000) if quick else
                                          (10, 1_000, 10_000, 100_000), add)
        except (RuntimeError, OSError, subprocess.SubprocessError) as exc:
            report["mcs_error"] = str(exc)
        try:  # SPEC §14: a carrier's arrival to its event, a verification's round trip
            if mcs:
                report["host"] = bench_host(layout_path, 20 if quick else 100, add)
        except (RuntimeError, OSError, AssertionError, subprocess.SubprocessError) as exc:
            report["host_error"] = str(exc)
        try:
            if gui:
                report["gui_animation"] = gui_animation(layout_path)
        except (RuntimeError, OSError, ValueError, subprocess.SubprocessError) as exc:
            report["gui_error"] = str(exc)
    measure_floors(report, rounds, quick, add)
    report["sweep"] = bench_sweep(paper, rounds, add, quick)
    report["contract"] = contract_entries(report)
    return report


def measure_floors(report, rounds, quick=False, add=None):
    """``report["floors"]`` from ``bench_floors``, or ``report["floors_error"]`` when a measure
    fails (a process that errs or times out, a floor that disagrees): the bench's other figures
    are kept and measured on. ``add``: each floor's row (workload "floor") as it is measured."""
    try:
        report["floors"] = bench_floors(rounds, quick, add)
    except (RuntimeError, OSError, AssertionError, subprocess.SubprocessError) as exc:
        report["floors_error"] = f"{type(exc).__name__}: {exc}"


def bench_floors(rounds, quick=False, add=None):
    """SPEC §9 amended (issue 30): what the same work costs written plainly, each beside the
    product's figure in interleaved rounds: fab's ``scan_layout`` and the closed form in plain
    Python (bench/fab_floor.py); `waferscan scan` of a scenario and the `freecadcmd` floor
    (bench/scenario_scan.py); `waferscan scan` of a 10,000-wafer layout (1,000 with
    ``quick``) and FreeCAD's own open + placement read of it (bench/documents.py)."""
    from .documents import bench_document_floor
    from .fab_floor import bench_fab_floor
    from .scenario_scan import bench_scenario_scan

    measures = {"fab": lambda: bench_fab_floor(rounds),
                "scenario": lambda: bench_scenario_scan(3 if quick else 7),
                "document": lambda: bench_document_floor(2 if quick else 3, quick=quick)}
    floors = {}
    for name, measure in measures.items():
        floors[name] = figure = measure()
        if add is not None:
            seconds = figure.get("scan", figure.get("scan_layout"))
            add({"workload": "floor", "engine": name, "seconds": seconds,
                 "floor_seconds": figure["floor"], "ratio": figure["ratio"]})
    return floors


def format_row(r):
    """One line of the bench's table."""
    if r["workload"] == "mcs":
        return (f"{r['workload']:<9} {r['engine']:<32} {r['history']:>9,} lines "
                f"{r['seconds'] * 1000:>10.3f} ms/s")
    if r["workload"] == "host":
        return (f"{r['workload']:<9} {r['engine']:<32} {r['carriers']:>9,} carriers "
                f"p50 {r['p50_ms']:>8.2f} ms  p99 {r['p99_ms']:>8.2f} ms")
    if r["workload"] == "floor":
        return (f"{r['workload']:<9} {r['engine']:<32} {r['seconds']:>12.6f} s  floor "
                f"{r['floor_seconds']:>10.6f} s  {r['ratio']:>6.2f}x")
    if r["workload"] == "sweep":
        return (f"{r['workload']:<9} {r['engine']:<32} {r['layouts']:>9,} layouts "
                f"{r['seconds']:>9.3f} s {r['layouts_per_minute']:>12,.0f} layouts/min")
    mark = f"  (sampled: {r['sampled_steps']:,} positions)" if r["sampled_steps"] else ""
    return (f"{r['workload']:<9} {r['engine']:<32} {r['steps']:>9,} steps "
            f"{r['wafers']:>6,} wafers {r['seconds']:>11.6f} s{mark}")
