"""The MCS link as an MCS drives it, from outside: a ``waferscan watch`` process on a folder,
commands appended to its commands.txt, results.txt watched for the answer. SPEC §9's MCS
figures: latency, the idle cost against the length of commands.txt, memory over a soak.

Exports ``Watcher``, ``answered``, ``append_commands``, ``wait_answer``, ``mcs_latency``,
``answered_histories``, ``mcs_idle``, ``mcs_poll_cost``, ``mcs_soak`` and ``bench_mcs``."""

from __future__ import annotations

import contextlib
import os
import random
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from ..core.files.mcs import COMMANDS, RESULTS
from .processes import cli, process_environment, timed_run
from .rounds import interleaved

__all__ = ["Watcher", "answered", "append_commands", "wait_answer", "mcs_latency",
           "answered_histories", "mcs_idle", "mcs_poll_cost", "mcs_soak", "bench_mcs"]

_SEQ = re.compile(r"^seq = (\d+)\s*$", re.MULTILINE)


class Watcher:
    """A ``waferscan watch`` process on a folder, as an MCS site runs it."""

    def __init__(self, folder, layout_path):
        self.folder = Path(folder)
        self.process = subprocess.Popen(cli("watch", folder, "--layout", layout_path),
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                        env=process_environment(), start_new_session=True)

    def cpu_seconds(self):
        """CPU time of all the process's threads (the scheduler's nanosecond count)."""
        total = 0
        for task in Path(f"/proc/{self.process.pid}/task").iterdir():
            try:
                total += int((task / "schedstat").read_text().split()[0])
            except (OSError, ValueError, IndexError):
                pass  # a thread that just ended
        return total / 1e9

    def rss_bytes(self):
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
        return None

    def alive(self):
        return self.process.poll() is None

    def stop(self):
        self.process.terminate()
        try:
            self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def answered(folder):
    """The seq results.txt answers now, or None."""
    try:
        match = _SEQ.search((Path(folder) / RESULTS).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError):
        return None
    return int(match.group(1)) if match else None


def append_commands(folder, lines):
    """Append whole lines to commands.txt, as an MCS does."""
    with open(Path(folder) / COMMANDS, "a", encoding="utf-8", newline="\n") as handle:
        handle.write("".join(f"{line}\n" for line in lines))


def wait_answer(folder, seq, watcher, timeout=120.0):
    """Wait until results.txt answers ``seq``: its file is looked at every 0.5 ms, and read only
    when it was replaced. Returns the time it was seen (perf_counter)."""
    path = Path(folder) / RESULTS
    deadline = time.perf_counter() + timeout
    seen = None
    while True:
        try:
            stat = path.stat()
            mark = (stat.st_ino, stat.st_mtime_ns, stat.st_size)
        except FileNotFoundError:
            mark = None
        if mark is not None and mark != seen:
            seen = mark
            got = answered(folder)
            if got is not None and got >= seq:
                return time.perf_counter()
        if time.perf_counter() > deadline or not watcher.alive():
            raise RuntimeError(f"no answer to seq {seq} in {folder} within {timeout:.0f} s")
        time.sleep(0.0005)


def mcs_latency(layout_path, count, seed=1):
    """Command appended -> results.txt replaced, ``count`` times, each append at a random
    moment (0-150 ms after the last answer) so that every phase of a poll is met. Seconds."""
    chance = random.Random(seed)
    with tempfile.TemporaryDirectory() as folder:
        watcher = Watcher(folder, layout_path)
        try:
            append_commands(folder, ["1 SCF"])
            wait_answer(folder, 1, watcher)  # start-up and the first scan: not counted
            samples = []
            for seq in range(2, count + 2):
                time.sleep(chance.uniform(0.0, 0.15))
                append_commands(folder, [f"{seq} SCF"])
                start = time.perf_counter()
                samples.append(wait_answer(folder, seq, watcher) - start)
        finally:
            watcher.stop()
    return samples


def _answered_history(folder, layout_path, lines):
    """A folder whose commands.txt holds ``lines`` commands, every one answered: the last is
    answered by `waferscan watch --once`, then commands.txt gets the earlier ones written in
    front (replaced by rename, as an MCS may) -- a watcher restarted on a long-used folder."""
    append_commands(folder, [f"{lines} SCF"])
    timed_run(cli("watch", folder, "--layout", layout_path, "--once"))
    if answered(folder) != lines:
        raise RuntimeError(f"watch --once did not answer seq {lines}")
    temporary = Path(folder) / ".commands.bench.tmp"
    temporary.write_text("".join(f"{seq} SCF\n" for seq in range(1, lines + 1)),
                         encoding="utf-8")
    os.replace(temporary, Path(folder) / COMMANDS)


@contextlib.contextmanager
def answered_histories(layout_path, histories):
    """{lines: folder} with ``_answered_history`` made once for each of ``histories``, for
    the idle measures to share; the folders go when the context ends."""
    with contextlib.ExitStack() as stack:
        folders = {}
        for lines in histories:
            folders[lines] = stack.enter_context(tempfile.TemporaryDirectory())
            _answered_history(folders[lines], layout_path, lines)
        yield folders


