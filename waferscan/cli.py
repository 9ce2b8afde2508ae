"""The ``waferscan`` command: argument parsing and output, nothing else.

Exit status 0 on success, 2 on bad input (one line ``waferscan: error: FILE:LINE: message`` on
stderr), 1 on an internal fault.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .addon import addon_root
from .core import report
from .core.engines import ENGINES
from .core.errors import InputError
from .core.mcs import (COMMANDS, PARAMETERS, RESULTS, apply_parameters, atomic_write_text,
                       format_parameters, format_results, read_parameters)
from .core.model import DIRECTIONS, MODES
from .core.scan import scan_layout
from .core.scenario import read_scenario

PROG = "waferscan"


def paper_scenario():
    """The paper's experiment as a scenario file (resources/examples/paper.toml)."""
    return Path(addon_root()) / "resources" / "examples" / "paper.toml"


class _Progress:
    """A one-line progress indicator on stderr, shown only on a terminal."""

    def __init__(self, label):
        self.label = label
        self.shown = False

    def __call__(self, done, total):
        if sys.stderr.isatty() and total:
            sys.stderr.write(f"\r{self.label}: {100.0 * done / total:5.1f} % ({done:,}/{total:,} steps)")
            sys.stderr.flush()
            self.shown = True

    def close(self):
        if self.shown:
            sys.stderr.write("\n")


def _write(path, text):
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise InputError(path, None, f"cannot write: {exc.strerror}") from None


def _read_layout(path):
    path = Path(path)
    if path.suffix.lower() == ".fcstd":
        raise InputError(path, None, "reading .FCStd layouts needs the CAD layer, which is not "
                                     "there yet: give a scenario .toml")
    if path.suffix.lower() != ".toml":
        raise InputError(path, None, "expected a scenario .toml")
    return read_scenario(path)


def _scan(layout, engine, source):
    if layout.scan.exact and engine != "analytic":
        raise InputError(source, None, f"z_step = 0 asks for exact edges, which only the "
                                       f"analytic engine gives (not {engine})")
    progress = _Progress(f"scanning ({engine})")
    try:
        return scan_layout(layout, engine, progress=progress)
    finally:
        progress.close()


def _print_result(result, as_json, paper=False):
    if as_json:
        print(json.dumps(report.result_dict(result), indent=2))
        return
    print(report.format_table(result, paper=paper))
    print()
    print(f"code {result.code}")
    print(f"E87  {result.e87}")


def demo_checks(result):
    """The paper experiment's acceptance checks (SPEC §8): list of (ok, text)."""
    scan = result.layout.scan
    plan = result.plan
    step = scan.z_step
    checks = [(result.code == report.PAPER_CODE,
               f"code {result.code} {'equals' if result.code == report.PAPER_CODE else 'differs from'}"
               f" the paper's {report.PAPER_CODE}")]
    normal, cross = [], []
    for run in result.runs:
        (cross if run.diff > 2 * plan.wafer_thickness else normal).append(run)
    seats = [plan.seat_z(s) for s in range(1, plan.slot_count + 1)]
    ok = all(any(0.0 <= r.bottom - z <= step + 1e-9 for z in seats) for r in normal)
    checks.append((ok, f"every normal wafer's IN within one step ({step:g} mm) above its seat"))
    ok = all(abs(r.diff - plan.wafer_thickness) <= step + 1e-9 for r in normal)
    checks.append((ok, f"every normal wafer's diff within one step of t = {plan.wafer_thickness:g} mm"))
    worst = max((abs(r.diff - 5.38) for r in cross), default=float("inf"))
    checks.append((worst <= 0.25, f"cross-slotted diffs {', '.join(f'{r.diff:.2f}' for r in cross)} "
                                  f"mm within 0.25 mm of the paper's 5.38 mm"))
    return checks


def cmd_demo(args):
    path = paper_scenario()
    layout = read_scenario(path)
    result = _scan(layout, args.engine, path)
    if args.out:
        out = Path(args.out)
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(out, None, f"cannot make the folder: {exc.strerror}") from None
        _write(out / PARAMETERS, format_parameters(layout))
        _write(out / COMMANDS, "1 SCF\n")
        _write(out / RESULTS, format_results(1, "SCF", result))
    if args.json:
        _print_result(result, True)
        return 0
    print(f"The paper's experiment ({path.name}): 25-slot FOUP, ten 300 mm wafers 0.7 mm thick,")
    print(f"{layout.scan.final_z - layout.scan.start_z:g} mm of Z travel at {layout.scan.z_step:g} mm "
          f"steps, engine {args.engine}.")
    print()
    _print_result(result, False, paper=True)
    print()
    checks = demo_checks(result)
    for ok, text in checks:
        print(f"[{'ok' if ok else 'FAIL'}] {text}")
    if args.out:
        print(f"\nMCS files written to {Path(args.out)}/: {PARAMETERS}, {COMMANDS}, {RESULTS}")
    return 0 if all(ok for ok, _ in checks) else 1


def cmd_scan(args):
    layout = _read_layout(args.input)
    if args.params:
        layout = apply_parameters(layout, read_parameters(args.params))
    changes = {k: v for k, v in (("mode", args.mode), ("direction", args.direction)) if v}
    if changes:
        layout = layout.with_scan(**changes)
    result = _scan(layout, args.engine, args.input)
    if args.out:
        _write(args.out, format_results(None, "SCF" if layout.scan.mode == "fast"
                                                   else "SCS", result))
    _print_result(result, args.json)
    return 0


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        # argparse's own usage errors: exit 2 like every other input error.
        self.print_usage(sys.stderr)
        sys.stderr.write(f"{PROG}: error: {message}\n")
        raise SystemExit(2)


def build_parser():
    parser = _Parser(prog=PROG, description="Wafer-scanning (mapping) simulator for FreeCAD "
                                             "layouts and scenario files.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    engines = sorted(ENGINES)

    demo = sub.add_parser("demo", help="the paper's experiment: scan, Table 1 and the slot code")
    demo.add_argument("--out", metavar="DIR", help="write parameters.txt, commands.txt and "
                                                    "results.txt to DIR")
    demo.add_argument("--json", action="store_true", help="print one JSON object")
    demo.add_argument("--engine", choices=engines, default="analytic")
    demo.set_defaults(run=cmd_demo)

    scan = sub.add_parser("scan", help="scan a scenario .toml")
    scan.add_argument("input", metavar="INPUT", help="scenario .toml")
    scan.add_argument("--params", metavar="FILE", help="a parameters.txt whose values override "
                                                       "the layout's")
    scan.add_argument("--engine", choices=engines, default="analytic")
    scan.add_argument("--mode", choices=MODES)
    scan.add_argument("--direction", choices=DIRECTIONS)
    scan.add_argument("--out", metavar="FILE", help="write the results in results.txt format")
    scan.add_argument("--json", action="store_true", help="print one JSON object")
    scan.set_defaults(run=cmd_scan)
    return parser


def main(argv=None):
    """Run the command line; returns (and, as a console script, exits with) the status."""
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except InputError as exc:
        sys.stderr.write(f"{PROG}: error: {exc}\n")
        return 2
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    sys.exit(main())
