"""Plot `waferscan bench --json` output (``waferscan.bench.plot``): cost against the number of
steps, against the number of wafers and against the MCS link's history. Runs in the venv
(matplotlib from PyPI) or in FreeCAD's Python (Debian's):

    .venv/bin/waferscan bench --json > build/bench.json
    .venv/bin/python scripts/plot_bench.py build/bench.json docs/bench.png

(`waferscan bench --plot docs/bench.png` draws it at the end of the run.)
"""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from waferscan.bench import plot  # noqa: E402


def main(source, target):
    plot(json.loads(Path(source).read_text(encoding="utf-8")), target)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
