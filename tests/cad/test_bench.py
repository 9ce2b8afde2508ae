"""The bench measures what it says: its workloads are the SPEC's, every engine's result is
checked against analytic, what is sampled is marked and scaled by the positions, rounds are
interleaved, and the MCS figures come from a real `waferscan watch` process. No timing is
asserted here."""

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from waferscan import bench
from waferscan.addon import paper_scenario
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import engines

PAPER = read_scenario(paper_scenario())
REPO = Path(__file__).resolve().parents[2]


def test_fab_workload_is_four_full_foups_at_a_micrometre():
    fab = bench.fab_layout(PAPER)
    assert len(fab.carriers) == 4 and len(fab.wafers) == 100
    assert fab.scan.position_count == 270_001
    assert [c.center[0] for c in fab.carriers] == [0.0, 505.0, 1010.0, 1515.0]
    hits = engines.analytic_engine(fab)
    assert len(hits.runs) == 25  # only the scanned FOUP is in the beam's reach


def test_steps_workload_has_the_asked_positions():
    for count in (1_000, 10_000, 1_000_000):
        assert bench.with_positions(PAPER, count).scan.position_count == count


def test_the_stack_is_400_foups_for_10000_wafers():
    stack = bench.stack_layout(400)
    assert len(stack.wafers) == 10_000 and len(stack.carriers) == 400
    assert stack.scan.final_z > max(w.center[2] for w in stack.wafers)


def test_sampling_keeps_the_whole_travel_and_scales_by_the_positions():
    fab = bench.fab_layout(PAPER)
    part = bench.sampled(fab, 100)
    assert part.scan.start_z == fab.scan.start_z
    assert part.scan.position(part.scan.last_step) == pytest.approx(fab.scan.final_z)
    assert part.scan.position_count == 2_701
    r = bench.row("fab", "loop", fab, [1.0, 3.0, 2.0], sampled_steps=2_701)
    assert r["seconds"] == pytest.approx(2.0 * 270_001 / 2_701)
    assert r["extrapolated"] and r["rounds"] == 3 and r["steps"] == 270_001


def test_rounds_are_interleaved_in_turning_order():
    calls = []
    tasks = {name: (lambda n=name: calls.append(n) or n) for name in "abc"}
    times, results = bench.interleaved(tasks, 3, batch={"b": 4})
    assert calls == ["a", "b", "b", "b", "b", "c",
                     "b", "b", "b", "b", "c", "a",
                     "c", "a", "b", "b", "b", "b"]
    assert {k: len(v) for k, v in times.items()} == {"a": 3, "b": 3, "c": 3}
    assert results == {"a": "a", "b": "b", "c": "c"}
    assert bench.median_ratio([4.0, 9.0, 1.0], [2.0, 3.0, 1.0]) == 2.0


def test_a_wrong_engine_is_caught(monkeypatch):
    broken = engines.ENGINES["vector"]

    def off_by_one(layout, progress=None):
        hits = broken(layout, progress)
        return replace(hits, runs=tuple((a + 1, b) for a, b in hits.runs))

    monkeypatch.setitem(engines.ENGINES, "vector", off_by_one)
    with pytest.raises(AssertionError, match="vector at 1000 positions differs from analytic"):
        bench.bench_steps(PAPER, (1_000,), 1, lambda row: None)


def test_the_paper_round_checks_every_engine():
    rows = []
    ratios = bench.bench_paper(paper_scenario(), 1, rows.append)
    assert {r["engine"] for r in rows} == {"analytic", "vector", "loop", "analytic scan_layout",
                                           "loop scan_layout", "document", "brep",
                                           "analytic document",
                                           "analytic document, no clearance"}
    assert all(r["steps"] == 5401 and not r["extrapolated"] for r in rows)
    assert ratios["loop/analytic"] > 1
    # SPEC §15: the bench times the fast scan with and without the clearance check; that the
    # two rows timed what they say is asserted here, how far apart they are is the bench's figure
    # (one round on a loaded machine can put either ahead).
    assert ratios["clearance"] > 0


def test_processes_run_this_checkout(tmp_path):
    rows = []
    bench.bench_processes(tmp_path, (1,), rows.append)
    assert [(r["engine"], r["wafers"]) for r in rows] == [("waferscan layout", 25),
                                                          ("waferscan scan", 25)]


@pytest.fixture(scope="module")
def saved_paper(tmp_path_factory):
    return bench.saved_layout(paper_scenario(), tmp_path_factory.mktemp("layout"))


