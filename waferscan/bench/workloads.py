"""The workloads: what the bench times in this process, each figure's callable, on SPEC's
layouts, as a user waits for them.

- **What a user waits for.** ``scan_layout`` end to end (engine, naming of the runs, slot map),
  the document build and read; whole processes are in ``processes``, the MCS link as an MCS
  drives it in ``mcs_link``, the GUI's animation in ``animation``.
- **Measured, not extrapolated**, with one stated exception: an engine that would take minutes
  on a workload and is no contract figure (``loop`` at 270,001 positions and more) runs on every
  m-th position of the whole travel, which keeps the mix of positions near and far from the
  wafers, and its time is scaled by the number of positions (marked ``sampled``). Cutting the
  travel short instead would change which wafers the accessibility check keeps, and
  under-report. Per-step ``brep`` on fab, a contract figure, runs at every position (~15 s a
  round; ``--quick`` samples it): scaling a sample up scales the scan's fixed cost too.
- Every engine's stepped result is checked equal to ``analytic``'s on what it ran.

Workloads:
- ``paper``: the paper's experiment (SPEC §8), the document engines through a FreeCAD document
  with the robot; ``paper-spot``: the same with a 1 mm beam spot (SPEC §10);
- ``fab``: four FOUPs of 25 wafers side by side at the 505 mm load-port pitch, scanning the
  first at 0.001 mm steps (270,001 positions); ``fab-steps``: the same at other steps;
- ``steps``: the paper's layout at 10^3 ... 10^6 positions;
- ``wafers``: 100 ... 10,000 wafers as a *stack* of FOUPs one above the other (the beam meets
  every wafer: 10,000 runs to name) and as a *row* of FOUPs side by side (25 in the beam's
  reach), in process (``waferscan layout`` + ``waferscan scan`` of the stack as processes:
  ``processes``);
- ``sweep``: sampled layouts a minute of a tolerance sweep (SPEC §12), in process and on Dask.

FreeCAD and the sweep's Dask are imported inside the measures that need them: the layouts
serve plain-Python tests too.

Exports the layouts (``paper_layout``, ``fab_layout``, ``stack_scenario``, ``stack_layout``,
``spot_layout``, ``with_positions``, ``sampled``) and the measures (``bench_paper``,
``bench_spot``, ``bench_fab``, ``vector_peak_memory``, ``bench_steps``, ``bench_wafers``,
``bench_sweep``)."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

from ..addon import addon_root
from ..core.files.scenario import parse_scenario, read_scenario, seated_wafers
from ..core.scan.engines import run_engine
from ..core.scan.layout_scan import scan_layout
from ..core.sensor.spot import BeamSpot
from .rounds import interleaved, median_ratio, per_minute, row

__all__ = ["paper_layout", "fab_layout", "stack_scenario", "stack_layout", "spot_layout",
           "with_positions", "sampled", "bench_paper", "bench_spot", "bench_fab",
           "vector_peak_memory", "bench_steps", "bench_wafers", "bench_sweep"]

LOAD_PORT_PITCH = 505.0  # mm between neighbouring load ports (SEMI E15)
STACK_PITCH = 300.0  # mm between the slot 1 seats of FOUPs stacked one above the other
SWEEP_TOLERANCES = Path(addon_root()) / "resources" / "examples" / "fab_tolerances.toml"


# --- Layouts ------------------------------------------------------------------------------

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


def stack_scenario(foups, z_step=0.05):
    """Scenario text: ``foups`` full 25-slot FOUPs stacked ``STACK_PITCH`` apart (a stocker's
    shelves), the paper's beam scanning all of them, so every wafer makes a run of its own."""
    top = 293.94 + (foups - 1) * STACK_PITCH + 260.0
    lines = ["[scan]", 'carrier = "S1"', "start_z = 280.0", f"final_z = {top:.2f}",
             f"z_step = {z_step}", "[sensor]", "emitter = [-80.0, 266.6, 280.0]",
             "direction = [1.0, 0.0, 0.0]", "length = 160.0"]
    for index in range(foups):
        lines += ["[[carrier]]", f'name = "S{index + 1}"', "slots = 25", "pitch = 10.0",
                  f"first_slot_z = {293.94 + index * STACK_PITCH:.2f}", "center = [0.0, 400.0]",
                  "wafer_diameter = 300.0", "wafer_thickness = 0.7", "support_span = 292.5",
                  'load = "' + "1" * 25 + '"']
    return "\n".join(lines) + "\n"