def mcs_idle(layout_path, folders, seconds, rounds=3, settle=3.0):
    """{lines: CPU seconds a second} that an idle watcher spends on a folder with ``lines``
    answered commands, for each of ``folders`` ({lines: folder}, ``answered_histories``): one
    watcher a history, all running at once after ``settle`` seconds for their start-up, each
    figure the median over ``rounds`` windows of ``seconds`` that all the watchers share.
    Measured one history after the other (5 s each), the same code gave 2.9 ms a second at 10
    lines and 5.2 at 100,000 in one run, 5.9 and 5.1 in the run before: the machine's moment,
    not the history."""
    with contextlib.ExitStack() as stack:
        watchers = {}
        for lines, folder in folders.items():
            watchers[lines] = (folder, Watcher(folder, layout_path))
            stack.callback(watchers[lines][1].stop)
        time.sleep(settle)
        samples = {lines: [] for lines in folders}
        for _ in range(rounds):
            start = {lines: w.cpu_seconds() for lines, (_, w) in watchers.items()}
            wall0 = time.perf_counter()
            time.sleep(seconds)
            wall = time.perf_counter() - wall0
            for lines, (_, watcher) in watchers.items():
                samples[lines].append((watcher.cpu_seconds() - start[lines]) / wall)
        for lines, (folder, watcher) in watchers.items():
            if not watcher.alive():
                raise RuntimeError("the watcher ended while idle")
            if answered(folder) != lines:
                raise RuntimeError(f"an idle watcher answered again ({answered(folder)})")
    return {lines: statistics.median(taken) for lines, taken in samples.items()}


def mcs_poll_cost(folders, rounds=5, polls=2000):
    """{lines: seconds} of one idle poll of the MCS link (``McsLink.poll``, what `waferscan
    watch` does every 10 ms) on a folder with ``lines`` answered commands, for each of
    ``folders`` ({lines: folder}, ``answered_histories``): the links polled in this process in
    interleaved rounds of ``polls`` polls, the median round. SPEC §9's "an idle poll costs the
    same" asks for this figure; a watcher process's CPU a second (``mcs_idle``) adds the
    interpreter's own wake-ups and the scheduler's moment, which differ from one process to
    the next by 2x."""
    from ..core.files.mcs_link import McsLink

    def must_not_scan(command, should_stop):
        raise AssertionError(f"an idle link carried out {command!r}")

    with contextlib.ExitStack() as stack:
        links = {}
        for lines, folder in folders.items():
            links[lines] = stack.enter_context(McsLink(folder, must_not_scan,
                                                       log=lambda text: None))
            links[lines].poll()  # the first poll reads the history; the later ones are idle

        def polled(link):
            for _ in range(polls):
                if link.poll():
                    raise AssertionError("an idle link answered")

        times, _ = interleaved({lines: (lambda link=link: polled(link))
                                for lines, link in links.items()}, rounds)
    return {lines: statistics.median(taken) / polls for lines, taken in times.items()}


def mcs_soak(layout_path, commands, batch=100):
    """``commands`` SCF commands appended ``batch`` at a time, each batch waited for; the
    watcher's resident memory after each. Returns a dict of the figures."""
    with tempfile.TemporaryDirectory() as folder:
        watcher = Watcher(folder, layout_path)
        samples = []  # (commands answered, RSS bytes)
        start = time.perf_counter()
        try:
            for first in range(1, commands + 1, batch):
                last = min(commands, first + batch - 1)
                append_commands(folder, [f"{seq} SCF" for seq in range(first, last + 1)])
                wait_answer(folder, last, watcher, timeout=600.0)
                samples.append((last, watcher.rss_bytes()))
        finally:
            watcher.stop()
        seconds = time.perf_counter() - start
    warm = samples[0]
    growth = samples[-1][1] - warm[1]
    return {"commands": commands, "seconds": seconds, "rss_after_first_batch": warm[1],
            "rss_end": samples[-1][1], "growth_bytes": growth,
            "growth_per_command_bytes": growth / max(1, samples[-1][0] - warm[0]),
            "samples": samples}


def bench_mcs(layout_path, quick, histories, add):
    """The SPEC §9 MCS figures, measured on `waferscan watch` processes."""
    latency = mcs_latency(layout_path, 20 if quick else 200)
    ordered = sorted(latency)
    p99 = ordered[min(len(ordered) - 1, int(round(0.99 * (len(ordered) - 1))))]
    idle_rounds, poll_rounds = (1, 3) if quick else (3, 7)
    with answered_histories(layout_path, histories) as folders:
        # The poll in this process first: its links hold the folders' locks until it ends.
        poll = mcs_poll_cost(folders, rounds=poll_rounds)
        idle = mcs_idle(layout_path, folders, 2.0 if quick else 5.0, rounds=idle_rounds)
    for engine, figures, rounds in (("watch idle (CPU s per s)", idle, idle_rounds),
                                    ("idle poll", poll, poll_rounds)):
        for lines in histories:
            add({"workload": "mcs", "engine": engine, "steps": None, "wafers": None,
                 "history": lines, "seconds": figures[lines], "rounds": rounds,
                 "sampled_steps": None, "extrapolated": False})
    soak = mcs_soak(layout_path, 300 if quick else 10_000)
    return {"latency_samples": latency, "latency_median": statistics.median(latency),
            "latency_p99": p99, "idle_cpu_per_second": idle, "idle_poll_seconds": poll,
            "soak": soak}
