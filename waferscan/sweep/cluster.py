"""``waferscan sweep`` on Dask: the INPUT loaded, a ``distributed.LocalCluster`` on this
machine's cores (or an existing scheduler) started or reached, the partitions of
``waferscan.core.sweep`` run on it with a progress line, and what goes wrong there (a bad
address, workers that die, an N beyond the sweep's counts) told in one line."""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

from ..core import sweep
from ..core.errors import InputError
from ..core.sweep.distributions import read_tolerances

# Partitions per worker: enough for the progress line to move and the load to even out; the
# results do not depend on it (core/sweep/run.py).
PARTITIONS_PER_WORKER = 4
# Without --workers or --scheduler a sweep runs in this process until a local cluster pays for
# itself (SPEC §9). Starting and closing a LocalCluster of 2 workers, with their first imports,
# costs 1.0-1.5 s on the 2-core machine of docs/performance.md; k workers sweep about 0.8 k
# times as fast as this process (2 workers: 1.49-1.86x measured). A pilot of PILOT_LAYOUTS
# layouts in process estimates the whole sweep's time here.
CLUSTER_START_S = 1.3
WORKER_EFFICIENCY = 0.8
PILOT_LAYOUTS = 512
# How long (s) to wait for an existing scheduler before calling its address bad input.
CONNECT_TIMEOUT = 10.0
PROGRESS_PREFIX = "sweep:"
# How long (s) a sweep on a cluster waits with no worker at all before it gives up (the
# cluster's workers died or were stopped); WAFERSCAN_SWEEP_WORKERLESS_SECONDS overrides it.
WORKERLESS_SECONDS = 60.0


def _workerless_seconds():
    try:
        seconds = float(os.environ.get("WAFERSCAN_SWEEP_WORKERLESS_SECONDS", WORKERLESS_SECONDS))
    except ValueError:
        return WORKERLESS_SECONDS
    return seconds if seconds > 0 else WORKERLESS_SECONDS


class ClusterLost(InputError):
    """The cluster can no longer run the sweep: every worker gone too long, or the scheduler
    gone. One line: what was lost, what to do."""


def load_layout(path):
    """The INPUT as a core Layout: a scenario .toml read directly (no FreeCAD), a layout
    .FCStd through FreeCAD's document."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".toml":
        from ..core.files.scenario import read_scenario

        return read_scenario(path)
    if suffix != ".fcstd":
        raise InputError(path, None, "expected a scenario .toml or a FreeCAD layout .FCStd")
    from ..cad.layout_files import opened_layout
    from ..cad.reader import read_layout

    with opened_layout(path) as doc:
        return read_layout(doc)


class ProgressLine:
    """``sweep: 3/8 partitions (37.5 %), 1,500 of 4,000 layouts`` on stderr: rewritten in place
    on a terminal, one line per update otherwise (the GUI reads these lines)."""

    def __init__(self, n, stream=None):
        self.n = n
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.shown = False

    def __call__(self, done, total, layouts=None):
        text = (f"{PROGRESS_PREFIX} {done}/{total} partitions ({100.0 * done / total:.1f} %)"
                + (f", {layouts:,} of {self.n:,} layouts" if layouts is not None else ""))
        self.stream.write(("\r" + text) if self.tty else (text + "\n"))
        self.stream.flush()
        self.shown = True

    def say(self, text):
        """One line of its own: how the sweep is run."""
        if self.shown and self.tty:
            self.stream.write("\n")
            self.shown = False
        self.stream.write(f"{PROGRESS_PREFIX} {text}\n")
        self.stream.flush()

    def close(self):
        if self.shown and self.tty:
            self.stream.write("\n")


def local_cluster(workers):
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes on this
    machine, quiet: the scheduler's and nannies' INFO lines (on closing too) are not the
    user's business. Its HTTP server (health, and a dashboard where bokeh is installed) takes a
    free port: another cluster on the machine may hold 8787."""
    import logging

    import dask
    from distributed import LocalCluster

    for name in ("distributed", "distributed.scheduler", "distributed.nanny",
                 "distributed.core", "distributed.worker"):
        logging.getLogger(name).setLevel(logging.ERROR)
    _python_for_workers()
    # Dask's statistical profiler samples each worker's task thread every 10 ms (taking the
    # GIL and walking its stack) for a dashboard page the user does not see here: with it, one
    # worker swept ~15 % slower than this process did (100,000 layouts: 5.21 s against 4.39 s;
    # without it 4.41 s against 4.17 s).
    with dask.config.set({"distributed.nanny.pre-spawn-environ": _worker_environ(),
                          "distributed.worker.profile.enabled": False}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=":0", silence_logs=logging.ERROR)


