"""Workloads timed as whole processes, process to process: `waferscan layout` and `waferscan
scan` of stacked FOUPs, and a headless scan's start-up against ``freecadcmd -c "import Part,
numpy"``. Every process runs this checkout's package, the code being measured.

Exports ``cli``, ``process_environment``, ``timed_run``, ``saved_layout``, ``bench_startup``
and ``bench_processes``."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from ..addon import addon_root
from .rounds import interleaved, row
from .workloads import stack_layout, stack_scenario

__all__ = ["cli", "process_environment", "timed_run", "saved_layout", "bench_startup",
           "bench_processes"]


_COMPILED = []


def process_environment():
    """The environment of the processes the bench starts: this checkout's package first, so
    that they run the code being measured, its bytecode compiled first, as an installed
    package's is (pip compiles it; where PYTHONDONTWRITEBYTECODE is set, as on the machines
    this is developed on, nothing else would, and every process would compile waferscan's
    sources at its start: ~0.1 s of a 0.3 s scan)."""
    if not _COMPILED:
        import compileall

        compileall.compile_dir(str(Path(addon_root()) / "waferscan"), quiet=1)
        _COMPILED.append(True)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (addon_root(), env.get("PYTHONPATH")) if p)
    return env


def cli(*args):
    """The ``waferscan`` command as a process (this interpreter, this checkout)."""
    return [sys.executable, "-m", "waferscan.cli", *map(str, args)]


def timed_run(command, timeout=600):
    """Run ``command`` to its end; the seconds it took. A failed process raises RuntimeError
    with the end of its stderr."""
    env = process_environment()  # before the clock: its first call compiles the package
    start = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          env=env, timeout=timeout)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed ({done.returncode}): "
                           f"{done.stderr.decode(errors='replace')[-500:]}")
    return seconds


def saved_layout(scenario_path, folder):
    """The scenario built and saved as a .FCStd in ``folder`` (as `waferscan layout` does)."""
    import FreeCAD as App

    from ..cad.layout_files import open_layout, save_document

    path = Path(folder) / "bench-layout.FCStd"
    doc = open_layout(scenario_path)
    try:
        save_document(doc, path)
    finally:
        App.closeDocument(doc.Name)
    return path


def bench_startup(layout_path, paper, rounds, add):
    """`waferscan scan LAYOUT.FCStd` and the documented `freecadcmd -c` form against
    `freecadcmd -c "import Part, numpy"`, process to process, interleaved."""
    script = (f"import sys, waferscan.cli as c; "
              f"sys.exit(c.main(['scan', {str(layout_path)!r}, '--json']))")
    commands = {"freecadcmd import Part, numpy": ["freecadcmd", "-c", "import Part, numpy"],
                "waferscan scan": cli("scan", layout_path),
                "freecadcmd -c waferscan scan": ["freecadcmd", "-c", script]}
    times, _ = interleaved({name: (lambda c=command: timed_run(c)) for name, command in
                            commands.items()}, rounds)
    for name in commands:
        add(row("startup", name, paper, times[name]))


def bench_processes(folder, foup_counts, add):
    """`waferscan layout` then `waferscan scan` of a stack of FOUPs, as processes."""
    for foups in foup_counts:
        scenario = Path(folder) / f"stack-{foups}.toml"
        scenario.write_text(stack_scenario(foups), encoding="utf-8")
        target = Path(folder) / f"stack-{foups}.FCStd"
        layout = stack_layout(foups)
        add(row("wafers", "waferscan layout", layout,
                [timed_run(cli("layout", scenario, "-o", target))]))
        add(row("wafers", "waferscan scan", layout, [timed_run(cli("scan", target))]))
        target.unlink()
