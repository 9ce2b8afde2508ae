"""The bench's sweep figures (SPEC §9) read from a report: each contract line against its
threshold."""

from waferscan import bench


def report(ideal, spot, level, one, two, ratio):
    return {"results": [], "sweep": {"ideal beam, in process": ideal,
                                     "1 mm spot, in process": spot,
                                     "1 mm spot, level beam": level,
                                     "Dask 1 worker": one, "Dask 2 workers": two,
                                     "2/1 workers": ratio}}


def sweep_lines(rep):
    return [(met, text) for met, text in bench.contract(rep) if "sweep" in text]


def test_sweep_contract_lines_against_their_thresholds():
    # SPEC §9 amended: >= 10 M a minute with the ideal beam, >= 100,000 with a 1 mm spot.
    lines = sweep_lines(report(15_000_000, 90_000, 120_000, 300_000, 500_000, 1.7))
    assert [met for met, _ in lines] == [True, False, True]
    assert "15,000,000 layouts a minute" in lines[0][1] and "120,000 without" in lines[1][1]
    lines = sweep_lines(report(9_900_000, 100_000, 120_000, 300_000, 450_000, 1.5))
    assert [met for met, _ in lines] == [False, True, False]


def test_the_merge_figure_is_judged_against_a_second():
    rep = report(15_000_000, 100_000, 120_000, 300_000, 500_000, 1.7)
    rep["sweep"]["merge of 1,000 partitions (s)"] = 0.4
    assert [met for met, _ in sweep_lines(rep)] == [True, True, True, True]
    rep["sweep"]["merge of 1,000 partitions (s)"] = 1.2
    lines = sweep_lines(rep)
    assert lines[2] == (False, "sweep's merge on the client: 1,000 partitions of a 100 M-layout "
                               "sweep (synthetic digests) in 1.200 s (<= 1 s)")


def test_the_merge_is_measured():
    from waferscan.bench.workloads import merge_seconds

    seconds = merge_seconds(1, partitions=20, layouts=200_000)
    assert 0.0 < seconds < 60.0


def test_no_sweep_measured_says_so():
    lines = sweep_lines({"results": []})
    assert lines == [(None, "sweeps (SPEC §12): not measured")]


def test_the_floor_and_the_beam_tilt_are_judged_against_their_ratios():
    rep = report(15_000_000, 100_000, 120_000, 300_000, 500_000, 1.7)
    rep["sweep"].update({"ideal beam / numpy floor": 2.4, "numpy floor, in process": 30_000_000,
                         "beam tilt / level beam": 1.6, "ideal beam, level beam": 20_000_000})
    lines = sweep_lines(rep)
    assert [met for met, _ in lines] == [True, True, False, True, True]
    assert lines[1][1].startswith("sweep, ideal beam: 2.40x a plain numpy draw")
    assert "(30,000,000 a minute; <= 2.5x" in lines[1][1]
    assert lines[2][1].startswith("sweep with [beam_tilt]: 1.60x the same sweep without it "
                                  "(20,000,000 a minute")
    rep["sweep"].update({"ideal beam / numpy floor": 2.6, "beam tilt / level beam": 1.4})
    assert [met for met, _ in sweep_lines(rep)] == [True, False, True, True, True]


def test_the_floor_sweeps_the_same_layouts_in_distribution():
    """The bench's numpy floor (bench/sweep_floor.py) does the sweep's work, not less: over
    20,000 layouts of the paper under fab_tolerances its confusion counts agree with the
    sweep's in distribution (its draws are its own), cell by cell."""
    import numpy as np
    from scenarios import PAPER, ROOT

    from waferscan.bench.sweep_floor import floor_sweep
    from waferscan.core import sweep
    from waferscan.core.files.scenario import read_scenario
    from waferscan.core.sweep.distributions import read_tolerances
    from waferscan.core.sweep.tally import STATE_KEYS

    layout = read_scenario(PAPER)
    tolerances = read_tolerances(ROOT / "resources" / "examples" / "fab_tolerances.toml")
    floor = floor_sweep(layout, tolerances, 20_000, seed=3)
    summary = sweep.run_sweep(layout, tolerances, 20_000, seed=3)
    product = np.zeros((8, 8), dtype=np.int64)
    for i, truth in enumerate(STATE_KEYS):
        for j, reported in enumerate(STATE_KEYS):
            product[i, j] = summary["confusion"].get(truth, {}).get(reported, 0)
    assert floor.sum() == product.sum() == 20_000 * 25
    # Every cell (placed x reported) as a share of the slots: within 0.3 points (statistical
    # spread ~0.05), so the floor maps as SPEC §4 does (position before thickness, the double
    # limit, the worst finding, a second run), not only places as the sweep does.
    assert np.allclose(floor / floor.sum(), product / product.sum(), atol=0.003)
    # present and double -> position error: position judged first
    assert floor[1, 5] > 0.05 * floor[1].sum() and floor[3, 5] > 0