def _worker_environ():
    """The environment Dask's nannies give a worker before it starts, without the low
    ``MALLOC_TRIM_THRESHOLD_`` Dask sets by default (64 KiB). A sweep's block allocates and
    frees numpy temporaries of megabytes; with that threshold glibc hands the memory back to
    the system after each block and faults it in again on the next, and fixing the threshold
    also turns off glibc's own adaptive one: a partition took ~20 % longer in a worker than in
    this process (1.39-1.42 s against 1.11-1.25 s; without the variable 1.04-1.11 s). A block's
    memory is bounded by its 500 layouts, so the worker's memory stays bounded without it."""
    import dask

    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    return environ


def _python_for_workers():
    """Inside ``freecadcmd`` (FreeCAD 0.20 quirk: ``sys.executable`` is freecadcmd itself)
    multiprocessing would start the workers as freecadcmd, which takes their arguments for its
    own options and exits. They are started with the venv's Python (same version) instead."""
    import multiprocessing

    if Path(sys.executable).name.startswith("python"):
        return
    from ..addon import venv_dir

    python = Path(venv_dir()) / "bin" / "python"
    if not python.exists():
        raise InputError(sys.executable, None, "Dask workers need a Python: run the sweep with "
                                               "the venv's waferscan, or use --workers 0")
    multiprocessing.set_executable(str(python))


class DaskPartitions:
    """A sweep's ``runner`` (core.sweep.run.sweep_tally) on a Dask cluster: each partition a task,
    its result left on the worker that computed it (a future); ``apply`` runs a function on
    each result where it lies and brings back only the answers (the digests and the few
    margins the summary needs, not the partitions' ~40 MB for 100,000 layouts). Progress is
    reported as partitions finish; ``sizes_of(i)``: the layouts in partition i."""

    def __init__(self, client, sizes_of, address=None):
        self.client = client
        self.sizes_of = sizes_of
        self.address = address or "the cluster"

    def run(self, function, args, progress=None):
        futures = self._guarded(lambda: self.client.map(function, *zip(*args), pure=False), 0, 0)
        index = {f.key: i for i, f in enumerate(futures)}
        done = layouts = 0
        for future in self._as_completed(futures):
            if future.status != "finished":
                self._guarded(future.result, done, len(futures))  # failed or cancelled
            done += 1
            layouts += self.sizes_of(index[future.key])
            if progress:
                progress(done, len(futures), layouts)
        return futures

    def apply(self, function, handles, *extra):
        # Each task runs on the worker that holds its partition; the extras are small.
        futures = self._guarded(lambda: self.client.map(
            function, handles, *[[e] * len(handles) for e in extra], pure=False),
            len(handles), len(handles))
        for _ in self._as_completed(futures):
            pass
        return self._guarded(lambda: self.client.gather(futures), len(handles), len(handles))

    def _as_completed(self, futures):
        """The futures as they finish, watching the cluster meanwhile: with no worker for
        WORKERLESS_SECONDS (the partitions would wait for ever) or the scheduler gone, one
        ClusterLost line instead of a frozen sweep or a traceback."""
        from distributed import wait

        pending = set(futures)
        alone_since = None
        limit = _workerless_seconds()
        while pending:
            finished, pending = self._guarded(
                lambda: self._wait(wait, pending), len(futures) - len(pending), len(futures))
            yield from finished
            if not pending or finished:
                alone_since = None
                continue
            workers = self._guarded(lambda: len(self.client.nthreads()),
                                    len(futures) - len(pending), len(futures))
            if workers:
                alone_since = None
            elif alone_since is None:
                alone_since = time.monotonic()
            elif time.monotonic() - alone_since >= limit:
                done = len(futures) - len(pending)
                raise ClusterLost("--scheduler", None, f"{self.address} has had no worker for "
                                  f"{limit:g} s: {done} of {len(futures)} partitions done, "
                                  f"{len(pending)} lost; start workers (dask worker "
                                  f"{self.address}) and run the sweep again")

    @staticmethod
    def _wait(wait, pending):
        """(finished, pending) after at most a second."""
        try:
            finished, left = wait(pending, timeout=1.0, return_when="FIRST_COMPLETED")
        except TimeoutError:  # (a TimeoutError is an OSError: caught before _guarded sees it)
            return set(), pending
        return set(finished), set(left)

    def _guarded(self, call, done, total):
        """``call()``, a lost scheduler said in one line (ClusterLost)."""
        import asyncio

        from distributed import client as dask_client
        from distributed.comm import CommClosedError

        lost = tuple(getattr(dask_client, name) for name in ("FutureCancelledError",
                                                              "FuturesCancelledError")
                     if hasattr(dask_client, name))
        try:
            return call()
        except (*lost, asyncio.CancelledError, CommClosedError, OSError) as exc:
            raise ClusterLost("--scheduler", None, f"lost the Dask scheduler at {self.address} "
                              f"mid-sweep ({done} of {total} partitions done: "
                              f"{type(exc).__name__}); check it and run the sweep again") \
                from None


