"""Traces what the document engine's MCS link keeps from one command to the next (issue 25):
N commands (N > 10) on a layout, SCS and SCF in turn, Python's allocations compared between
the 10th and the last, the TOP (default 6) places that grew printed with their tracebacks.

    .venv/bin/python scripts/trace_doc_watch.py resources/examples/slow_jab.toml 30 [TOP]

runs it on this machine's FreeCAD (Z_STEP=2 in the environment for a coarser, faster scan);
inside scripts/freecad1-run.sh, with "$WAFERSCAN_VENV/bin/python", on FreeCAD 1.0."""
import gc
import os
import sys
import tempfile
import tracemalloc
from pathlib import Path
from types import SimpleNamespace

sys.path.append("/usr/lib/freecad-python3/lib")
sys.path.append("/usr/lib/freecad/lib")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import FreeCAD as App  # noqa: E402

from waferscan.cad.layout_files import open_layout  # noqa: E402
from waferscan.cad.mcs_watch import document_scanner  # noqa: E402

layout, n = sys.argv[1], int(sys.argv[2])
folder = Path(tempfile.mkdtemp())
(folder / "parameters.txt").write_text(f"z_step = {os.environ.get('Z_STEP', '0.5')}\n")
doc = open_layout(layout)
scan = document_scanner(doc, folder, "document")
tracemalloc.start(12)
first = None
for k in range(n):
    scan(SimpleNamespace(name=("SCS", "SCF")[k % 2], line=k + 1), lambda: None)
    if k == 9:
        gc.collect()
        first = tracemalloc.take_snapshot()
gc.collect()
last = tracemalloc.take_snapshot()
# the snapshot's own bookkeeping and one-off imports are not the link's
ignored = [tracemalloc.Filter(False, tracemalloc.__file__, all_frames=True),
           tracemalloc.Filter(False, "<frozen importlib._bootstrap*>", all_frames=True)]
first, last = first.filter_traces(ignored), last.filter_traces(ignored)
stats = last.compare_to(first, "traceback")
total = sum(s.size_diff for s in stats)
print(f"FreeCAD {'.'.join(App.Version()[:3])}, {layout}, {n - 10} commands: "
      f"{total / (n - 10):+.0f} B a command")
for s in stats[:int(sys.argv[3]) if len(sys.argv) > 3 else 6]:
    print(f"{s.size_diff / (n - 10):+.0f} B/cmd, {s.count_diff} blocks")
    for line in s.traceback.format()[-12:]:
        print("   ", line)
