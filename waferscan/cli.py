"""The ``waferscan`` command: argument parsing and output, nothing else.

Exit status 0 on success, 2 on bad input (one line ``waferscan: error: FILE:LINE: message`` on
stderr), 1 on an internal fault; ``waferscan calibrate`` exits 3, 4 or 5 for its own failures
(core/scan/calibration.py EXIT_CODES).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from .addon import paper_scenario
from .core.errors import InputError
from .core.files import report
from .core.files.mcs import (
    COMMANDS,
    PARAMETERS,
    RESULTS,
    Parameters,
    format_parameters,
    format_results,
    read_parameters,
)
from .core.files.text_files import atomic_write_text, check_output_path
from .core.model import DIRECTIONS, MODES
from .core.scan.engines import CAD_ENGINES, ENGINES

PROG = "waferscan"


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


def _check_out(path, option="--out"):
    """Refuse an output path that is not a regular file or a new path (a device node, a FIFO,
    a symlink, a folder) before any work is done; ``-`` is the standard output."""
    if path is not None and str(path) != "-":
        check_output_path(path, option)


def _write(path, text, option="--out"):
    if str(path) == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    check_output_path(path, option)  # again: the path may have changed while we worked
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise InputError(path, None, f"cannot write: {exc.strerror}") from None


def _check_engine(layout, engine, source, parameters=None):
    from .core.scan.engine_choice import check_engine

    check_engine(layout, engine, source, parameters)


def _scan_scenario(path, engine, parameters=None):
    """A scenario's scan without its FreeCAD document (robot.scenario_scan), for the outputs
    whose figures are the document's to the last printed digit (table, results.txt, warnings;
    cmd_scan keeps --json's full floats and --plot on the document, whose read-back differs
    by ~1e-14 mm: a wafer's thickness from its solid, the beam from the robot's kinematics).
    None where the document must answer: not a scenario, a CAD engine, or what
    ``scan_scenario`` leaves to it (NeedsDocument)."""
    if Path(path).suffix.lower() != ".toml" or engine in CAD_ENGINES:
        return None
    from .robot.scenario_scan import NeedsDocument, scan_scenario

    progress = _Progress(f"scanning ({engine})")
    try:
        result = scan_scenario(path, engine, parameters, progress=progress,
                               check=lambda layout: _check_engine(layout, engine, path,
                                                                  parameters))
    except NeedsDocument:
        return None
    finally:
        progress.close()
    _ENDS_AT_ONCE.append(True)  # no FreeCAD document, nothing left at exit (console)
    return result


_ENDS_AT_ONCE = []  # non-empty: the command held nothing that Python's shutdown must close


def _scan_input(path, engine, parameters=None, store=False, document=True):
    """Scan a scenario or a layout through a FreeCAD document: the scenario is built into one,
    the layout opened; the scan reads it back. ``store``: the results are kept in the layout
    as its ScanResults spreadsheet and the layout saved (atomically). ``document`` False: a
    scenario is scanned without its document where nothing needs it (``_scan_scenario``).
    FreeCAD is imported only here."""
    if not document and not store:
        result = _scan_scenario(path, engine, parameters)
        if result is not None:
            return result
    from .cad.document_scan import scan_document
    from .cad.layout_files import opened_layout, save_document, setting_error
    from .core.scan.clearance import SweepBlocked
    from .cad.results_sheet import store_in_document

    if store and Path(path).suffix.lower() != ".fcstd":
        raise InputError(path, None, "--store keeps the results in a layout .FCStd; "
                                     "this is a scenario (make a layout with waferscan layout)")
    if store:
        check_output_path(path, "--store")  # the layout is replaced: a regular file only
    progress = _Progress(f"scanning ({engine})")
    with opened_layout(path) as doc:
        try:
            def check(layout):
                _check_engine(layout, engine, path, parameters)

            result = scan_document(doc, engine, progress=progress, parameters=parameters,
                                   check=check)
        except SweepBlocked as exc:  # named by the file and line that asked for the sweep
            raise setting_error(exc.message, path, parameters, "scan", "sweep") from None
        finally:
            progress.close()
        if store:
            store_in_document(doc, result)
            save_document(doc, path)
        return result


def _warn(result):
    """Each of the result's warnings as one line on stderr (SPEC §3 "Honest results")."""
    for warning in result.warnings:
        sys.stderr.write(f"{PROG}: warning: {warning}\n")


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
    result = _scan_input(path, args.engine)
    # SPEC §8's checks are for the exact engines: the paper's own test is shown beside one.
    exact = _scan_input(path, "analytic") if args.engine == "paper" else result
    layout = result.layout
    if args.out:
        out = Path(args.out)
        for name in (PARAMETERS, COMMANDS, RESULTS):
            if out.is_dir():
                _check_out(out / name, "--out")
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(out, None, f"cannot make the folder: {exc.strerror}") from None
        _write(out / PARAMETERS, format_parameters(layout))
        _write(out / COMMANDS, "1 SCF\n")
        _write(out / RESULTS, format_results(1, "SCF", result))
    if args.json:
        _print_result(result, True)
        _warn(result)
        return 0
    print(f"The paper's experiment ({path.name}): 25-slot FOUP, ten 300 mm wafers 0.7 mm thick,")
    print(f"{layout.scan.final_z - layout.scan.start_z:g} mm of Z travel at {layout.scan.z_step:g} mm "
          f"steps, scanned through the FreeCAD document with the {args.engine} engine.")
    print()
    _print_result(result, False, paper=True)
    print()
    if exact is not result:
        for line in report.paper_test_beside_exact(result, exact):
            print(line)
        print()
        for ok, text in demo_checks(result):
            print(f"[{'paper' if ok else 'paper differs'}] {text}")
        print("SPEC §8's checks, on the exact test (analytic engine):")
    checks = demo_checks(exact)
    for ok, text in checks:
        print(f"[{'ok' if ok else 'FAIL'}] {text}")
    _warn(result)
    if args.out:
        print(f"\nMCS files written to {Path(args.out)}/: {PARAMETERS}, {COMMANDS}, {RESULTS}")
    return 0 if all(ok for ok, _ in checks) else 1


