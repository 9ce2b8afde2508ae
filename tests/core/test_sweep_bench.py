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
    lines = sweep_lines(report(150_000, 9_000, 12_000, 300_000, 500_000, 1.7))
    assert [met for met, _ in lines] == [True, False, True]
    assert "150,000 layouts a minute" in lines[0][1] and "12,000 without" in lines[1][1]
    lines = sweep_lines(report(99_000, 10_000, 12_000, 300_000, 450_000, 1.5))
    assert [met for met, _ in lines] == [False, True, False]


def test_no_sweep_measured_says_so():
    lines = sweep_lines({"results": []})
    assert lines == [(None, "sweeps (SPEC §12): not measured")]
