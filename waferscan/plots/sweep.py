"""A sweep's plots: confusion.png (the counts, true state down, reported across) and margins.png
(the margins of the truly present wafers), from the summary ``core.sweep`` made."""

from __future__ import annotations

from ..core import sweep
from ..core.files.text_files import replacing

def plot_sweep(summary, folder, histograms=None):
    """confusion.png (counts, true state down, reported across) and margins.png (histograms of
    the thickness and position margins of the truly present wafers, when ``histograms`` gives
    them as (counts, bin edges): the sweep's tally's; else their percentiles)."""
    import warnings

    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    with warnings.catch_warnings():
        # Debian's mpl_toolkits beside PyPI's matplotlib: only 3D plots suffer, none here.
        warnings.simplefilter("ignore", UserWarning)
        import matplotlib.pyplot as plt

    names = sweep.STATE_KEYS
    true_names = list(summary["confusion"])
    matrix = np.array([[summary["confusion"][t].get(r, 0) for r in names] for t in true_names])
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.imshow(np.log10(matrix + 1), cmap="Blues")
    ax.set_xticks(range(len(names)), names, rotation=35, ha="right")
    ax.set_yticks(range(len(true_names)), true_names)
    ax.set_xlabel("reported state")
    ax.set_ylabel("true state")
    for i in range(len(true_names)):
        for j in range(len(names)):
            if matrix[i, j]:
                ax.text(j, i, f"{matrix[i, j]:,}", ha="center", va="center", fontsize=8)
    ax.set_title(f"Confusion of {summary['n']:,} layouts (seed {summary['seed']})")
    fig.tight_layout()
    out = [folder / "confusion.png"]
    _save(fig, out[0])
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key in zip(axes, ("thickness", "position")):
        hist = None if histograms is None else histograms.get(key)
        dist = summary["margins"].get(key)
        if hist is not None:
            ax.stairs(hist[0], hist[1], fill=True, color="tab:blue")
        elif dist:
            keys = ["min", *[f"p{p}" for p in sweep.PERCENTILES], "max"]
            ax.plot([dist[k] for k in keys], range(len(keys)), "o-")
            ax.set_yticks(range(len(keys)), keys)
        ax.axvline(0.0, color="tab:red", lw=1)
        ax.set_xlabel(f"{key} margin to the recipe's window (mm)")
        ax.set_title(f"{key}: worst {dist['min']:.4f} mm" if dist else f"{key}: no present wafer")
    fig.tight_layout()
    out.append(folder / "margins.png")
    _save(fig, out[1])
    return out


def _save(figure, path):
    """The figure as a PNG at ``path``, whole or not at all; the figure closed."""
    import matplotlib.pyplot as plt

    try:
        with replacing(path, suffix=".tmp.png") as temporary:
            figure.savefig(temporary, dpi=100)
    finally:
        plt.close(figure)
