"""The Documents figure of the bench (bench.documents): `waferscan scan X.FCStd` against
FreeCAD's open + placement read of X. Its structure, and that the file it scans gives the
scenario's own results; no timing is asserted."""

import json
import subprocess

import pytest

from waferscan.bench.documents import bench_document_floor, floor_command
from waferscan.bench.processes import cli, process_environment, timed_run


def json_scan(path):
    done = subprocess.run(cli("scan", path, "--json"), capture_output=True,
                          env=process_environment(), timeout=600, check=True)
    return json.loads(done.stdout)


def test_quick_round_structure_and_the_scan_of_its_file(tmp_path):
    figures = bench_document_floor(1, quick=True, folder=tmp_path)
    assert set(figures) == {"scan", "floor", "ratio", "wafers", "file_bytes"}
    assert figures["wafers"] == 1_000
    assert all(figures[k] > 0.0 for k in ("scan", "floor", "ratio"))
    layout = tmp_path / "stack-1000.FCStd"
    assert figures["file_bytes"] == layout.stat().st_size
    scanned = json_scan(layout)
    assert scanned == json_scan(tmp_path / "stack-1000.toml")
    assert len(scanned["wafers"]) == len(scanned["runs"]) == 1_000
    # The floor opens the file for real: a missing one fails it.
    with pytest.raises(RuntimeError):
        timed_run(floor_command(tmp_path / "missing.FCStd"))
