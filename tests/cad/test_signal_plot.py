"""``waferscan scan … --plot FILE.png|svg`` (SPEC §10): the signal plot is written in the venv
(PyPI's matplotlib) and inside FreeCAD (Debian's), its samples are the model's b(z), and a
wrong suffix is bad input."""

from dataclasses import replace

import numpy as np
from commands import cli_in_freecad, freecadcmd, waferscan
from figures import PNG_SIGNATURE
from scenarios import paper_with

from waferscan.cli import paper_scenario
from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan.layout_scan import scan_layout
from waferscan.core.sensor.spot import BeamSpot, BlockedFraction
from waferscan.plots.signal import signal_samples


def spot_scenario(tmp_path):
    return paper_with(tmp_path, "[sensor]\n", "[sensor]\nspot_diameter = 1.0\n", "spot.toml")


def test_plot_files_from_the_venv(tmp_path):
    scenario = spot_scenario(tmp_path)
    for name, head in (("s.png", PNG_SIGNATURE), ("s.svg", b"<?xml")):
        done = waferscan("scan", scenario, "--plot", tmp_path / name)
        assert done.returncode == 0, done.stderr
        data = (tmp_path / name).read_bytes()
        assert data.startswith(head) and len(data) > 10_000
    assert b"<svg" in (tmp_path / "s.svg").read_bytes()[:2000]
    assert not list(tmp_path.glob(".*tmp*"))


def test_a_plot_without_png_or_svg_is_bad_input(tmp_path):
    done = waferscan("scan", spot_scenario(tmp_path), "--plot", tmp_path / "s.pdf")
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {tmp_path / 's.pdf'}: --plot writes .png")
    assert not (tmp_path / "s.pdf").exists()


def test_plot_inside_freecad(tmp_path):
    scenario = spot_scenario(tmp_path)
    target = tmp_path / "fc.png"
    done = freecadcmd(cli_in_freecad("scan", scenario, "--plot", target))
    assert target.read_bytes().startswith(b"\x89PNG"), done.stdout + done.stderr


def test_the_plotted_samples_are_the_models_blocked_fraction():
    paper = replace(read_scenario(paper_scenario()), spot=BeamSpot(diameter=1.0))
    result = scan_layout(paper)
    z, b = signal_samples(result)
    first = paper.wafers[0]
    fraction = BlockedFraction(paper, [first], paper.spot)
    near = (z > first.center[2] - 0.6) & (z < first.center[2] + 1.3)
    assert near.sum() > 100
    expected = fraction(z[near] - paper.beam.emitter[2])
    assert np.allclose(b[near], expected, atol=1e-12)
    assert b.max() > 0.99 and abs(b[near].max() - fraction(first.center[2] + 0.35 - 280.0)) < 1e-3
