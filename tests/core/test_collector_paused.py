"""SPEC §9 (10,000 wafers <= 12x 1,000, garbage collection accounted for): the core's
scan_layout holds Python's cyclic collector off while it runs and gives it back as it was; the
CAD layer's engines (a stepper) run with it."""

import gc

import pytest
from scenarios import PAPER

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import layout_scan

LAYOUT = read_scenario(PAPER)


@pytest.fixture
def seen(monkeypatch):
    states = []
    real = layout_scan._scan_layout

    def watched(*args):
        states.append(gc.isenabled())
        return real(*args)

    monkeypatch.setattr(layout_scan, "_scan_layout", watched)
    yield states
    gc.enable()


def test_the_collector_waits_for_the_scan_and_is_given_back(seen):
    gc.enable()
    result = layout_scan.scan_layout(LAYOUT)
    assert seen == [False] and gc.isenabled()
    assert result.code == "1101221001220001010000010"
    gc.disable()
    layout_scan.scan_layout(LAYOUT)
    assert seen == [False, False] and not gc.isenabled()  # left off, as it was


def test_a_failing_scan_gives_the_collector_back(monkeypatch):
    def failing(*args):
        assert not gc.isenabled()
        raise RuntimeError("in the scan")

    monkeypatch.setattr(layout_scan, "_scan_layout", failing)
    gc.enable()
    with pytest.raises(RuntimeError, match="in the scan"):
        layout_scan.scan_layout(LAYOUT)
    assert gc.isenabled()


def test_a_stepper_runs_with_the_collector(seen):
    from waferscan.core.scan.engines import run_engine

    gc.enable()
    layout_scan.scan_layout(LAYOUT, stepper=lambda lay, progress: run_engine("analytic", lay))
    assert seen == [True]


def test_scans_in_threads_that_overlap_give_the_collector_back():
    # Thread A enters, B enters, A leaves, B leaves (and the other way round): the collector
    # is on after the last, however they interleave (a Dask worker of several threads).
    import threading

    gc.enable()
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()
    inside_b = []

    def a():
        with layout_scan.collector_paused():
            a_in.set()
            b_in.wait(10)
        a_out.set()

    def b():
        a_in.wait(10)
        with layout_scan.collector_paused():
            b_in.set()
            a_out.wait(10)
            inside_b.append(gc.isenabled())  # A has left; B's pause still holds

    threads = [threading.Thread(target=a), threading.Thread(target=b)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(20)
    assert inside_b == [False] and gc.isenabled()
