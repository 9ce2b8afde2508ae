"""A sweep's outputs: the summary as text for the terminal, and summary.json, the CSV tables
and the plots (plots/sweep.py) written as one set into ``--out``."""

from __future__ import annotations

import csv
import io
import json
import os
import shutil
import stat
from pathlib import Path

from ..core import sweep
from ..core.errors import InputError
from ..core.files.text_files import atomic_write_text
from ..plots.sweep import plot_sweep

# --- outputs ---------------------------------------------------------------------------------

def _csv(rows):
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerows(rows)
    return buffer.getvalue()


def confusion_rows(summary):
    """The confusion matrix as CSV rows: true state down, reported state across."""
    names = sweep.STATE_KEYS
    rows = [["true \\ reported", *names]]
    for true, counts in summary["confusion"].items():
        rows.append([true, *[counts.get(r, 0) for r in names]])
    return rows


def rate_rows(summary):
    rows = [["state", "true", "reported", "correct", "miss_rate", "miss_low95", "miss_high95",
             "false_call_rate", "false_call_low95", "false_call_high95"]]
    for state, r in summary["rates"].items():
        rows.append([state, r["true"], r["reported"], r["correct"], r["miss_rate"],
                     *r["miss_rate_95"], r["false_call_rate"], *r["false_call_rate_95"]])
    return [[("" if v is None else v) for v in row] for row in rows]


def margin_rows(summary):
    keys = ["count", "min", *[f"p{p}" for p in sweep.PERCENTILES], "max"]
    rows = [["margin", *keys]]
    for name, dist in summary["margins"].items():
        rows.append([name, *(["" for _ in keys] if dist is None else [dist[k] for k in keys])])
    return rows


def clearance_rows(summary):
    """The [clearance] report as CSV rows (clearance.csv): the rate with its interval, the
    least distances' distribution, the contacts by closest part and by slot."""
    c = summary["clearance"]
    least = c["least_distance"] or {}
    keys = ["min", *[f"p{p}" for p in sweep.PERCENTILES], "max"]
    rows = [["body", "clearance_min", "layouts", "contacts", "contact_rate", "low95", "high95",
             *[f"least_{k}" for k in keys]],
            [c["body"], c["clearance_min"], c["layouts"], c["contacts"], c["contact_rate"],
             *c["contact_rate_95"], *[least.get(k, "") for k in keys]],
            [], ["closest part", "contacts"], *[[k, v] for k, v in c["contacts_by_part"].items()],
            [], ["slot", "contacts"], *[[k, v] for k, v in c["contacts_by_slot"].items()]]
    return [[("" if v is None else v) for v in row] for row in rows]


OUTPUT_NAMES = ("summary.json", "confusion.csv", "rates.csv", "margins.csv", "confusion.png",
                "margins.png", "clearance.csv")


def output_folder(folder):
    """Check the sweep's output folder before the sweep, so that a path that cannot be one is
    refused before the work, not after it (InputError): a new path in a folder that can be
    written in, or a folder holding nothing but a sweep's outputs (it is replaced as a whole).
    Nothing is made yet."""
    folder = Path(folder)
    try:
        st = os.stat(folder, follow_symlinks=False)
    except FileNotFoundError:
        parent = folder.parent
        if not parent.is_dir():
            raise InputError(folder, None, f"cannot make the folder: no folder {parent}") \
                from None
        if not os.access(parent, os.W_OK | os.X_OK):
            raise InputError(folder, None, f"cannot make the folder: cannot write in {parent}")
        return folder
    except OSError as exc:
        raise InputError(folder, None, f"cannot make the folder: {exc.strerror}") from None
    if not stat.S_ISDIR(st.st_mode):
        raise InputError(folder, None, "cannot make the folder: File exists")
    others = sorted(set(os.listdir(folder)) - set(OUTPUT_NAMES))
    if others:
        raise InputError(folder, None, f"holds other files than a sweep's ({others[0]!r}"
                                       f"{' …' if len(others) > 1 else ''}): --out is replaced "
                                       "as a whole; name a new folder")
    if not os.access(folder.parent, os.W_OK | os.X_OK):
        raise InputError(folder, None, f"cannot replace it: cannot write in {folder.parent}")
    return folder


