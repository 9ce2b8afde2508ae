"""The sensor's signal as a picture (SPEC §10 "Signal plot"): the blocked fraction b(z) along
the scan, the amplifier's thresholds, the latched ON/OFF edges and the scanned carrier's slot
windows; a close-up of the first runs beside the whole travel.

matplotlib is imported here only, when a plot is asked for: in the venv it is PyPI's, inside
FreeCAD Debian's (3.6, numpy 1.24); only what both offer is used. The Agg backend draws without
a display.
"""

from __future__ import annotations

from pathlib import Path

from ..core.errors import InputError
from ..core.files.text_files import replacing
from ..core.scan.sensing import SignalTrace

FORMATS = (".png", ".svg")
# Samples of b across each group of wafers (its reach is a few spot heights).
SAMPLES_PER_GROUP = 600


def signal_of(result):
    """The result's SignalTrace; for the ideal sensor b is 1 over each run, 0 elsewhere."""
    if result.signal is not None:
        return result.signal
    runs = tuple(r.unlatched or (r.bottom, r.top) for r in result.runs)
    return SignalTrace([], runs, 1.0, 1.0)


def signal_samples(result):
    """(z, b) arrays along the scan: dense across every group of wafers, the ideal beam's runs
    as steps, zero between."""
    import numpy as np

    scan = result.layout.scan
    signal = signal_of(result)
    points = [np.array([scan.start_z, scan.final_z])]
    for group in signal.groups:
        lo, hi = group.z_range
        points.append(np.linspace(lo, hi, SAMPLES_PER_GROUP))
    for lo, hi in signal.ideal_runs:
        span = max(hi - lo, 1e-6)
        points.append(np.array([lo - 1e-3 * span, lo, hi, hi + 1e-3 * span]))
    z = np.unique(np.concatenate(points))
    z = z[(z >= scan.start_z) & (z <= scan.final_z)]
    return z, signal.blocked(z)


def check_plot_path(path):
    """InputError unless ``path`` names a .png or .svg file."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise InputError(str(path), None, f"--plot writes {' or '.join(FORMATS)} files, "
                                          f"not {path.suffix or 'a file without a suffix'!r}")


def plot_signal(result, path, drawn=None):
    """Write the signal plot of a scan result to ``path`` (.png or .svg), atomically. A slow
    scan with a jab or a sweep adds its chosen pockets seen from above (plots/pockets.py);
    ``drawn``, a list, collects what those panels drew."""
    drawn = [] if drawn is None else drawn
    check_plot_path(path)
    path = Path(path)
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    with warnings.catch_warnings():
        # Debian's mpl_toolkits beside PyPI's matplotlib: only 3D plots suffer, none here.
        warnings.simplefilter("ignore", UserWarning)
        import matplotlib.pyplot as plt

    z, b = signal_samples(result)
    signal = signal_of(result)
    plan = result.plan
    edges = _edges(result)
    close = _close_up_runs(result)
    columns = max(1, len(close))
    pockets = bool(result.pockets)  # SPEC §13: a slow scan's pockets from above, a third row
    figure = plt.figure(figsize=(11, 6.5 + 3.8 * pockets))
    grid = figure.add_gridspec(2 + pockets, columns, height_ratios=(1.0, 1.1, 1.6)[:2 + pockets],
                               hspace=0.35 + 0.15 * pockets, wspace=0.25)
    whole = figure.add_subplot(grid[0, :])
    _draw(whole, z, b, signal, plan, edges, result, labels=True)
    scan = result.layout.scan
    whole.set_xlim(scan.start_z, scan.final_z)
    whole.set_title(f"Blocked fraction b(z): {_sensor_words(result)}; code {result.code}",
                    fontsize=10)
    for i, (lo, hi, title) in enumerate(close):
        axis = figure.add_subplot(grid[1, i])
        _draw(axis, z, b, signal, plan, edges, result, labels=False)
        axis.set_xlim(lo, hi)
        axis.set_title(title, fontsize=9)
    if pockets:
        from .pockets import draw_pockets

        draw_pockets(figure, grid[2, :], result, drawn)
    try:
        with replacing(path, suffix=f".tmp{path.suffix}") as temporary:
            figure.savefig(str(temporary), dpi=110)
    except OSError as exc:
        raise InputError(str(path), None, f"cannot write: {exc.strerror}") from None
    finally:
        plt.close(figure)


def _sensor_words(result):
    spot = result.layout.spot
    amplifier = result.layout.amplifier
    if spot is None or spot.ideal:
        words = "ideal line beam"
    elif spot.round:
        words = f"round spot {spot.diameter:g} mm"
    else:
        words = f"slit spot {spot.width:g} x {spot.height:g} mm"
    if amplifier is not None:
        words += f", thresholds {amplifier.threshold_on:g}/{amplifier.off_level:g}"
    return words + f", latch {result.layout.scan.latch}"


def _edges(result):
    from ..core.scan.sensing import scan_edges

    return scan_edges(result)


def _close_up_runs(result, count=3):
    """Up to ``count`` windows around distinct runs: the first, the first much longer one
    (a tilted wafer) and the first of another length."""
    chosen, seen = [], []
    for run in result.runs:
        kind = round(run.diff * 4)  # lengths a quarter millimetre apart count as others
        if kind in seen:
            continue
        seen.append(kind)
        pad = max(0.6, 0.4 * run.diff)
        spot = result.layout.spot
        if spot is not None and not spot.ideal:
            pad += spot.half_height
        names = ", ".join(run.wafers) or "run"
        chosen.append((run.bottom - pad, run.top + pad,
                       f"{names}: IN {run.z_in:.3f}, OUT {run.z_out:.3f}, {run.diff:.3f} mm"))
        if len(chosen) == count:
            break
    return chosen


def _draw(axis, z, b, signal, plan, edges, result, labels):
    for slot in range(1, plan.slot_count + 1):
        lo, hi = plan.window(slot)
        if slot % 2:
            axis.axvspan(lo, hi, color="0.93", lw=0)
        seat = plan.seat_z(slot)
        axis.axvline(seat, color="0.75", lw=0.6, ls=":")
    axis.plot(z, b, color="tab:blue", lw=1.2, label="b(z)")
    axis.axhline(signal.threshold_on, color="tab:red", lw=0.9, ls="--",
                 label=f"threshold_on {signal.threshold_on:g}")
    if signal.threshold_off != signal.threshold_on:
        axis.axhline(signal.threshold_off, color="tab:orange", lw=0.9, ls="--",
                     label=f"threshold_off {signal.threshold_off:g}")
    for i, edge in enumerate(edges):
        colour = "tab:green" if edge["edge"] == "on" else "tab:purple"
        marker = "^" if edge.get("stroke", "up") == "up" else "v"
        axis.plot([edge["z"]], [1.04], marker=marker, color=colour, ms=5, ls="none",
                  label=(f"{edge['edge'].upper()} edges" if labels and i < 2 else None))
        axis.axvline(edge["z"], color=colour, lw=0.5, alpha=0.6)
    axis.set_ylim(-0.03, 1.1)
    axis.set_xlabel("scan position z (mm)", fontsize=8)
    axis.set_ylabel("blocked fraction", fontsize=8)
    axis.tick_params(labelsize=7)
    if labels:
        axis.legend(loc="upper right", fontsize=7, ncol=4, framealpha=0.9)
