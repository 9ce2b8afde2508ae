"""The bench's floors (SPEC §9 amended, issue 30) read from a report: each figure beside its
floor, judged against its ratio."""

from waferscan import bench


def floors(fab=1.5, document=1.8, wafers=10_000, scenario=0.9):
    return {"results": [], "floors": {
        "fab": {"scan_layout": 60e-6, "floor": 40e-6, "ratio": fab},
        "document": {"scan": 3.6, "floor": 2.0, "ratio": document, "wafers": wafers,
                     "file_bytes": 6_800_000},
        "scenario": {"scan": 0.45, "floor": 0.5, "ratio": scenario}}}


def floor_lines(report):
    return [(met, text) for met, text in bench.contract(report) if "floor:" in text]


def test_each_figure_is_judged_beside_its_floor():
    lines = floor_lines(floors())
    assert [met for met, _ in lines] == [True, True, True]
    assert lines[0][1] == ("fab scan_layout 60 us = 1.50x the closed form written plainly (40 us, "
                           "the same runs and slot code; floor: <= 2x)")
    assert lines[1][1] == ("waferscan scan of a 10,000-wafer .FCStd (6.8 MB): 3.60 s = 1.80x "
                           "FreeCAD's own open + placement read (2.00 s; floor: <= 2x)")
    assert lines[2][1].startswith("waferscan scan paper.toml: 0.450 s = 0.90x freecadcmd -c")
    lines = floor_lines(floors(fab=2.1, document=2.5, scenario=1.05))
    assert [met for met, _ in lines] == [False, False, False]


def test_a_quick_run_does_not_judge_the_document_floor():
    met, text = floor_lines(floors(wafers=1_000, document=1.2))[1]
    assert met is None and text.endswith("not the contract's 10,000 (--quick)")


def test_no_floors_measured_adds_no_line():
    assert floor_lines({"results": []}) == []


def test_a_failed_floor_is_said_and_the_rest_measured(monkeypatch):
    """A floor measure that fails (a process that errs, one that times out) is kept in the
    report as an error, a NOT MET line naming why, not an end of the bench."""
    import subprocess

    from waferscan.bench import report as bench_report

    for failure in (RuntimeError("waferscan scan exited 1"),
                    subprocess.TimeoutExpired(["waferscan", "layout"], 600)):
        def failing(rounds, quick=False, add=None, failure=failure):
            raise failure

        monkeypatch.setattr(bench_report, "bench_floors", failing)
        report = {"results": []}
        bench_report.measure_floors(report, 1, quick=True)
        assert "floors" not in report
        lines = [(met, text) for met, text in bench.contract(report)
                 if text.startswith("floors")]
        assert lines == [(False, "floors: the measure failed: "
                                 f"{type(failure).__name__}: {failure}")]


def test_each_floor_shows_a_line_as_it_is_measured(monkeypatch):
    """On a terminal the floors (~2 minutes) show a table line each as they are measured."""
    from waferscan.bench import documents, fab_floor, report as bench_report, scenario_scan

    monkeypatch.setattr(fab_floor, "bench_fab_floor",
                        lambda rounds: {"scan_layout": 1.3e-4, "floor": 5.6e-5, "ratio": 2.45})
    monkeypatch.setattr(scenario_scan, "bench_scenario_scan",
                        lambda rounds: {"scan": 0.244, "floor": 0.254, "ratio": 0.98})
    monkeypatch.setattr(documents, "bench_document_floor",
                        lambda rounds, quick=False: {"scan": 14.1, "floor": 3.2, "ratio": 4.28,
                                                     "wafers": 10_000, "file_bytes": 1})
    rows = []
    report = {"results": []}
    bench_report.measure_floors(report, 1, add=rows.append)
    assert [bench.format_row(r) for r in rows] == [
        "floor     fab                                  0.000130 s  floor   0.000056 s    2.45x",
        "floor     scenario                             0.244000 s  floor   0.254000 s    0.98x",
        "floor     document                            14.100000 s  floor   3.200000 s    4.28x"]
    assert report["floors"]["document"]["ratio"] == 4.28