def cmd_scan(args):
    _check_out(args.out)  # before the scan: a device, FIFO or symlink there wastes no time
    if args.plot:
        from .plots.signal import check_plot_path

        check_plot_path(args.plot)  # before the scan: a wrong suffix wastes no time
        _check_out(args.plot, "--plot")
    parameters = read_parameters(args.params) if args.params else None
    overrides = {k: v for k, v in (("mode", args.mode), ("direction", args.direction)) if v}
    if overrides:
        base = parameters or Parameters({}, {}, "--mode/--direction")
        parameters = Parameters({**base.values, **overrides}, base.lines, base.source)
    # --json's full floats and --plot's curves are the document's read-back: its path.
    result = _scan_input(args.input, args.engine, parameters, store=args.store,
                         document=args.json or bool(args.plot))
    if args.out:
        _write(args.out, format_results(None, "SCF" if result.layout.scan.mode == "fast"
                                        else "SCS", result))
    if args.plot:
        from .plots.signal import plot_signal  # matplotlib only when a plot is asked for

        _check_out(args.plot, "--plot")
        plot_signal(result, args.plot)
    if args.out == "-":  # results.txt on stdout is the output: no report beside it
        _warn(result)
        return 0
    _print_result(result, args.json)
    if not args.json:  # SPEC §13: the jab and sweep per pocket, the two modes' durations
        if result.pockets:
            print()
            print(report.format_pockets(result))
        print(report.format_durations(result))
    _warn(result)
    return 0


