"""The bench measures what it says: its workloads are the SPEC's, every engine's result is
checked against analytic, and what is extrapolated is marked. No timing is asserted here."""

from dataclasses import replace

import pytest

from waferscan import bench
from waferscan.cli import paper_scenario
from waferscan.core import engines
from waferscan.core.scenario import read_scenario

PAPER = read_scenario(paper_scenario())


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


def test_extrapolated_runs_are_marked_and_checked():
    fab = bench.fab_layout(PAPER)
    row = bench.run_core("fab", fab, "loop", repeats=1, budget_positions=300)
    assert row["extrapolated"] and row["steps"] == 270_001 and row["wafers"] == 100
    whole = bench.run_core("paper", PAPER, "vector", repeats=1,
                           reference=engines.analytic_engine(PAPER))
    assert not whole["extrapolated"] and whole["seconds"] > 0


def test_a_wrong_engine_is_caught(monkeypatch):
    broken = engines.ENGINES["vector"]

    def off_by_one(layout, progress=None):
        hits = broken(layout, progress)
        return replace(hits, runs=tuple((a + 1, b) for a, b in hits.runs))

    monkeypatch.setitem(engines.ENGINES, "vector", off_by_one)
    with pytest.raises(AssertionError, match="vector differs from analytic on paper"):
        bench.run_core("paper", PAPER, "vector", repeats=1,
                       reference=engines.analytic_engine(PAPER))


def test_document_engines_in_the_bench():
    row = bench.run_document("paper", paper_scenario(), "brep", repeats=1, budget_positions=300)
    assert row["extrapolated"] and row["steps"] == 5401


def test_contract_reads_the_rows():
    rows = [{"workload": "paper", "engine": "loop", "steps": 5401, "wafers": 10, "seconds": 1.0},
            {"workload": "paper", "engine": "analytic", "steps": 5401, "wafers": 10,
             "seconds": 0.001},
            {"workload": "fab", "engine": "analytic", "steps": 270001, "wafers": 100,
             "seconds": 0.006},
            {"workload": "steps", "engine": "analytic", "steps": 1000, "wafers": 10,
             "seconds": 0.001},
            {"workload": "steps", "engine": "analytic", "steps": 10**6, "wafers": 10,
             "seconds": 0.0011}]
    met = [ok for ok, _ in bench.contract(rows, {"updates_per_second": 20.0, "max_stall": 0.05})]
    assert met == [True, False, True, False]