def run(input_path, tolerance_path, n, seed=0, workers=None, scheduler=None,
              partition_count=None, rules=None, progress=None, clearance_body=None):
    """Load, sweep and summarise; returns (summary dict, the margins' histograms: {"thickness" |
    "position": (counts, bin edges)}). ``workers``: the local cluster's worker processes
    (0: no Dask, in this process; default: this process while a pilot says that a cluster of
    one worker a core would not pay for its start-up, ``cluster_pays``, else one a core);
    ``scheduler``: the address of an existing Dask scheduler instead. ``clearance_body``: what
    reduces a robot for a [clearance] report (layout -> core.sweep.clearance.StrokeBody:
    waferscan.robot.sweep_clearance.stroke_body, which the command passes; this package does
    not import the robot's)."""
    layout = load_layout(input_path)
    tolerances = read_tolerances(tolerance_path)
    try:
        layout.scanned_carrier
    except ValueError as exc:
        raise InputError(input_path, None, str(exc)) from None
    if "beam_tilt" in tolerances.quantities and layout.beam.direction[:2] == (0.0, 0.0):
        raise InputError(tolerance_path, None, "[beam_tilt]: the INPUT's beam runs vertically")
    check_count(n, layout)
    body = _clearance_body(layout, tolerances, clearance_body)
    if workers is None and scheduler is None:
        cores = os.cpu_count() or 1
        # One core: a cluster never pays (cluster_pays), and no pilot is needed to say so.
        estimate = (_in_process_seconds(layout, tolerances, n, seed, rules, body)
                    if cluster_pays(float("inf"), cores) else None)
        if estimate is None or not cluster_pays(estimate, cores):
            if progress is not None and hasattr(progress, "say"):
                progress.say(
                    "in this process: one core, where a local cluster never pays for its "
                    "start-up (--workers K to use one)" if estimate is None else
                    f"in this process: {n:,} layouts take about {estimate:.2f} s here, less "
                    f"than a local cluster of {cores} workers needs to pay for its start-up "
                    f"(--workers K to use one)")
            workers = 0
        else:
            workers = cores
    if workers == 0 and scheduler is None:
        count = partition_count or 1
        return _sweep(layout, tolerances, n, seed, rules, count, None, progress, None, body)
    from distributed import Client

    cluster = None
    if scheduler is None:
        workers = workers or os.cpu_count() or 1
        cluster = local_cluster(workers)
        client = Client(cluster)
    else:
        client = _connect(Client, scheduler)
        # A lost scheduler or its workers are said in one line (ClusterLost); the client's
        # reconnection attempts log tracebacks meanwhile, which are not the user's news.
        _silence_dask_logs()
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        threads = tune_workers(client)
        if progress is not None and hasattr(progress, "say") and threads:
            said = threaded_workers_note(threads, scheduler)
            if said:
                progress.say(said)
    try:
        count = partition_count or workers * PARTITIONS_PER_WORKER
        return _sweep(layout, tolerances, n, seed, rules, count, client, progress, scheduler,
                      body)
    except KeyboardInterrupt:
        # Ctrl-C: the command says so in one line (cli.main); the cluster torn down mid-task
        # logs its cancelled coroutines as ERROR tracebacks, which are not the user's news.
        _silence_dask_logs()
        if cluster is not None:
            _kill_local_workers(cluster)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def tune_workers(client):
    """What ``local_cluster`` gives its workers, given to an existing cluster's where it can be
    set while they run: Dask's statistical profiler stopped, and glibc's trim and mmap
    thresholds raised (32 MiB, the most its own adaptive mmap threshold reaches) so that a
    block's numpy temporaries are not handed back to the system and faulted in again (the
    low MALLOC_TRIM_THRESHOLD_ Dask's nannies set). Returns {worker: threads}: threads a worker
    cannot be given fewer of once started (``threaded_workers_note``)."""
    def tune(dask_worker):
        for name in ("profile", "profile-cycle"):
            callback = dask_worker.periodic_callbacks.get(name)
            if callback is not None:
                callback.stop()
        try:
            import ctypes

            libc = ctypes.CDLL("libc.so.6")
            libc.mallopt(-1, 64 * 1024 * 1024)  # M_TRIM_THRESHOLD
            libc.mallopt(-3, 32 * 1024 * 1024)  # M_MMAP_THRESHOLD
        except (OSError, AttributeError):
            pass  # not glibc: nothing to set
        return dask_worker.state.nthreads

    try:
        return client.run(tune)
    except Exception:  # noqa: BLE001 (a worker refusing it: the sweep runs as the cluster is)
        return {}