def cmd_calibrate(args):
    """SPEC §11: calibrate from reference wafers; exit 3, 4, 5 for the failures (docs:
    tutorials/recipes-calibration.md)."""
    from .cad.document_calibration import calibrate_input
    from .core.scan.calibration import EXIT_CODES, CalibrationError, format_calibration

    _check_out(args.out)  # before the calibration
    parameters = read_parameters(args.params) if args.params else None
    try:
        calibration = calibrate_input(args.input, parameters, args.engine)
    except CalibrationError as exc:
        if args.json:
            print(json.dumps(report.calibration_failure_dict(exc), indent=2))
        sys.stderr.write(f"{PROG}: calibration failed: {exc}\n")
        return EXIT_CODES[exc.kind]
    if args.out:
        _write(args.out, format_parameters(calibration.after))
        if args.out == "-":  # the recipe on stdout is the output
            _warn(calibration.check)
            return 0
    if args.json:
        print(json.dumps(report.calibration_dict(calibration), indent=2))
        _warn(calibration.check)
        return 0
    print(format_calibration(calibration))
    if args.out:
        print(f"\nrecipe written to {args.out}")
    _warn(calibration.check)
    return 0


def cmd_layout(args):
    from .cad.layout_files import opened_layout, save_document

    if os.path.lexists(args.output):  # a new path's folder is save_document's to check
        check_output_path(args.output, "--output")
    with opened_layout(args.scenario) as doc:
        save_document(doc, args.output)
    print(f"{args.output}: layout of {args.scenario}")
    return 0


def cmd_crosscheck(args):
    from .cad.clearance_brep import clearance_dict, format_clearance
    from .cad.crosscheck import crosscheck
    from .cad.layout_files import opened_layout, setting_error
    from .core.scan.clearance import SweepBlocked

    with opened_layout(args.input) as doc:
        try:
            check = crosscheck(doc)
        except SweepBlocked as exc:  # named by the line that asked for the sweep, as scan does
            raise setting_error(exc.message, args.input, None, "scan", "sweep") from None
    if args.json:
        data = report.crosscheck_dict(check)
        data["clearance"] = clearance_dict(check.clearance)  # SPEC §15, issue 29
        print(json.dumps(data, indent=2))
    else:
        # The clearance lines (SPEC §15) go before the last line, the verdict on everything
        # (check.ok covers the clearance too), which stays last as scripts read it (tail -1).
        *lines, verdict = report.format_crosscheck(check).split("\n")
        print("\n".join([*lines, format_clearance(check.clearance), "", verdict]))
    _warn(check.result)
    return 0 if check.ok else 1


def cmd_watch(args):
    import signal

    from .core.files.mcs_link import StopFlag, stop_on_signals

    # Ctrl-C and SIGTERM stop the watcher from here on, FreeCAD's loading included: a
    # KeyboardInterrupt inside FreeCAD's start leaves its module half made.
    stopping = StopFlag()
    stop_on_signals(stopping)
    try:
        from .cad.mcs_watch import watch

        folder = Path(args.folder)
        if not folder.is_dir():
            raise InputError(folder, None, "no such folder")
        return watch(folder, Path(args.layout) if args.layout else paper_scenario(),
                     args.engine, args.poll, once=args.once, stopping=stopping)
    finally:
        # The process ends with the watch: a further Ctrl-C while it exits is ignored (Python
        # would give SIGINT back its default action while it shuts down).
        for number in (signal.SIGINT, signal.SIGTERM):
            signal.signal(number, signal.SIG_IGN)


def cmd_serve(args):
    import signal

    from .core.files.mcs_link import StopFlag, stop_on_signals

    stopping = StopFlag()  # as for watch: Ctrl-C and SIGTERM stop it, FreeCAD's loading included
    stop_on_signals(stopping)
    try:
        from .host.server import serve

        return serve(args.input, args.hsms, active=args.active, ids_path=args.ids,
                     engine=args.engine, stopping=stopping, mcs_folder=args.mcs,
                     empty=args.empty, messages_out=(lambda text: print(text, flush=True)) if args.sml else None)
    finally:
        for number in (signal.SIGINT, signal.SIGTERM):
            signal.signal(number, signal.SIG_IGN)


