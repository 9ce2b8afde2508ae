"""Plot `waferscan bench --json` output: cost against the number of steps and against the number
of wafers, per engine (log-log). Run with Debian's Python, whose matplotlib matches its numpy:

    .venv/bin/waferscan bench --json > build/bench.json
    /usr/bin/python3 scripts/plot_bench.py build/bench.json docs/bench.png
"""

import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"analytic": "tab:green", "vector": "tab:blue", "loop": "tab:red"}


def main(source, target):
    rows = json.load(open(source, encoding="utf-8"))["results"]
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, workload, key, label in ((axes[0], "steps", "steps", "stepped positions (10 wafers)"),
                                     (axes[1], "wafers", "wafers", "wafers (5,401 positions)")):
        for engine, colour in COLOURS.items():
            points = sorted((r[key], r["seconds"], r["extrapolated"]) for r in rows
                            if r["workload"] == workload and r["engine"] == engine)
            if not points:
                continue
            ax.plot([p[0] for p in points], [p[1] for p in points], "-", color=colour,
                    label=engine)
            for x, y, extrapolated in points:
                ax.plot(x, y, "o", color=colour, fillstyle="none" if extrapolated else "full")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("seconds per scan (median)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    axes[0].set_title("cost against steps")
    axes[1].set_title("cost against wafers")
    figure.text(0.5, 0.01, "open markers: extrapolated from a subset of the steps",
                ha="center", fontsize=8)
    figure.tight_layout(rect=(0, 0.03, 1, 1))
    figure.savefig(target, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
