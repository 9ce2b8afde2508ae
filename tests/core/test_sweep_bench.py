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