def _poll_seconds(text):
    """--poll: a finite number of seconds, above 0 and at most a minute."""
    try:
        seconds = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not 0.0 < seconds <= 60.0:  # also refuses nan; inf is above 60
        raise argparse.ArgumentTypeError(f"must be above 0 and at most 60 s, got {text!r}")
    return seconds


def cmd_bench(args):
    from . import bench

    def show(row):
        if not args.json:
            print(bench.format_row(row), flush=True)

    load = os.getloadavg()  # the machine's load, stated beside the figures (issue 30)
    report = bench.run_bench(paper_scenario(), quick=args.quick, gui=not args.no_gui,
                             mcs=not args.no_mcs, progress=show, only=args.only)
    report["load_average"] = {"start": list(load), "end": list(os.getloadavg()),
                              "cores": os.cpu_count()}
    if args.plot:
        bench.plot(report, args.plot)
    if args.json:
        print(json.dumps(report, indent=2))
    elif "contract" in report:  # --only host measures figures SPEC §9 sets no target for
        print()
        print(bench.format_contract(report))
    if not args.json:
        start, end = report["load_average"]["start"], report["load_average"]["end"]
        print(f"\nload average (1, 5, 15 min) at the start {start[0]:.2f}, {start[1]:.2f}, "
              f"{start[2]:.2f}; at the end {end[0]:.2f}, {end[1]:.2f}, {end[2]:.2f} "
              f"({report['load_average']['cores']} cores)")
    return 0


def _robot_stroke_body(layout):
    """A [clearance] report's robot, reduced to prisms (Pinocchio imported only then)."""
    from .robot.sweep_clearance import stroke_body

    return stroke_body(layout)


def cmd_sweep(args):
    from . import sweep

    if args.out:  # refused before the sweep, not after it
        sweep.output_folder(args.out)
    progress = sweep.ProgressLine(args.n)
    try:
        summary, histograms = sweep.run(
            args.input, args.tolerances, args.n, seed=args.seed, workers=args.workers,
            scheduler=args.scheduler, partition_count=args.partitions, rules=args.rules,
            progress=progress, clearance_body=_robot_stroke_body)
    finally:
        progress.close()
    # The summary first: a set of files that cannot be written loses nothing computed.
    if args.json:
        print(json.dumps(summary, indent=2), flush=True)
    else:
        print(sweep.format_summary(summary), flush=True)
    if args.out:
        sweep.write_outputs(summary, args.out, histograms)
        if not args.json:
            print(f"\nsummary.json, CSV tables and PNG plots written to {Path(args.out)}/")
    return 0


def _whole(minimum):
    """An argparse type: a whole number >= ``minimum`` (-n and --partitions 1, --workers and
    --seed 0; --workers 0: no Dask, in this process)."""

    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(
                f"must not be negative, got {text!r}" if minimum == 0
                else f"must be at least {minimum}, got {text!r}")
        return value

    return parse


