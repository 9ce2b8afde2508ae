"""The bench's plot: cost against the steps, against the wafers and against the MCS link's
history, log-log, drawn from a report's rows (`waferscan bench --plot`,
scripts/plot_bench.py).

Exports ``plot`` and ``PLOT_SERIES``."""

from __future__ import annotations

__all__ = ["plot", "PLOT_SERIES"]

PLOT_SERIES = (
    # (panel, workload, engine, colour, label)
    (0, "steps", "analytic", "tab:green", "analytic"),
    (0, "steps", "vector", "tab:blue", "vector"),
    (0, "steps", "loop", "tab:red", "loop"),
    (1, "wafers", "analytic scan_layout (stack)", "tab:green", "scan_layout, stacked FOUPs"),
    (1, "wafers", "analytic scan_layout (row)", "tab:olive", "scan_layout, FOUPs in a row"),
    (1, "wafers", "document build", "tab:purple", "document build (in process)"),
    (1, "wafers", "document read", "tab:pink", "document read (in process)"),
    (1, "wafers", "waferscan layout", "tab:brown", "waferscan layout (process)"),
    (1, "wafers", "waferscan scan", "tab:gray", "waferscan scan (process)"),
    (2, "mcs", "watch idle (CPU s per s)", "tab:red", "idle watcher"),
)


def plot(report, target):
    """Cost against the steps, against the wafers and against the MCS history, log-log, as a
    PNG. matplotlib is imported here only: in the venv it is PyPI's (built for numpy 2),
    inside FreeCAD Debian's (numpy 1.24); both draw this."""
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    with warnings.catch_warnings():
        # Debian's mpl_toolkits beside PyPI's matplotlib: only 3D plots suffer, none here.
        warnings.simplefilter("ignore", UserWarning)
        import matplotlib.pyplot as plt

    rows = report["results"]
    figure, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    keys = {0: "steps", 1: "wafers", 2: "history"}
    for panel, workload, engine, colour, label in PLOT_SERIES:
        points = sorted((r[keys[panel]], r["seconds"], bool(r.get("sampled_steps")))
                        for r in rows if r["workload"] == workload and r["engine"] == engine)
        if not points:
            continue
        ax = axes[panel]
        ax.plot([p[0] for p in points], [p[1] for p in points], "-", color=colour, label=label)
        for x, y, part in points:
            ax.plot(x, y, "o", color=colour, fillstyle="none" if part else "full")
    titles = (("cost against steps (paper layout, 10 wafers)", "stepped positions",
               "seconds per scan (median)"),
              ("cost against wafers", "wafers", "seconds (median)"),
              ("idle MCS link against history", "lines in commands.txt",
               "CPU seconds per second"))
    for ax, (title, xlabel, ylabel) in zip(axes, titles):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=8)
            # At least two decades on the cost axis: a flat series drawn over its own narrow
            # range (the idle link's 5.6-6.7 ms/s) would show its noise as a peak.
            low, high = ax.get_ylim()
            if high / low < 100.0:
                middle = (low * high) ** 0.5
                ax.set_ylim(middle / 10.0, middle * 10.0)
    figure.text(0.5, 0.01, "open markers: sampled over the whole travel and scaled by the "
                "number of positions", ha="center", fontsize=8)
    figure.tight_layout(rect=(0, 0.03, 1, 1))
    figure.savefig(target, dpi=100)
    plt.close(figure)