def stack_layout(foups):
    return parse_scenario(stack_scenario(foups), "<stack>")


def with_positions(layout, count):
    """The layout with its travel cut into ``count`` positions."""
    travel = layout.scan.final_z - layout.scan.start_z
    return layout.with_scan(z_step=travel / (count - 1))


def sampled(layout, every):
    """Every ``every``-th position of the layout's scan, over the whole travel."""
    return layout.with_scan(z_step=layout.scan.z_step * every)


def spot_layout(paper):
    """The layout with a 1 mm round beam spot (SPEC §10) at the default accuracy."""
    return replace(paper, spot=BeamSpot(diameter=1.0))


def _runs(result):
    """The (z_in, z_out) edges of a scan's runs."""
    return [(r.z_in, r.z_out) for r in result.runs]


def _check(result, reference, what, on=None):
    """Raise AssertionError unless ``result`` equals ``analytic``'s ``reference``."""
    if result != reference:
        raise AssertionError(f"{what} differs from analytic" + (f" on {on}" if on else ""))


# --- In-process workloads -----------------------------------------------------------------

def bench_paper(scenario_path, rounds, add):
    """The paper: analytic, vector and loop (engine calls and scan_layout end to end), and the
    document and brep engines through a FreeCAD document with the robot, interleaved."""
    import FreeCAD as App

    from ..cad.document_scan import scan_document
    from ..cad.layout_files import open_layout

    paper = paper_layout(scenario_path)
    reference = run_engine("analytic", paper)
    doc = open_layout(scenario_path)
    try:
        tasks = {
            "analytic": lambda: run_engine("analytic", paper),
            "vector": lambda: run_engine("vector", paper),
            "loop": lambda: run_engine("loop", paper),
            "analytic scan_layout": lambda: scan_layout(paper, "analytic"),
            "loop scan_layout": lambda: scan_layout(paper, "loop"),
            "document": lambda: scan_document(doc, "document"),
            "brep": lambda: scan_document(doc, "brep"),
            # SPEC §15: the same fast scan through the document with and without the robot's
            # clearance check (issue 29: it may add at most 2x).
            "analytic document": lambda: scan_document(doc, "analytic"),
            "analytic document, no clearance": lambda: scan_document(doc, "analytic",
                                                                     clearance=False),
        }
        times, results = interleaved(tasks, rounds,
                                     batch={"analytic": 50, "analytic scan_layout": 50,
                                            "analytic document": 20,
                                            "analytic document, no clearance": 20})
        expected = _runs(scan_document(doc, "analytic"))
    finally:
        App.closeDocument(doc.Name)
    for name in ("analytic", "vector", "loop"):
        _check(results[name], reference, f"{name} on the paper")
    for name in ("document", "brep", "loop scan_layout"):
        _check(_runs(results[name]), expected, name, on="the paper")
    if results["analytic document"].clearance is None \
            or results["analytic document, no clearance"].clearance is not None:
        raise AssertionError("the clearance rows did not time what they are named for")
    for name in tasks:
        add(row("paper", name, paper, times[name]))
    return {"loop/analytic": median_ratio(times["loop"], times["analytic"]),
            "clearance": median_ratio(times["analytic document"],
                                      times["analytic document, no clearance"]),
            "loop/analytic scan_layout": median_ratio(times["loop scan_layout"],
                                                      times["analytic scan_layout"])}


