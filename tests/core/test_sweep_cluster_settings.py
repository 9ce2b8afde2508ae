"""Issue 30, SPEC §9: a sweep on an existing cluster (--scheduler) gives its workers what
WaferScan's own LocalCluster gives its own where that can be set while they run (Dask's
profiler stopped, glibc's trim and mmap thresholds raised), and says what cannot be: a worker of
more than one thread. A real `dask scheduler` and one `dask worker` of 2 threads on 127.0.0.1;
the summary is the same as in this process."""

import json
import os
import subprocess
import sys
from pathlib import Path

from commands import CLI
from hsms_peers import free_port
from processes import _end_group
from scenarios import EXAMPLES, PAPER, ROOT

TOLERANCES = EXAMPLES / "fab_tolerances.toml"


def test_an_existing_clusters_workers_are_tuned_and_a_threaded_one_is_named(tmp_path):
    dask = Path(sys.executable).with_name("dask")
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    started = []
    try:
        started.append(subprocess.Popen(
            [str(dask), "scheduler", "--host", "127.0.0.1", "--port", str(port),
             "--no-dashboard"], cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True))
        started.append(subprocess.Popen(
            [str(dask), "worker", address, "--nthreads", "2", "--no-dashboard", "--host",
             "127.0.0.1"], cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True))
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(1, timeout=120)
            before = client.run(lambda dask_worker: sorted(
                name for name, pc in dask_worker.periodic_callbacks.items()
                if name.startswith("profile") and pc.is_running()))
            assert list(before.values()) == [["profile", "profile-cycle"]]
        args = [*CLI, "sweep", str(PAPER), "--tolerances", str(TOLERANCES), "-n", "3000",
                "--seed", "5", "--json"]
        on_cluster = subprocess.run(args + ["--scheduler", address], cwd=ROOT, env=env,
                                    capture_output=True, text=True, timeout=300)
        assert on_cluster.returncode == 0, on_cluster.stderr[-2000:]
        with Client(address, timeout=60) as client:
            after = client.run(lambda dask_worker: sorted(
                name for name, pc in dask_worker.periodic_callbacks.items()
                if name.startswith("profile") and pc.is_running()))
        assert list(after.values()) == [[]]  # the profiler stopped
    finally:
        for process in reversed(started):
            _end_group(process)
    assert (f"sweep: {address}'s workers run 2 threads each: a sweep holds Python's GIL, so "
            f"one single-threaded process a core is faster (dask worker {address} --nworkers "
            f"K --nthreads 1, as waferscan's own cluster runs)") in on_cluster.stderr
    here = subprocess.run(args + ["--workers", "0"], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=300)
    assert json.loads(on_cluster.stdout) == json.loads(here.stdout)
