"""``waferscan bench``: the engines side by side on the same workloads, in one process.

Workloads:
- ``paper``: the paper's experiment (SPEC §8), every engine, the document engines through a
  FreeCAD document with the robot;
- ``fab``: four FOUPs of 25 wafers side by side at the 505 mm load-port pitch, scanning one of
  them at 0.001 mm steps (270,001 positions);
- ``steps``: the paper's layout at 10^3 ... 10^6 positions;
- ``wafers``: 25 ... 2,500 wafers (1 ... 100 full FOUPs) at the paper's steps.

Every run's stepped results are checked equal to ``analytic``'s. Times are the median of several
repeats. An engine too slow for a workload runs on a subset of its steps and is extrapolated to
the whole, and marked so.
"""

from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from .core.engines import run_engine
from .core.scenario import read_scenario, seated_wafers

LOAD_PORT_PITCH = 505.0  # mm between neighbouring load ports (SEMI E15)


def paper_layout(path):
    return read_scenario(path)


def fab_layout(paper, foups=4, z_step=0.001):
    """``foups`` full FOUPs in a row, the first being the paper's; scanning the first."""
    first = paper.scanned_carrier
    carriers, wafers = [], []
    for index in range(foups):
        carrier = replace(first, name=f"LP{index + 1}",
                          center=(first.center[0] + index * LOAD_PORT_PITCH, first.center[1]))
        carriers.append(carrier)
        for slot in range(1, carrier.slot_count + 1):
            wafers += seated_wafers(carrier, slot, "present", slot)
    return replace(paper, carriers=tuple(carriers), wafers=tuple(wafers), carrier="LP1",
                   robot=None, scan=replace(paper.scan, z_step=z_step))


def with_positions(layout, count):
    """The layout with its travel cut into ``count`` positions."""
    travel = layout.scan.final_z - layout.scan.start_z
    return layout.with_scan(z_step=travel / (count - 1))


def _time(function, repeats):
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def _subset(layout, positions):
    """The first ``positions`` steps of the layout's scan."""
    scan = layout.scan
    return layout.with_scan(final_z=scan.start_z + (positions - 1) * scan.z_step)


def run_core(workload, layout, engine, repeats=5, budget_positions=None, reference=None):
    """Time a core engine; with ``budget_positions`` it runs on that many steps only and the
    time is scaled to the whole. Checks the result against ``reference`` when whole."""
    positions = layout.scan.position_count
    partial = budget_positions is not None and budget_positions < positions
    target = _subset(layout, budget_positions) if partial else layout
    seconds, hits = _time(lambda: run_engine(engine, target), repeats)
    if partial:
        reference_part = run_engine("analytic", target)
        assert hits == reference_part, f"{engine} differs from analytic on {workload}"
        seconds *= positions / target.scan.position_count
    elif reference is not None:
        assert hits == reference, f"{engine} differs from analytic on {workload}"
    return {"workload": workload, "engine": engine, "steps": positions,
            "wafers": len(layout.wafers), "seconds": seconds, "extrapolated": partial}


def run_document(workload, scenario_path, engine, repeats=3, budget_positions=None):
    """Time a document engine on the scenario built into a FreeCAD document (robot included).
    The ``brep`` engine runs on the first ``budget_positions`` steps and is extrapolated."""
    import FreeCAD as App

    from .cad.document_scan import scan_document
    from .cad.layout_files import open_layout
    from .core.mcs import Parameters

    doc = open_layout(scenario_path)
    try:
        full = scan_document(doc, "analytic")
        positions = full.layout.scan.position_count
        parameters = None
        if budget_positions is not None and budget_positions < positions:
            scan = full.layout.scan
            final = scan.start_z + (budget_positions - 1) * scan.z_step
            parameters = Parameters({"final_z": final}, {}, "bench")
        seconds, result = _time(lambda: scan_document(doc, engine, parameters=parameters),
                                repeats)
        reference = scan_document(doc, "analytic", parameters=parameters)
        assert [(r.z_in, r.z_out) for r in result.runs] == \
            [(r.z_in, r.z_out) for r in reference.runs], f"{engine} differs from analytic"
        done = result.layout.scan.position_count
        return {"workload": workload, "engine": engine, "steps": positions,
                "wafers": len(full.layout.wafers), "seconds": seconds * positions / done,
                "extrapolated": done < positions}
    finally:
        App.closeDocument(doc.Name)


def run_bench(scenario_path, quick=False, progress=print):
    """All workloads; returns the list of result rows."""
    rows = []

    def add(row):
        rows.append(row)
        progress(row)

    paper = paper_layout(scenario_path)
    reference = run_engine("analytic", paper)
    for engine in ("analytic", "vector", "loop"):
        add(run_core("paper", paper, engine, repeats=3 if engine == "loop" else 7,
                     reference=reference))
    add(run_document("paper", scenario_path, "document", repeats=1 if quick else 3))
    add(run_document("paper", scenario_path, "brep", repeats=1,
                     budget_positions=1000 if quick else 2000))

    fab = fab_layout(paper)
    fab_reference = run_engine("analytic", fab)
    add(run_core("fab", fab, "analytic", repeats=21, reference=fab_reference))
    add(run_core("fab", fab, "vector", repeats=1, budget_positions=None if not quick else 20_000,
                 reference=fab_reference))
    add(run_core("fab", fab, "loop", repeats=1, budget_positions=2_000))

    step_counts = (1_000, 10_000, 100_000) if quick else (1_000, 10_000, 100_000, 1_000_000)
    for count in step_counts:
        layout = with_positions(paper, count)
        ref = run_engine("analytic", layout)
        add(run_core("steps", layout, "analytic", repeats=9, reference=ref))
        add(run_core("steps", layout, "vector", repeats=1 if count > 10_000 else 3,
                     budget_positions=None if count <= 100_000 else 100_000, reference=ref))
        add(run_core("steps", layout, "loop", repeats=1, budget_positions=min(count, 2_000),
                     reference=ref if count <= 2_000 else None))
    foup_counts = (1, 4, 10) if quick else (1, 4, 10, 40, 100)
    for foups in foup_counts:
        layout = fab_layout(paper, foups=foups, z_step=paper.scan.z_step)
        ref = run_engine("analytic", layout)
        add(run_core("wafers", layout, "analytic", repeats=5, reference=ref))
        add(run_core("wafers", layout, "vector", repeats=1, reference=ref))
        add(run_core("wafers", layout, "loop", repeats=1, budget_positions=500))
    return rows