def threaded_workers_note(threads, address):
    """A line when the cluster's workers run more than one thread each, else None: a sweep's
    partitions are mostly Python holding the GIL, so two threads of one process sweep little
    faster than one, where WaferScan's own LocalCluster runs one single-threaded process a core
    (docs/performance.md gives what each setting costs)."""
    many = sorted({n for n in threads.values() if n > 1})
    if not many:
        return None
    counts = "/".join(map(str, many))
    return (f"{address}'s workers run {counts} threads each: a sweep holds Python's GIL, so "
            f"one single-threaded process a core is faster (dask worker {address} --nworkers "
            f"K --nthreads 1, as waferscan's own cluster runs)")


def cluster_pays(seconds_in_process, workers):
    """True when a local cluster of ``workers`` would finish a sweep that takes
    ``seconds_in_process`` in this process sooner, its start-up included: when
    seconds > CLUSTER_START_S x s / (s - 1), s = WORKER_EFFICIENCY x workers its speed-up. One
    worker never pays."""
    speedup = WORKER_EFFICIENCY * workers
    if speedup <= 1.0:
        return False
    return seconds_in_process > CLUSTER_START_S * speedup / (speedup - 1.0)


def _in_process_seconds(layout, tolerances, n, seed, rules, body):
    """How long the sweep of ``n`` layouts would take in this process: a pilot of
    PILOT_LAYOUTS of them (a separate seed; the pilot's results are dropped), timed and scaled.
    A sweep no larger than the pilot is that fast anyway: 0."""
    if n <= PILOT_LAYOUTS:
        return 0.0
    import time

    start = time.perf_counter()
    _sweep(layout, tolerances, PILOT_LAYOUTS, seed + 1, rules, 1, None, None, None, body)
    return (time.perf_counter() - start) * n / PILOT_LAYOUTS


def _kill_local_workers(cluster):
    """Ctrl-C: the sweep's results are dropped, so the local cluster's worker processes are
    killed outright before the cluster is closed. Closed one by one, a worker whose scheduler
    went away first prints its own traceback from its own process (seen on Python 3.13:
    BrokenPipeError in Worker.close), which no log level here can silence. Each nanny is told
    first that its worker's end is no reason to start another."""
    for nanny in list(getattr(cluster, "workers", {}).values()):
        pid = getattr(nanny, "pid", None)
        try:
            nanny.close_gracefully(reason="sweep interrupted")
        except Exception:  # noqa: BLE001 (a nanny already closing: its worker goes anyway)
            pass
        if pid:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


