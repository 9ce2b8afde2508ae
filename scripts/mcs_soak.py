"""Soak and time the real MCS link from outside, as an MCS meets it (docs/reliability.md's figures).

    .venv/bin/python scripts/mcs_soak.py [--commands 2000] [--engine analytic]
        [--z-step 0.05] [--interval 0.02] [--history-lines 100000] [--idle 10]

Starts ``waferscan watch`` on a fresh folder whose commands.txt already holds
``--history-lines`` answered-looking lines (seqs below the first command sent), appends one
command at a time, and measures for each the time from the append to results.txt being
replaced (its inode changes: the link renames a new file over it). Prints the latency median,
p99 and maximum, the watcher's resident memory growth per command from the first quarter to
the end, and the CPU the idle watcher burns (per cent of one core) over ``--idle`` seconds.
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def rss_kib(pid):
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def cpu_seconds(pid):
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def inode(path):
    try:
        return os.stat(path).st_ino
    except OSError:
        return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--commands", type=int, default=2000)
    parser.add_argument("--engine", default="analytic")
    parser.add_argument("--z-step", type=float, default=None, help="z_step in parameters.txt")
    parser.add_argument("--interval", type=float, default=0.02, help="s between commands")
    parser.add_argument("--history-lines", type=int, default=0)
    parser.add_argument("--idle", type=float, default=10.0, help="s of idle to measure")
    args = parser.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        first = args.history_lines + 1
        if args.z_step is not None:
            (folder / "parameters.txt").write_text(f"z_step = {args.z_step}\n")
        (folder / "commands.txt").write_text("".join(f"{seq} SCF\n" for seq in range(1, first)))
        # The history lines count as answered: results.txt says seq first - 1.
        (folder / "results.txt").write_text(f"seq = {first - 1}\ncommand = SCF\nstatus = ok\n")
        out = open(folder.parent / f"mcs_soak_{os.getpid()}.log", "w")
        process = subprocess.Popen([sys.executable, "-m", "waferscan.cli", "watch", str(folder),
                                    "--engine", args.engine], cwd=ROOT, stdout=out,
                                   stderr=subprocess.STDOUT)
        try:
            results = folder / "results.txt"
            # Ready when it has read the history (the first answer comes back).
            latencies, rss = [], {}
            for n, seq in enumerate(range(first, first + args.commands), start=1):
                before = inode(results)
                with open(folder / "commands.txt", "a") as handle:
                    handle.write(f"{seq} {'SCF' if seq % 2 else 'SCS'}\n")
                start = time.perf_counter()
                deadline = start + 120.0
                while inode(results) == before:
                    if time.perf_counter() > deadline or process.poll() is not None:
                        raise SystemExit(f"no answer to seq {seq}")
                    time.sleep(0.0002)
                latencies.append(time.perf_counter() - start)
                if n in (max(1, args.commands // 4), args.commands):
                    rss[n] = rss_kib(process.pid)
                time.sleep(args.interval)
            time.sleep(0.5)
            cpu0, wall0 = cpu_seconds(process.pid), time.monotonic()
            time.sleep(args.idle)
            idle = (cpu_seconds(process.pid) - cpu0) / (time.monotonic() - wall0)
        finally:
            process.send_signal(signal.SIGINT)
            process.wait(60)
            out.close()
    ms = sorted(1000.0 * x for x in latencies[1:] or latencies)  # the first includes start-up
    p99 = ms[min(len(ms) - 1, int(round(0.99 * (len(ms) - 1))))]
    quarter = max(1, args.commands // 4)
    growth = (rss[args.commands] - rss[quarter]) / max(1, args.commands - quarter)
    print(f"engine {args.engine}, {args.commands} commands after {args.history_lines} history "
          f"lines")
    print(f"append -> results.txt replaced: median {statistics.median(ms):.1f} ms, p99 "
          f"{p99:.1f} ms, max {ms[-1]:.1f} ms")
    print(f"resident memory: {rss[quarter] / 1024:.1f} MB at command {quarter}, "
          f"{rss[args.commands] / 1024:.1f} MB at {args.commands}: {growth:+.2f} kB a command")
    print(f"idle: {100.0 * idle:.2f} % of one core")


if __name__ == "__main__":
    main()