def saved_layout(scenario_path, folder):
    """The scenario built and saved as a .FCStd in ``folder`` (as `waferscan layout` does)."""
    import FreeCAD as App

    from .cad.layout_files import open_layout, save_document

    path = Path(folder) / "bench-layout.FCStd"
    doc = open_layout(scenario_path)
    try:
        save_document(doc, path)
    finally:
        App.closeDocument(doc.Name)
    return path


def _command_seconds(command, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def startup(layout_path, steps, wafers, repeats=7):
    """Headless `waferscan scan LAYOUT.FCStd` against `freecadcmd -c "import Part, numpy"`,
    the floor of any FreeCAD script that touches solids and arrays."""
    script = Path(sys.executable).with_name("waferscan")
    scan = [str(script)] if script.exists() else [sys.executable, "-m", "waferscan.cli"]
    rows = []
    for engine, command in (("freecadcmd import Part, numpy",
                             ["freecadcmd", "-c", "import Part, numpy"]),
                            ("waferscan scan", scan + ["scan", str(layout_path)])):
        rows.append({"workload": "startup", "engine": engine, "steps": steps, "wafers": wafers,
                     "seconds": _command_seconds(command, repeats), "extrapolated": False})
    return rows


def gui_animation(layout_path, seconds=3.0):
    """Placement updates a second, and the longest stall, of the robot stepping through the
    layout in a real FreeCAD GUI (under Xvfb when there is no display). None without FreeCAD's
    GUI or Xvfb."""
    freecad = shutil.which("freecad")
    if freecad is None:
        return None
    command = [freecad, str(Path(__file__).with_name("gui") / "animation_bench.py")]
    if not os.environ.get("DISPLAY"):
        if shutil.which("xvfb-run") is None:
            return None
        command = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24"] + command
    with tempfile.TemporaryDirectory() as folder:
        result_path = Path(folder) / "result.json"
        env = dict(os.environ, WAFERSCAN_BENCH_LAYOUT=str(layout_path),
                   WAFERSCAN_BENCH_RESULT=str(result_path), WAFERSCAN_BENCH_SECONDS=str(seconds),
                   QTWEBENGINE_DISABLE_SANDBOX="1")
        subprocess.run(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       timeout=180, start_new_session=True)
        result = json.loads(result_path.read_text())
    if not result.get("ok"):
        raise RuntimeError(f"the GUI animation bench failed: {result.get('error')}")
    return result


def format_rows(rows):
    lines = [f"{'workload':<9} {'engine':<9} {'steps':>9} {'wafers':>7} {'seconds':>12}"]
    for r in rows:
        mark = "  (extrapolated)" if r["extrapolated"] else ""
        lines.append(f"{r['workload']:<9} {r['engine']:<9} {r['steps']:>9} {r['wafers']:>7} "
                     f"{r['seconds']:>12.6f}{mark}")
    return "\n".join(lines)


def contract(rows, gui=None):
    """SPEC §9's figures from the rows (and the GUI measurement): list of (met, text)."""
    def seconds(workload, engine, steps=None, wafers=None):
        for r in rows:
            if (r["workload"], r["engine"]) == (workload, engine) and \
                    (steps is None or r["steps"] == steps) and \
                    (wafers is None or r["wafers"] == wafers):
                return r["seconds"]
        return None

    ratio = seconds("paper", "loop") / seconds("paper", "analytic")
    fab = seconds("fab", "analytic")
    flat = [r["seconds"] for r in rows if (r["workload"], r["engine"]) == ("steps", "analytic")]
    spread = max(flat) / min(flat)
    floor = seconds("startup", "freecadcmd import Part, numpy")
    scan = seconds("startup", "waferscan scan")
    checks = [(ratio >= 200, f"analytic is {ratio:,.0f}x faster than loop on the paper "
                           "(>= 200x), identical results"),
            (fab <= 0.005, f"fab (4 FOUPs x 25 wafers, 270,001 positions): analytic "
                           f"{fab * 1000:.2f} ms (<= 5 ms)"),
            (spread < 2.0, f"analytic from 10^3 to {max(r['steps'] for r in rows if r['workload'] == 'steps'):,} "
                           f"positions: slowest / fastest = {spread:.2f} (flat)")]
    if floor is not None and scan is not None:
        checks.append((scan <= 1.2 * floor, f"headless waferscan scan of a saved layout: "
                                            f"{scan:.3f} s = {scan / floor:.2f}x freecadcmd -c "
                                            f"\"import Part, numpy\" ({floor:.3f} s) (<= 1.2x)"))
    if gui is not None:
        checks.append((gui["updates_per_second"] >= 30 and gui["max_stall"] <= 0.1,
                       f"GUI animation: {gui['updates_per_second']:.1f} placement updates a "
                       f"second (>= 30), longest stall {gui['max_stall'] * 1000:.0f} ms (<= 100)"))
    return checks