def _silence_dask_logs():
    import logging

    for name in ("distributed", "distributed.scheduler", "distributed.nanny",
                 "distributed.core", "distributed.worker", "distributed.client",
                 "distributed.comm", "tornado", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


# A sweep's counts are 64-bit integers: the sums over layouts of products of a layout's slot
# counts (core/sweep/tally.py's layout_moments) reach N x S², which must stay below 2**63.
COUNT_LIMIT = 2 ** 63 - 1


def check_count(n, layout):
    """InputError (-n) when N layouts of the INPUT's slots are more than a sweep's counts hold
    exactly (10^30 was an OverflowError traceback). A sweep's memory does not grow with N
    (core/sweep/margins.py), so nothing else bounds N: a large N only takes its time, and
    Ctrl-C ends it."""
    slots = max(1, layout.scanned_carrier.slot_count)
    most = COUNT_LIMIT // (slots * slots)
    if n > most:
        shown = f"{n:,}" if n < 10 ** 21 else f"{n:.3g}"
        raise InputError("-n", None, f"{shown} layouts: more than a sweep counts exactly (its "
                         f"counts are 64-bit integers, up to N x slots²): at most {most:,} "
                         f"layouts of {slots} slots")


def _connect(Client, scheduler):
    """A Client of the scheduler at ``scheduler``, or one InputError line saying why not (an
    address Dask cannot use: tls:// without its certificates, ucx:// without UCX)."""
    scheme = scheduler.split("://", 1)[0].lower() if "://" in scheduler else "tcp"
    if scheme == "ucx":
        try:
            import ucp  # noqa: F401 (ucx-py, what Dask's ucx:// needs)
        except ImportError:
            raise InputError("--scheduler", None, f"{scheduler}: ucx:// needs UCX (the ucx-py "
                             "package), which is not installed; use tcp://") from None
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT)
    except TypeError as exc:  # tls:// without Dask's TLS configuration, among others
        hint = (" (tls:// needs Dask's TLS configuration: distributed.comm.tls ca-file, "
                "client cert and key)" if scheme in ("tls", "wss") else "")
        raise InputError("--scheduler", None, f"cannot use the Dask scheduler at {scheduler}: "
                         f"{exc}{hint}") from None
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError("--scheduler", None,
                         f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None


def _clearance_body(layout, tolerances, reduce):
    """The robot's collision geometry reduced for the [clearance] report by ``reduce``
    (waferscan.robot.sweep_clearance.stroke_body, with Pinocchio and coal, here: the workers
    get numbers only), or None: no report asked, or no robot (the core reduces the scanner's
    heads)."""
    if tolerances.clearance is None or layout.robot is None:
        return None
    if reduce is None:
        raise InputError(tolerances.source, None, "[clearance]: the layout's robot is reduced "
                         "by waferscan.robot.sweep_clearance.stroke_body; pass it as "
                         "clearance_body")
    try:
        return reduce(layout)
    except ValueError as exc:
        raise InputError(tolerances.source, None, str(exc)) from None


def _sweep(layout, tolerances, n, seed, rules, count, client, progress, address=None,
           clearance_body=None):
    parts = sweep.partitions(n, count)

    def sizes_of(i):
        return sweep.layouts_in(n, parts[i])

    runner = None if client is None else DaskPartitions(client, sizes_of, address)

    def local_progress(done, total, layouts=None):
        if progress:
            progress(done, total, layouts if layouts is not None else
                     sum(sizes_of(i) for i in range(done)))

    try:
        base, tally = sweep.sweep_tally(layout, tolerances, n, seed, rules=rules,
                                        partition_count=count, runner=runner,
                                        progress=local_progress, histograms=True,
                                        clearance_body=clearance_body)
    except ValueError as exc:
        raise InputError(tolerances.source, None, str(exc)) from None
    return sweep.summarise(base, tolerances, n, seed, tally), tally["histograms"]