def bench_fab(paper, rounds, add, loop_every=100, brep_every=1):
    """Four FOUPs at 0.001 mm: scan_layout end to end, vector and per-step brep in full (all
    270,001 positions; ``brep_every`` > 1 samples it, for a quick run), loop sampled over the
    whole travel; scan_layout at other steps (flat?). Returns the brep / analytic ratio, the
    median of the rounds' ratios."""
    import FreeCAD as App

    from ..cad.builder import build_document
    from ..cad.document_scan import scan_document
    from ..core.files.mcs import Parameters

    fab = fab_layout(paper)
    reference = run_engine("analytic", fab)
    loop_part = sampled(fab, loop_every)
    loop_reference = run_engine("analytic", loop_part)
    brep_step = fab.scan.z_step * brep_every
    doc = build_document(fab, name="BenchFab")
    try:
        # brep_every = 1: fab's own z_step, every position. A sample scaled up would scale the
        # scan's fixed cost (reading the document, ~20 ms) by the sampling factor too: every
        # 100th position scaled gave 16.9 s where the whole scan took 15.0 s.
        brep_parameters = Parameters({"z_step": brep_step}, {}, "bench")
        brep_expected = _runs(scan_document(doc, "analytic", parameters=brep_parameters))
        tasks = {"analytic scan_layout": lambda: scan_layout(fab, "analytic"),
                 "vector": lambda: run_engine("vector", fab),
                 "loop": lambda: run_engine("loop", loop_part),
                 "brep": lambda: scan_document(doc, "brep", parameters=brep_parameters)}
        # 200 analytic scans a round (~0.05 s): a batch long enough for the machine's noise
        times, results = interleaved(tasks, rounds, batch={"analytic scan_layout": 200})
    finally:
        App.closeDocument(doc.Name)
    _check(results["vector"], reference, "vector on fab")
    _check(results["loop"], loop_reference, "loop on fab")
    brep = results["brep"]
    _check(_runs(brep), brep_expected, "brep", on="fab")
    add(row("fab", "analytic scan_layout", fab, times["analytic scan_layout"]))
    add(row("fab", "vector", fab, times["vector"]))
    add(row("fab", "loop", fab, times["loop"], sampled_steps=loop_part.scan.position_count))
    brep_steps = brep.layout.scan.position_count
    add(row("fab", "brep", fab, times["brep"],
            sampled_steps=brep_steps if brep_steps != fab.scan.position_count else None))
    brep_ratio = median_ratio([t * fab.scan.position_count / brep_steps for t in times["brep"]],
                              times["analytic scan_layout"])

    # Flat in the steps: the same scan at 5,401 ... 2,700,001 positions.
    steps = (0.05, 0.005, 0.001, 0.0001)
    layouts = {z: fab.with_scan(z_step=z) for z in steps}
    times, _ = interleaved({z: (lambda lay=lay: scan_layout(lay, "analytic"))
                            for z, lay in layouts.items()}, max(5, rounds),
                           batch={z: 20 for z in steps})
    for z in steps:
        add(row("fab-steps", "analytic scan_layout", layouts[z], times[z], z_step=z))
    return brep_ratio