def test_mcs_figures_come_from_a_watcher_process(saved_paper):
    latency = bench.mcs_latency(saved_paper, 3)
    assert len(latency) == 3 and all(0 < s < 30 for s in latency)
    with bench.answered_histories(saved_paper, (10, 1_000)) as folders:
        poll = bench.mcs_poll_cost(folders, rounds=2, polls=50)
        idle = bench.mcs_idle(saved_paper, folders, 0.5, rounds=2, settle=1.0)
    assert sorted(idle) == [10, 1_000]
    assert all(0 <= v < 2.0 for v in idle.values())  # CPU seconds a second, two cores at most
    assert sorted(poll) == [10, 1_000] and all(0 < v < 0.01 for v in poll.values())
    soak = bench.mcs_soak(saved_paper, 20, batch=10)
    assert [n for n, _ in soak["samples"]] == [10, 20]
    assert soak["rss_end"] > 10e6


def _report():
    def r(workload, engine, seconds, wafers=100, steps=270_001, **extra):
        return {"workload": workload, "engine": engine, "steps": steps, "wafers": wafers,
                "seconds": seconds, "rounds": 3, "sampled_steps": None,
                "extrapolated": False, **extra}

    rows = [r("fab", "analytic scan_layout", 0.0004), r("fab", "brep", 50.0),
            r("fab-steps", "analytic scan_layout", 0.0004, steps=5_401),
            r("fab-steps", "analytic scan_layout", 0.0009, steps=2_700_001),
            r("wafers", "analytic scan_layout (stack)", 0.01, wafers=1_000),
            r("wafers", "analytic scan_layout (stack)", 0.3, wafers=10_000),
            r("wafers", "waferscan layout", 12.0, wafers=10_000),
            r("wafers", "waferscan scan", 3.0, wafers=10_000),
            r("startup", "freecadcmd import Part, numpy", 0.2, wafers=10, steps=5_401),
            r("startup", "waferscan scan", 0.2, wafers=10, steps=5_401),
            r("startup", "freecadcmd -c waferscan scan", 0.25, wafers=10, steps=5_401)]
    return {"results": rows,
            "ratios": {"loop/analytic": 1200.0, "loop/analytic scan_layout": 1100.0},
            "mcs": {"latency_samples": [0.01] * 99 + [0.2], "latency_median": 0.01,
                    "latency_p99": 0.01, "idle_cpu_per_second": {"10": 0.001, "100000": 0.5},
                    "idle_poll_seconds": {"10": 20e-6, "100000": 40e-6},
                    "soak": {"commands": 10_000, "growth_bytes": 2e6,
                             "growth_per_command_bytes": 200.0}},
            "gui_animation": {"updates_per_second": 50.0, "max_stall": 0.05}}


def test_contract_reads_the_report():
    met = [ok for ok, _ in bench.contract(_report())]
    # loop, brep, fab 5 ms, flat, linear, 20 s, scan 1.2x, freecadcmd 1.2x, p99, median 5 ms,
    # idle CPU, idle poll the same, memory, GUI, sweeps
    assert met == [True, True, True, False, False, True, True, False, True, False, True, False,
                   True, False, None]
    # SPEC §9 amended: the loop's ratio is judged end to end, what a user waits for
    report = _report()
    report["ratios"]["loop/analytic scan_layout"] = 990.0
    ok, text = bench.contract(report)[0]
    assert not ok and text.startswith("analytic vs loop on the paper, scan_layout end to end: "
                                      "990x (>= 1,000x") and "engine calls alone 1,200x" in text


def test_the_plot_draws_in_the_venv_and_in_freecad(tmp_path):
    report = _report()
    report["results"] += [
        {"workload": "mcs", "engine": "watch idle (CPU s per s)", "steps": None,
         "wafers": None, "history": h, "seconds": s, "rounds": 1, "sampled_steps": None,
         "extrapolated": False} for h, s in ((10, 0.001), (100_000, 0.5))]
    venv_png = tmp_path / "venv.png"
    bench.plot(report, venv_png)
    source = tmp_path / "bench.json"
    source.write_text(json.dumps(report))
    freecad_png = tmp_path / "freecad.png"
    # Inside FreeCAD Debian's matplotlib and numpy 1.24 come first.
    script = (f"import json, sys; sys.path.insert(0, {str(REPO)!r}); "
              f"import matplotlib, waferscan.bench as b; "
              f"b.plot(json.load(open({str(source)!r})), {str(freecad_png)!r}); "
              f"print('matplotlib', matplotlib.__file__)")
    done = subprocess.run(["freecadcmd", "-c", script], check=True, capture_output=True,
                          text=True, timeout=120)
    assert "matplotlib /usr/lib/python3/dist-packages/" in done.stdout
    scripted = tmp_path / "script.png"
    subprocess.run([sys.executable, str(REPO / "scripts" / "plot_bench.py"), str(source),
                    str(scripted)], check=True, capture_output=True, timeout=120)
    for png in (venv_png, freecad_png, scripted):
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