_at_least_one, _not_negative = _whole(1), _whole(0)


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
    engines = sorted(ENGINES) + list(CAD_ENGINES)

    demo = sub.add_parser("demo", help="the paper's experiment: scan, Table 1 and the slot code")
    demo.add_argument("--out", metavar="DIR", help="write parameters.txt, commands.txt and "
                                                    "results.txt to DIR")
    demo.add_argument("--json", action="store_true", help="print one JSON object")
    demo.add_argument("--engine", choices=engines, default="document")
    demo.set_defaults(run=cmd_demo)

    scan = sub.add_parser("scan", help="scan a scenario .toml or a layout .FCStd")
    scan.add_argument("input", metavar="INPUT", help="scenario .toml or layout .FCStd")
    scan.add_argument("--params", metavar="FILE", help="a parameters.txt whose values override "
                                                       "the layout's")
    scan.add_argument("--engine", choices=engines, default="analytic")
    scan.add_argument("--mode", choices=MODES)
    scan.add_argument("--direction", choices=DIRECTIONS)
    scan.add_argument("--out", metavar="FILE", help="write the results in results.txt format "
                      "(a regular file or a new path; - for the standard output)")
    scan.add_argument("--json", action="store_true", help="print one JSON object")
    scan.add_argument("--plot", metavar="FILE", help="draw the sensor's signal b(z), thresholds, "
                      "edges and slot windows to a .png or .svg")
    scan.add_argument("--store", action="store_true", help="keep the results in the layout "
                                                           ".FCStd (its ScanResults spreadsheet)")
    scan.set_defaults(run=cmd_scan)

    calibrate = sub.add_parser("calibrate", help="recipe from reference wafers in the bottom "
                               "and top slots, then a check scan (exit 3, 4, 5: failures)")
    calibrate.add_argument("input", metavar="INPUT", help="scenario .toml or layout .FCStd")
    calibrate.add_argument("--params", metavar="FILE", help="a parameters.txt: the recipe to "
                           "start from (default: the layout's own)")
    calibrate.add_argument("--out", metavar="RECIPE", help="write the new recipe as a "
                           "parameters.txt")
    calibrate.add_argument("--engine", choices=sorted(ENGINES), default="analytic")
    calibrate.add_argument("--json", action="store_true", help="print one JSON object")
    calibrate.set_defaults(run=cmd_calibrate)

    layout = sub.add_parser("layout", help="build a FreeCAD layout from a scenario")
    layout.add_argument("scenario", metavar="SCENARIO.toml")
    layout.add_argument("-o", "--output", metavar="LAYOUT.FCStd", required=True)
    layout.set_defaults(run=cmd_layout)

    check = sub.add_parser("crosscheck", help="confirm every IN/OUT and every motion's "
                           "clearance with FreeCAD's B-rep geometry")
    check.add_argument("input", metavar="INPUT", help="scenario .toml or layout .FCStd")
    check.add_argument("--json", action="store_true", help="print one JSON object")
    check.set_defaults(run=cmd_crosscheck)

    watch = sub.add_parser("watch", help="the MCS link: carry out commands.txt in a folder")
    watch.add_argument("folder", metavar="DIR")
    watch.add_argument("--layout", metavar="INPUT", help="scenario .toml or layout .FCStd "
                                                         "(default: the paper's experiment)")
    watch.add_argument("--once", action="store_true", help="carry out what is pending, then exit")
    watch.add_argument("--engine", choices=engines, default="analytic")
    watch.add_argument("--poll", type=_poll_seconds, default=0.01, metavar="SECONDS",
                       help="how often commands.txt is checked for a change, one stat "
                            "(default 0.01 s)")
    watch.set_defaults(run=cmd_watch)

    serve = sub.add_parser("serve", help="the host link: the layout's carriers as SEMI E87 load "
                                         "ports a SECS/GEM host verifies over HSMS (SPEC §14)")
    serve.add_argument("input", metavar="INPUT", help="scenario .toml or layout .FCStd")
    serve.add_argument("--hsms", required=True, metavar="HOST:PORT",
                       help="where the equipment listens (with --active: the host to reach)")
    serve.add_argument("--active", action="store_true",
                       help="connect out to the host (HSMS active) instead of listening")
    serve.add_argument("--ids", metavar="IDS.toml",
                       help="the tool's CEIDs, DVIDs, SVIDs and ports (default: documented IDs)")
    serve.add_argument("--engine", choices=engines, default="analytic")
    serve.add_argument("--mcs", metavar="DIR",
                       help="an MCS link folder: LOAD <carrier-id> [<port>] places a carrier "
                            "(SCF, SCS, CAL as waferscan watch)")
    serve.add_argument("--empty", action="store_true",
                       help="start with the load ports empty (carriers arrive by LOAD)")
    serve.add_argument("--sml", action="store_true",
                       help="print every HSMS message, decoded (SML), on stdout")
    serve.set_defaults(run=cmd_serve)

    bench = sub.add_parser("bench", help="the engines side by side (SPEC §9)")
    bench.add_argument("--json", action="store_true", help="print one JSON object")
    bench.add_argument("--quick", action="store_true", help="smaller sweeps, fewer rounds")
    bench.add_argument("--no-gui", action="store_true", help="skip the GUI animation measure")
    bench.add_argument("--no-mcs", action="store_true", help="skip the MCS link measures")
    bench.add_argument("--only", choices=("sweep", "host", "floors"),
                       help="measure only these figures (sweep: SPEC §12's sweeps; host: SPEC "
                            "§14's host link; floors: fab, a scenario's and a 10,000-wafer "
                            "layout's scan beside their floors)")
    bench.add_argument("--plot", metavar="PNG", help="also plot cost against wafers and "
                                                     "against MCS history (needs matplotlib)")
    bench.set_defaults(run=cmd_bench)

    sweep = sub.add_parser("sweep", help="Monte Carlo check of a recipe under tolerances "
                                         "(SPEC §12), on Dask")
    sweep.add_argument("input", metavar="INPUT", help="scenario .toml or layout .FCStd")
    sweep.add_argument("--tolerances", metavar="TOL.toml", required=True,
                       help="the tolerances to draw from; a [clearance] table adds the rate of "
                            "scans with a contact (SPEC §15)")
    sweep.add_argument("-n", type=_at_least_one, required=True, metavar="N",
                       help="how many layouts to draw")
    sweep.add_argument("--seed", type=_not_negative, default=0,
                       help="the random seed, a whole number >= 0 (default 0)")
    where = sweep.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_not_negative, metavar="K",
                       help="local Dask worker processes (default: one per core; 0: no Dask)")
    where.add_argument("--scheduler", metavar="ADDR", help="an existing Dask scheduler, "
                                                           "e.g. tcp://HOST:8786 (its workers' "
                                                           "profiler is stopped and their "
                                                           "malloc trimming raised, for as "
                                                           "long as they run)")
    sweep.add_argument("--partitions", type=_at_least_one, metavar="P",
                       help="how many tasks the layouts are split into (default: 4 a worker; "
                            "the results do not depend on it)")
    sweep.add_argument("--rules", choices=("waferscan", "boundary"),
                       help="the rule set to map with (default: the recipe's)")
    sweep.add_argument("--out", metavar="DIR", help="write summary.json, CSV tables and PNG "
                                                    "plots to DIR")
    sweep.add_argument("--json", action="store_true", help="print the summary as JSON")
    sweep.set_defaults(run=cmd_sweep)
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
    except KeyboardInterrupt:  # Ctrl-C where a command has no stop of its own: one line
        sys.stderr.write(f"{PROG}: interrupted\n")
        return 130
    finally:
        # FreeCAD 1.0 quirk: sys.exit() in `freecadcmd -c` ends the process without flushing
        # Python's buffers, and a batch run's output would be lost.
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass


def console():
    """The `waferscan` console script: ``main`` in a process that ends with the command, so
    the documents it opens are left to the process's end (cad.CLOSE_AFTER_USE)."""
    from . import cad

    cad.CLOSE_AFTER_USE = False
    status = main()
    if _ENDS_AT_ONCE:
        # A scenario scanned without its document leaves nothing for Python's shutdown to do
        # but take pinocchio and coal apart (~40 ms of a 0.45 s command): main has flushed the
        # output, the process ends here.
        os._exit(0 if status is None else status)
    sys.exit(status)


if __name__ == "__main__":
    console()
