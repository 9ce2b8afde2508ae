"""A sweep's memory does not grow with N (issue 25): a partition counts its margins block by
block (core/sweep/margins.py), as distinct values with counts or, when they are too many, as a
histogram, and draws its blocks again when the summary needs values a histogram does not hold.
The summary stays the one every margin kept in one sorted array gives, byte for byte."""

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from commands import CLI
from scenarios import PAPER, ROOT, SWEEP_TOLERANCES, normal

from waferscan.core import sweep
from waferscan.core.files.scenario import read_scenario
from waferscan.core.mapping import BOUNDARY, WAFERSCAN
from waferscan.core.sweep import margins
from waferscan.core.sweep.distributions import parse_tolerances


def _summary_and_histograms(n, seed, rules, count):
    tol = parse_tolerances(SWEEP_TOLERANCES)
    base, tally = sweep.sweep_tally(read_scenario(PAPER), tol, n, seed, rules=rules,
                                    partition_count=count, histograms=True)
    return sweep.summarise(base, tol, n, seed, tally), tally["histograms"]


def _watched(monkeypatch):
    """(tallies, redrawn): lists the partitions' tallies and the sources drawn again are
    appended to as the sweep runs."""
    tallies, redrawn = [], []
    partition_tally, partition_margins = sweep.tally.partition_tally, \
        sweep.reduction.partition_margins
    monkeypatch.setattr(sweep.run, "partition_tally",
                        lambda *a: tallies.append(partition_tally(*a)) or tallies[-1])
    monkeypatch.setattr(sweep.reduction, "partition_margins",
                        lambda source: redrawn.append(source) or partition_margins(source))
    return tallies, redrawn


@pytest.mark.parametrize("rules", [WAFERSCAN, BOUNDARY])
def test_margins_drawn_again_give_the_summary_of_margins_kept(rules, monkeypatch):
    # Every margin kept (a limit no partition reaches): the summary as before issue 25.
    monkeypatch.setattr(margins, "DISTINCT_LIMIT", 10 ** 9)
    kept, kept_hists = _summary_and_histograms(2200, 7, rules, 3)
    # Limits that send the partitions, then their brackets, to histograms: one, two and up to
    # four rounds of drawing the blocks again.
    tallies, redrawn = _watched(monkeypatch)
    monkeypatch.setattr(sweep.tally, "MARGINS_KEPT", 0)  # histograms, none kept whole
    for limit in (1, 5, 300):
        monkeypatch.setattr(margins, "DISTINCT_LIMIT", limit)
        redrawn.clear()
        for count in (1, 3):
            tallies.clear()
            got, hists = _summary_and_histograms(2200, 7, rules, count)
            assert json.dumps(got) == json.dumps(kept), (limit, count)
            for key, (counts, edges) in kept_hists.items():
                assert np.array_equal(hists[key][0], counts) and \
                    np.array_equal(hists[key][1], edges)
            assert not any(t["margins"]["position"].exact for t in tallies)
        assert redrawn  # the blocks were drawn again


@pytest.mark.parametrize("kept", [10 ** 9, 4000])
def test_margins_kept_whole_are_not_drawn_again(kept, monkeypatch):
    """A kind of margin past DISTINCT_LIMIT is kept whole in a sweep of no more than
    MARGINS_KEPT slots (no second pass), and in a larger one counted in a histogram (a second pass):
    the summary and histograms byte for byte those of every margin kept as distinct values."""
    monkeypatch.setattr(margins, "DISTINCT_LIMIT", 10 ** 9)
    expected, expected_hists = _summary_and_histograms(2200, 7, WAFERSCAN, 3)
    monkeypatch.setattr(margins, "DISTINCT_LIMIT", 300)
    monkeypatch.setattr(sweep.tally, "MARGINS_KEPT", kept)
    tallies, redrawn = _watched(monkeypatch)
    got, hists = _summary_and_histograms(2200, 7, WAFERSCAN, 3)
    assert json.dumps(got) == json.dumps(expected)
    for key, (counts, edges) in expected_hists.items():
        assert np.array_equal(hists[key][0], counts) and np.array_equal(hists[key][1], edges)
    position = [t["margins"]["position"] for t in tallies]
    if kept > 10 ** 6:  # every partition's position margins kept, sorted: nothing drawn again
        assert all(isinstance(p, np.ndarray) for p in position) and not redrawn
        assert sum(len(p) for p in position) == got["margins"]["position"]["count"]
        assert all((np.diff(p) >= 0).all() for p in position)
    else:  # 55,000 slots in the sweep: more than 4,000, so none kept
        assert not any(isinstance(p, np.ndarray) for p in position) and redrawn


def _rss_run(n, limit):
    """Peak resident memory (kB) of a fresh process sweeping the paper N times, and the
    summary."""
    code = ("import json, resource, sys\n"
            "from waferscan.core import sweep\n"
            "from waferscan.core.sweep import margins\n"
            "from waferscan.core.files.scenario import read_scenario\n"
            "from waferscan.core.sweep.distributions import parse_tolerances\n"
            f"margins.DISTINCT_LIMIT = {limit}\n"
            f"sweep.tally.MARGINS_KEPT = {limit}\n"
            f"summary = sweep.run_sweep(read_scenario({str(PAPER)!r}), "
            f"parse_tolerances({SWEEP_TOLERANCES!r}), {n}, seed=2)\n"
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\n"
            "print(json.dumps(summary))\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    rss, summary = done.stdout.splitlines()
    return int(rss), json.loads(summary)


def test_a_sweeps_memory_does_not_grow_with_n():
    """4,000 and 40,000 layouts with every quantity varied (position margins off the step
    grid) and a partition keeping at most 2,000 distinct margins, so that both sweeps count
    them in histograms and draw their blocks again: the peaks of resident memory within 4 MB.
    Before, the second kept 36,000 layouts' margins more (~20 MB)."""
    small, _ = _rss_run(4000, 2000)
    large, summary = _rss_run(40_000, 2000)
    assert summary["n"] == 40_000 and summary["margins"]["position"]["count"] > 400_000
    assert large - small < 4096, (small, large)


@pytest.mark.parametrize("n", ["1000000000", "10000000000000"])
def test_a_huge_n_is_swept_in_memory_that_does_not_grow(tmp_path, n):
    """-n 10^9 grew ~9 MB a second until the machine ran out (it was then refused as more than
    the memory); now it is swept, ~14 hours here, in flat memory; Ctrl-C ends it."""
    tol = tmp_path / "TOL.toml"
    tol.write_text(normal("beam_z", 0, 0.1))
    process = subprocess.Popen([*CLI, "sweep", str(PAPER), "--tolerances", str(tol), "-n", n,
                                "--workers", "0"], cwd=ROOT, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)

    def rss():
        with open(f"/proc/{process.pid}/status") as status:
            return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:"))

    def peak(seconds):
        """The highest resident memory over the next ``seconds``, read every 0.2 s: one
        reading rises and falls by ~4 MB as the blocks of layouts come and go."""
        end, high = time.monotonic() + seconds, 0
        while time.monotonic() < end:
            assert process.poll() is None, process.communicate()[1][-3000:]
            high = max(high, rss())
            time.sleep(0.2)
        return high

    try:
        time.sleep(6.0)  # imports done, the first blocks swept
        first = peak(5.0)
        time.sleep(5.0)
        grown = peak(5.0) - first
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    # kB between the peaks of two 5 s windows 10 s apart; before the fix: ~90 MB
    assert grown < 8192, grown
    assert process.returncode == 130 and err == "waferscan: interrupted\n", err[-3000:]
    assert out == ""
