"""SPEC §9: a sweep without --workers runs in this process until a local cluster pays for its
start-up: a pilot times 512 layouts here and ``cluster_pays`` decides; --workers K is always
honoured. The results do not depend on where they were computed."""

import json
import subprocess
import sys

import pytest
from scenarios import EXAMPLES, PAPER

from waferscan.sweep import cluster

TOLERANCES = EXAMPLES / "fab_tolerances.toml"


def test_a_cluster_pays_only_beyond_its_start_up_scaled_by_its_speed_up():
    # 2 workers: s = 1.6, so T > 1.3 x 1.6 / 0.6 = 3.467 s; one worker (s = 0.8) never pays.
    threshold = cluster.CLUSTER_START_S * 1.6 / 0.6
    assert threshold == pytest.approx(3.4667, abs=1e-4)
    assert not cluster.cluster_pays(threshold - 0.01, 2)
    assert cluster.cluster_pays(threshold + 0.01, 2)
    assert not cluster.cluster_pays(1e9, 1)
    assert cluster.cluster_pays(2.0, 16)  # s = 12.8: T > 1.41 s


class Saying:
    """A progress line that keeps what the sweep says of itself."""

    def __init__(self, said):
        self.said = said

    def __call__(self, done, total, layouts=None):
        pass

    def say(self, text):
        self.said.append(text)


class NoCluster(Exception):
    pass


def _refuse_cluster(workers):
    raise NoCluster(workers)


@pytest.fixture
def watched(monkeypatch):
    """run() with the local cluster replaced by an error that names its workers."""
    monkeypatch.setattr(cluster, "local_cluster", _refuse_cluster)
    monkeypatch.setattr(cluster.os, "cpu_count", lambda: 2)
    return monkeypatch


def test_without_workers_a_short_sweep_stays_in_this_process(watched):
    said = []
    progress = Saying(said)
    summary, _ = cluster.run(PAPER, TOLERANCES, 2000, seed=4, progress=progress)
    in_process, _ = cluster.run(PAPER, TOLERANCES, 2000, seed=4, workers=0)
    assert summary == in_process
    assert len(said) == 1 and said[0].startswith("in this process: 2,000 layouts take about ")
    assert said[0].endswith("less than a local cluster of 2 workers needs to pay for its "
                            "start-up (--workers K to use one)")


def test_without_workers_a_long_sweep_goes_to_a_cluster_of_one_worker_a_core(watched):
    watched.setattr(cluster, "_in_process_seconds", lambda *args: 60.0)
    with pytest.raises(NoCluster) as started:
        cluster.run(PAPER, TOLERANCES, 2000, seed=4)
    assert started.value.args == (2,)


def test_workers_are_always_honoured(watched):
    watched.setattr(cluster, "_in_process_seconds", lambda *args: 0.0)
    with pytest.raises(NoCluster) as started:
        cluster.run(PAPER, TOLERANCES, 2000, seed=4, workers=2)
    assert started.value.args == (2,)


def test_a_sweep_no_larger_than_the_pilot_is_not_piloted(watched):
    def pilot(*args):
        raise AssertionError("no pilot for a sweep of the pilot's size")

    watched.setattr(cluster, "_sweep", pilot)
    assert cluster._in_process_seconds(None, None, cluster.PILOT_LAYOUTS, 0, None, None) == 0.0
    with pytest.raises(AssertionError, match="no pilot"):
        cluster._in_process_seconds(None, None, cluster.PILOT_LAYOUTS + 1, 0, None, None)


def test_the_command_says_where_it_ran_and_gives_the_same_summary():
    args = [sys.executable, "-m", "waferscan.cli", "sweep", str(PAPER), "--tolerances",
            str(TOLERANCES), "-n", "3000", "--seed", "2", "--json"]
    default = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert default.returncode == 0, default.stderr
    assert "sweep: in this process: 3,000 layouts take about " in default.stderr
    explicit = subprocess.run(args + ["--workers", "0"], capture_output=True, text=True,
                              timeout=300)
    assert "in this process:" not in explicit.stderr  # asked for: nothing to explain
    assert json.loads(default.stdout) == json.loads(explicit.stdout)


def test_one_core_runs_in_this_process_without_a_pilot(watched):
    watched.setattr(cluster.os, "cpu_count", lambda: 1)

    def pilot(*args):
        raise AssertionError("no pilot where a cluster never pays")

    watched.setattr(cluster, "_in_process_seconds", pilot)
    said = []
    progress = Saying(said)
    summary, _ = cluster.run(PAPER, TOLERANCES, 2000, seed=4, progress=progress)
    assert summary == cluster.run(PAPER, TOLERANCES, 2000, seed=4, workers=0)[0]
    assert said == ["in this process: one core, where a local cluster never pays for its "
                    "start-up (--workers K to use one)"]