def vector_peak_memory(paper):
    """Peak memory (bytes, numpy's allocations traced) of the vector engine on the fab
    workload."""
    import tracemalloc

    fab = fab_layout(paper)
    tracemalloc.start()
    try:
        run_engine("vector", fab)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def bench_steps(paper, counts, rounds, add, loop_measured_up_to=10_000):
    """The paper's layout at more and more positions: analytic and vector measured in full,
    loop in full up to ``loop_measured_up_to`` positions and sampled beyond."""
    for count in counts:
        layout = with_positions(paper, count)
        reference = run_engine("analytic", layout)
        every = max(1, count // loop_measured_up_to)
        loop_part = sampled(layout, every) if every > 1 else layout
        tasks = {"analytic": lambda lay=layout: run_engine("analytic", lay),
                 "vector": lambda lay=layout: run_engine("vector", lay),
                 "loop": lambda lay=loop_part: run_engine("loop", lay)}
        times, results = interleaved(tasks, rounds, batch={"analytic": 20})
        _check(results["vector"], reference, f"vector at {count} positions")
        _check(results["loop"], run_engine("analytic", loop_part), f"loop at {count} positions")
        add(row("steps", "analytic", layout, times["analytic"]))
        add(row("steps", "vector", layout, times["vector"]))
        add(row("steps", "loop", layout, times["loop"],
                sampled_steps=loop_part.scan.position_count if every > 1 else None))


def bench_wafers(paper, foup_counts, rounds, build_up_to, add):
    """scan_layout against the number of wafers, stacked and in a row, interleaved; the
    document build and read (in process) of the stack."""
    import FreeCAD as App

    from ..cad.builder import build_document
    from ..cad.reader import read_layout

    layouts = {}
    for foups in foup_counts:
        layouts[("stack", foups)] = stack_layout(foups)
        layouts[("row", foups)] = fab_layout(paper, foups=foups, z_step=paper.scan.z_step)
    tasks = {key: (lambda lay=lay: scan_layout(lay, "analytic")) for key, lay in layouts.items()}
    times, results = interleaved(tasks, rounds)
    for (kind, foups), layout in layouts.items():
        if kind == "stack" and len(results[(kind, foups)].runs) != 25 * foups:
            raise AssertionError(f"the stack of {foups} FOUPs gave "
                                 f"{len(results[(kind, foups)].runs)} runs")
        add(row("wafers", f"analytic scan_layout ({kind})", layout, times[(kind, foups)]))
    for foups in foup_counts:
        if 25 * foups > build_up_to:
            continue
        layout = layouts[("stack", foups)]
        start = time.perf_counter()
        doc = build_document(layout, name="BenchStack")
        built = time.perf_counter()
        read = read_layout(doc)
        done = time.perf_counter()
        App.closeDocument(doc.Name)
        if len(read.wafers) != len(layout.wafers):
            raise AssertionError("the stack's document lost wafers")
        add(row("wafers", "document build", layout, [built - start]))
        add(row("wafers", "document read", layout, [done - built]))


def bench_spot(paper, rounds, add):
    """SPEC §10: the paper's layout with a 1 mm round beam spot at the default accuracy
    (threshold 0.5), on the step grid and with exact edges, beside the ideal beam,
    ``scan_layout`` end to end, interleaved. Rows ``paper-spot``; returns the medians in
    seconds (the contract: <= 20 ms)."""
    spot = spot_layout(paper)
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


def _stroke_body(paper):
    """The paper robot's collision geometry reduced for a sweep's [clearance] report, or None
    without Pinocchio (the contact-rate figure is then not measured)."""
    from ..addon import MissingPinocchio

    try:
        from ..robot.sweep_clearance import stroke_body
    except (ImportError, MissingPinocchio):
        return None
    return stroke_body(paper)


def merge_seconds(rounds, partitions=1000, layouts=100_000_000, kinds=2):
    """SPEC §9: the median seconds of the client's merge of ``partitions`` digests of a sweep
    of ``layouts`` (synthetic: each partition's margins every DIGEST_STRIDE-th one of a normal
    draw, as a partition's digest holds them), for ``kinds`` kinds of margin: the brackets of
    the summary's order statistics, the part of the merge that grows with the partitions."""
    import numpy as np

    from ..core.sweep import reduction

    rng = np.random.default_rng(0)
    each = layouts // partitions
    digests = []
    for _ in range(partitions):
        margins = {}
        for k in range(kinds):
            samples = np.sort(rng.normal(0.2, 0.05, each // reduction.DIGEST_STRIDE + 1))
            margins[f"kind {k}"] = {"count": each, "stride": reduction.DIGEST_STRIDE,
                                    "samples": samples, "min": float(samples[0]),
                                    "max": float(samples[-1])}
        digests.append({"margins": margins})
    ranks = [0, layouts // 100, layouts // 2, layouts - 1]
    taken = []
    for _ in range(max(3, rounds)):
        start = time.perf_counter()
        for key in digests[0]["margins"]:
            reduction._brackets(digests, key, ranks)
        taken.append(time.perf_counter() - start)
    return float(np.median(taken))


def bench_sweep(paper, rounds, add, quick=False):
    """SPEC §9 / §12: sampled layouts a minute of a sweep of the paper's 25-slot FOUP under
    resources/examples/fab_tolerances.toml (seat, thickness, protrusion, beam height and tilt,
    response time, every state drawn): the library function in this process with the ideal
    beam and with a 1 mm spot, and the ideal beam's with its [clearance] report (the rate of
    layouts with a contact, SPEC §15; with Pinocchio), interleaved; then a Dask LocalCluster of 1 worker against one of
    2 (both started before the timing, as a user's cluster is), interleaved. Rows ``sweep``;
    returns {name: layouts a minute} and the 2-worker / 1-worker ratio."""
    from ..core import sweep
    from ..core.sweep.distributions import read_tolerances
    from ..sweep import DaskPartitions, local_cluster

    tolerances = read_tolerances(SWEEP_TOLERANCES)
    spot = spot_layout(paper)
    n_ideal = 20_000 if quick else 100_000
    n_spot = 100 if quick else 500
    # The same tolerances but a level beam: a tilted beam takes translation_range's general
    # (corner) path in every column of the spot, a level one its closed form (docs/performance.md).
    level = replace(tolerances, quantities={k: v for k, v in tolerances.quantities.items()
                                            if k != "beam_tilt"})
    from .sweep_floor import floor_sweep

    tasks = {
        "ideal beam, in process": lambda: sweep.run_sweep(paper, tolerances, n_ideal, seed=1),
        # SPEC §9 amended: the floor beside it (a plain numpy draw + scan + map of as many
        # layouts), and the same sweep without the beam's tilt
        "numpy floor, in process": lambda: floor_sweep(paper, tolerances, n_ideal, seed=1),
        "ideal beam, level beam": lambda: sweep.run_sweep(paper, level, n_ideal, seed=1),
        "1 mm spot, in process": lambda: sweep.run_sweep(spot, tolerances, n_spot, seed=1),
        "1 mm spot, level beam": lambda: sweep.run_sweep(spot, level, n_spot, seed=1),
    }
    measured = [("ideal beam, in process", n_ideal, paper),
                ("numpy floor, in process", n_ideal, paper),
                ("ideal beam, level beam", n_ideal, paper),
                ("1 mm spot, in process", n_spot, spot),
                ("1 mm spot, level beam", n_spot, spot)]
    body = _stroke_body(paper)
    if body is not None:  # SPEC §15: the same sweep with its [clearance] report
        from ..core.sweep.clearance import ClearanceStudy

        contact = replace(tolerances, clearance=ClearanceStudy())
        tasks["contact rate, in process"] = lambda: sweep.run_sweep(
            paper, contact, n_ideal, seed=1, clearance_body=body)
        measured.append(("contact rate, in process", n_ideal, paper))
    times, results = interleaved(tasks, max(1, rounds // 3))
    rates = {"merge of 1,000 partitions (s)": merge_seconds(rounds),
             "ideal beam / numpy floor": median_ratio(times["ideal beam, in process"],
                                                      times["numpy floor, in process"]),
             "beam tilt / level beam": median_ratio(times["ideal beam, in process"],
                                                    times["ideal beam, level beam"])}
    for name, n, layout in measured:
        rates[name] = per_minute(n, times[name])
        add(row("sweep", name, layout, times[name], layouts=n,
                layouts_per_minute=rates[name]))
    from distributed import Client

    clusters = {k: local_cluster(k) for k in (1, 2)}
    clients = {k: Client(c) for k, c in clusters.items()}
    try:
        def on(k):
            parts = sweep.partitions(n_ideal, k * 4)
            runner = DaskPartitions(clients[k], lambda i: sweep.layouts_in(n_ideal, parts[i]))
            return sweep.run_sweep(paper, tolerances, n_ideal, seed=1, partition_count=k * 4,
                                   runner=runner)

        # Each worker's first task imports waferscan and numpy's first allocations (a partition
        # took 2.5 s there against 1.85-1.9 s after), and a fresh worker's first sweep faults
        # its memory in; a user's cluster has done that before the next sweep, and the figure
        # compares the work divided, so each cluster runs one whole sweep untimed first.
        for k in (1, 2):
            on(k)
        dask_tasks = {f"Dask {k} worker{'s' if k > 1 else ''}": (lambda k=k: on(k))
                      for k in (1, 2)}
        dask_times, dask_results = interleaved(dask_tasks, max(2, rounds // 2))
    finally:
        for k in clients:
            clients[k].close()
            clusters[k].close()
    if len({json.dumps(r, sort_keys=True) for r in
            list(dask_results.values()) + [results["ideal beam, in process"]]}) != 1:
        raise AssertionError("the sweep's summary differs between Dask and in process")
    for name, taken in dask_times.items():
        rates[name] = per_minute(n_ideal, taken)
        add(row("sweep", name, paper, taken, layouts=n_ideal, layouts_per_minute=rates[name]))
    rates["2/1 workers"] = median_ratio(dask_times["Dask 1 worker"], dask_times["Dask 2 workers"])
    return rates

