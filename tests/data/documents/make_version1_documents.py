"""Makes the documents of tests/cad/test_settings_units.py with the code of the commit before
issue 27 item 13's last changes (1628a1b: ScanSettings at version 1, SensorResponse and
SamplePeriod floats in s, WristSpeed and WristAcceleration bare floats, ThicknessTolerance a float
in mm whose negative value meant half the thickness), and what that code read and scanned from
them. Run from a checkout of that commit:

    git archive 1628a1b | tar -x -C /tmp/v1 && cd /tmp/v1 && \\
        PYTHONPATH=/tmp/v1 python3 /path/to/make_version1_documents.py OUT_FOLDER

(python3 with FreeCAD's lib on sys.path, as tests/conftest.py gives it). Writes
OUT_FOLDER/{explicit,defaults}.FCStd and version1.json."""

import json
import sys
from dataclasses import asdict, replace
from pathlib import Path

sys.path.insert(0, str(Path.cwd() / "tests"))
import conftest  # noqa: E402,F401  (FreeCAD's lib on sys.path)
import FreeCAD as App  # noqa: E402

from waferscan.addon import paper_scenario  # noqa: E402
from waferscan.cad.builder import build_document  # noqa: E402
from waferscan.cad.document_scan import scan_document  # noqa: E402
from waferscan.cad.layout_files import save_document  # noqa: E402
from waferscan.cad.reader import read_layout  # noqa: E402
from waferscan.core.files.scenario import read_scenario  # noqa: E402
from waferscan.core.sensor import settings  # noqa: E402


def layouts():
    paper = replace(read_scenario(paper_scenario()), robot=None)
    explicit = replace(paper, scan=replace(paper.scan, sensor_response=0.00025, wrist_speed=45.0,
                                           wrist_acceleration=180.0, sweep=1.5),
                       mapping=replace(paper.mapping, thickness_tolerance=0.3))
    explicit = settings.with_settings(explicit, {"latch": "sampled", "sample_period": 0.0005})
    return {"explicit": explicit, "defaults": paper}


def main(out):
    out.mkdir(parents=True, exist_ok=True)
    expected = {}
    for name, layout in layouts().items():
        doc = build_document(layout, name=f"Version1{name.title()}")
        try:
            read = read_layout(doc)
            result = scan_document(doc)
            expected[name] = {"scan": asdict(read.scan), "mapping": asdict(read.mapping),
                              "code": result.code, "runs": repr(result.runs),
                              "edges": repr(result.edges), "durations": dict(result.durations)}
            save_document(doc, out / f"{name}.FCStd")
        finally:
            App.closeDocument(doc.Name)
    (out / "version1.json").write_text(json.dumps(expected, indent=1, default=str) + "\n")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