def write_outputs(summary, folder, histograms=None):
    """summary.json, confusion.csv, rates.csv, margins.csv, confusion.png and margins.png (and
    clearance.csv with a [clearance] report) as one set: written in a temporary folder beside ``folder``, then renamed into place (an
    earlier sweep's set there is replaced as a whole: never one file from each). Returns the
    paths written; InputError (nothing at ``folder`` changed) when they cannot be."""
    folder = output_folder(folder)
    temporary = folder.with_name(f".{folder.name}.{os.getpid()}.tmp")
    old = folder.with_name(f".{folder.name}.{os.getpid()}.old")
    files = {
        "summary.json": json.dumps(summary, indent=2) + "\n",
        "confusion.csv": _csv(confusion_rows(summary)),
        "rates.csv": _csv(rate_rows(summary)),
        "margins.csv": _csv(margin_rows(summary)),
    }
    if "clearance" in summary:  # a [clearance] report was asked for
        files["clearance.csv"] = _csv(clearance_rows(summary))
    try:
        shutil.rmtree(temporary, ignore_errors=True)
        os.mkdir(temporary)
        for name, text in files.items():
            atomic_write_text(temporary / name, text)
        plot_sweep(summary, temporary, histograms)
        if folder.exists():
            os.rename(folder, old)
            try:
                os.rename(temporary, folder)
            except OSError:
                os.rename(old, folder)  # put the earlier set back
                raise
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(temporary, folder)
    except OSError as exc:
        raise InputError(folder, None, f"cannot write: {exc.strerror}; nothing written "
                                       "(the summary is on the standard output)") from None
    finally:
        shutil.rmtree(temporary, ignore_errors=True)
    return [folder / name for name in OUTPUT_NAMES
            if name != "clearance.csv" or "clearance" in summary]


def format_summary(summary):
    """A short text report: the confusion matrix, the rates and the margins."""
    names = sweep.STATE_KEYS
    lines = [f"{summary['n']:,} layouts, seed {summary['seed']}, rules {summary['rules']}",
             "", "confusion (true down, reported across):",
             "  " + f"{'true':>14} " + " ".join(f"{n[:10]:>10}" for n in names)]
    for true, counts in summary["confusion"].items():
        lines.append("  " + f"{true:>14} " + " ".join(f"{counts.get(r, 0):>10,}"
                                                      for r in names))
    lines += ["", "per state: miss rate [95 %], false-call rate [95 %] (intervals over the layouts)"]
    for state, r in summary["rates"].items():
        def pct(v, ci):
            if v is None:
                return "      -"
            return f"{100 * v:6.2f} % [{100 * ci[0]:.2f}, {100 * ci[1]:.2f}]"
        lines.append(f"  {state:>14}: miss {pct(r['miss_rate'], r['miss_rate_95'])}, "
                     f"false call {pct(r['false_call_rate'], r['false_call_rate_95'])}")
    for key, dist in summary["margins"].items():
        if dist:
            lines.append(f"{key} margin (mm): min {dist['min']:.4f}, p1 {dist['p1']:.4f}, "
                         f"median {dist['p50']:.4f}")
    if summary.get("suggested"):
        s = summary["suggested"]
        lines.append(f"safer windows: thickness {s['thickness_min']:.4f} to "
                     f"{s['thickness_max']:.4f} mm, position -{s['position_below']:.4f} / "
                     f"+{s['position_above']:.4f} mm, threshold_on {s['threshold_on']:g}")
    if "clearance" in summary:
        from ..core.sweep.clearance import format_clearance

        lines += format_clearance(summary["clearance"])
    return "\n".join(lines)
