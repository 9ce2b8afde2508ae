"""`waferscan scan X.toml` without the FreeCAD document (robot.scenario_scan, SPEC §9 amended):
its outputs are byte for byte those of the scan through the built document, the way every scan
of a scenario went before (stdout's table, results.txt, the warnings on stderr, the exit status
and the error lines), over the examples and random scenarios; the carrier's boxes it checks the
clearance against are the document's own numbers; and FreeCAD is not imported on its way."""

import json
import math
import random
import subprocess
import sys

import pytest
from random_layouts import random_layout
from scenarios import EXAMPLES, PAPER, PAPER_TEXT, ROOT, TWO_CARRIERS_TEXT

from waferscan import cli

EXAMPLE_FILES = sorted(EXAMPLES.glob("*.toml"))


def run(argv, capsys, document, monkeypatch, out=None):
    """``waferscan`` ARGV in this process: (exit status, stdout, stderr, results.txt's text,
    both without results.txt's timestamp, whether the scan went without a document).
    ``document``: through the built document, as every scenario was scanned before."""
    with monkeypatch.context() as patch:
        patch.setattr(cli, "_ENDS_AT_ONCE", [])
        if document:
            patch.setattr(cli, "_scan_scenario", lambda *args, **kw: None)
        if out is not None and out.exists():
            out.unlink()
        status = cli.main(argv)
        captured = capsys.readouterr()
        written = untimed(out.read_text()) if out is not None and out.exists() else None
        return status, untimed(captured.out), captured.err, written, bool(cli._ENDS_AT_ONCE)


def untimed(text):
    """results.txt's text without its timestamp line (the time it was written)."""
    return "".join(line for line in text.splitlines(True) if not line.startswith("timestamp = "))


def same_outputs(argv, capsys, monkeypatch, out=None):
    """Both ways' outputs equal, byte for byte; whether the scan went without a document."""
    free = run(argv, capsys, False, monkeypatch, out)
    through = run(argv, capsys, True, monkeypatch, out)
    assert free[:4] == through[:4], argv
    assert not through[4]
    return free[4]


OPTIONS = ([], ["--engine", "loop"], ["--engine", "vector"], ["--engine", "paper"],
           ["--mode", "slow"], ["--direction", "down"])


@pytest.mark.parametrize("example", EXAMPLE_FILES, ids=lambda p: p.name)
def test_examples_print_what_their_documents_print(example, capsys, monkeypatch, tmp_path):
    out = tmp_path / "results.txt"
    free = [same_outputs(["scan", str(example), *options, "--out", str(out)], capsys,
                         monkeypatch, out)
            for options in OPTIONS]
    free.append(same_outputs(["scan", str(example), "--out", "-"], capsys, monkeypatch))
    if example.name in ("paper.toml", "calibration_drifted.toml"):  # fast scans with the robot
        assert free[0] and free[1] and free[2]
    if example.name == "fab_tolerances.toml":  # a TOL.toml: refused by the scenario's reader
        assert not any(free)


def test_the_paper_scan_goes_without_a_document(capsys, monkeypatch):
    """The paper's scan (the bench's workload) takes the new way, with its robot's clearance
    and the carrier's 55 solids checked; --json stays on the document (its full floats)."""
    status, stdout, _, _, free = run(["scan", str(PAPER)], capsys, False, monkeypatch)
    assert status == 0 and free
    assert "code 1101221001220001010000010" in stdout
    status, stdout, _, _, free = run(["scan", str(PAPER), "--json"], capsys, False, monkeypatch)
    assert status == 0 and not free
    assert json.loads(stdout)["clearance"]["carrier"] == "checked: 55 solids of LP1"


def _toml_value(value):
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return repr(float(value))


def scenario_text(layout, mapping=""):
    """A core Layout written as a scenario: its carriers, every wafer a free placement."""
    scan = layout.scan
    lines = ["[scan]", f'carrier = "{layout.carrier}"', f"start_z = {scan.start_z!r}",
             f"final_z = {scan.final_z!r}", f"z_step = {scan.z_step!r}", "",
             "[sensor]", f"emitter = {_toml_value(layout.beam.emitter)}",
             f"direction = {_toml_value(layout.beam.direction)}",
             f"length = {layout.beam.length!r}", f"lift_axis = {_toml_value(layout.lift_axis)}",
             "", "[mapping]", mapping, ""]
    for c in layout.carriers:
        lines += ["[[carrier]]", f'name = "{c.name}"', f"slots = {c.slot_count}",
                  f"pitch = {c.pitch!r}", f"first_slot_z = {c.first_slot_z!r}",
                  f"center = {_toml_value(c.center)}", f"front = {_toml_value(c.front)}",
                  f"wafer_diameter = {c.wafer_diameter!r}",
                  f"wafer_thickness = {c.wafer_thickness!r}",
                  f"support_span = {c.support_span!r}", ""]
    for w in layout.wafers:
        lines += ["[[wafer]]", f'name = "{w.name}"', f"center = {_toml_value(w.center)}",
                  f"normal = {_toml_value(w.normal)}", f"diameter = {w.diameter!r}",
                  f"thickness = {w.thickness!r}", ""]
    return "\n".join(lines)


def test_random_scenarios_print_what_their_documents_print(capsys, monkeypatch, tmp_path):
    """Random carriers turned every way, free wafers tilted every way, tilted beams and lift
    axes (tests/random_layouts.py), scanned by the scanner's heads (no robot). Where a head
    runs into a wafer the document answers (its clearance searched, not swept): some of them."""
    out = tmp_path / "results.txt"
    free = []
    for seed in range(12):
        rng = random.Random(7100 + seed)
        layout = random_layout(rng, max_steps=600)
        mapping = f"clearance_min = {rng.choice([0.5, 1.0, 3.0, 20.0])!r}"
        path = tmp_path / f"random{seed}.toml"
        path.write_text(scenario_text(layout, mapping))
        for options in ([], ["--engine", "vector"]):
            free.append(same_outputs(["scan", str(path), *options, "--out", str(out)], capsys,
                                     monkeypatch, out))
    assert sum(free) >= 4


def _paper_variant(rng):
    """The paper's scenario (its robot) with a random load, beam depth, step and clearance_min:
    contacts, exact edges, a beam the robot cannot reach. A protruding wafer or a beam set
    deeper runs the fork into the wafers: the document answers those."""
    load = []
    while len(load) < 25:
        digit = rng.choice("01111345" + ("2" if len(load) < 24 else ""))
        load += ["2", "2"] if digit == "2" else [digit]
    y = 266.6 + rng.choice([0.0, 0.0, rng.uniform(-6.0, 0.5)])
    step = rng.choice([0.05, 0.013, 0.1, 0.0])
    text = (PAPER_TEXT.replace('load = "1101221001220001010000010"', f'load = "{"".join(load)}"')
            .replace("emitter = [-80.0, 266.6, 280.0]", f"emitter = [-80.0, {y!r}, 280.0]")
            .replace("z_step = 0.05", f"z_step = {step!r}")
            .replace("clearance_min = 0.5", f"clearance_min = {rng.uniform(0.2, 2.0)!r}"))
    assert text.count("\n") == PAPER_TEXT.count("\n")
    return text, step


def test_random_paper_scenarios_print_what_their_documents_print(capsys, monkeypatch,
                                                                  tmp_path):
    out = tmp_path / "results.txt"
    free = []
    for seed in range(12):
        rng = random.Random(7200 + seed)
        text, step = _paper_variant(rng)
        path = tmp_path / f"paper{seed}.toml"
        path.write_text(text)
        for engine in ["analytic"] if step == 0.0 else ["analytic", "loop"]:
            free.append(same_outputs(["scan", str(path), "--engine", engine, "--out", str(out)],
                                     capsys, monkeypatch, out))
    assert sum(free) >= 6


@pytest.mark.parametrize("old, new", [
    ("length = 160.0", "length = 150.0"),  # the fork holds its heads 160 mm apart
    ("base = [0.0, -300.0, 0.0]", "base = [0.0, -900.0, 0.0]"),  # out of the arm's reach
    ("z_step = 0.05", "z_step = 0.0"),  # exact edges: the loop engine refuses them
    ("pitch = 10.0", "pitch = -10.0"),  # the scenario's reader refuses it
])
def test_errors_are_the_documents(old, new, capsys, monkeypatch, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(PAPER_TEXT.replace(old, new, 1))
    argv = ["scan", str(path), "--engine", "loop"]
    free = run(argv, capsys, False, monkeypatch)
    through = run(argv, capsys, True, monkeypatch)
    assert free[:4] == through[:4]
    assert free[0] == 2 and free[2].startswith("waferscan: error: ") and free[2].count("\n") == 1


def test_parameters_over_a_scenario(capsys, monkeypatch, tmp_path):
    """A parameters.txt over the scenario: its values, and a bad one's line, as the document's."""
    good = tmp_path / "parameters.txt"
    good.write_text("thickness_tolerance = 0.2\nposition_tolerance = 0.4\n")
    assert same_outputs(["scan", str(PAPER), "--params", str(good)], capsys, monkeypatch)
    bad = tmp_path / "bad.txt"
    bad.write_text("z_step = 0.05\nposition_tolerance = -1\n")
    same_outputs(["scan", str(PAPER), "--params", str(bad)], capsys, monkeypatch)
    # Two carriers, the second one scanned: its own solids are the obstacles.
    two = tmp_path / "two.toml"
    two.write_text(TWO_CARRIERS_TEXT)
    other = tmp_path / "other.txt"
    other.write_text("carrier = LP2\nstart_z = 590.0\nfinal_z = 870.0\n")
    for params in ([], ["--params", str(other)]):
        same_outputs(["scan", str(two), *params], capsys, monkeypatch)


def test_carrier_boxes_are_the_documents(built):
    """The boxes the scan without a document checks are the built carrier's solids as the
    document's scan reads them: the same names, the same corners (exactly for a carrier facing
    -Y, to rounding for a turned one)."""
    from dataclasses import replace

    from waferscan.cad.document_scan import _carrier_solids
    from waferscan.cad.reader import DocumentScene, read_layout
    from waferscan.core.files.scenario import read_scenario
    from waferscan.robot.scenario_scan import carrier_solids

    paper = read_scenario(PAPER)
    rng = random.Random(7300)
    turned = [replace(paper.carriers[0], front=(math.sin(a), -math.cos(a)),
                      slot_count=rng.randint(1, 25), pitch=rng.uniform(5.0, 12.0),
                      center=(rng.uniform(-50, 50), rng.uniform(300, 500)))
              for a in (0.0, 0.0, 0.3, -1.1, math.pi / 2)]
    for k, carrier in enumerate(turned):
        layout = replace(paper, carriers=(carrier,), wafers=(), robot=None)
        doc = built(layout, f"Boxes{k}")
        scene = DocumentScene.of(doc)
        read = read_layout(doc, scene)
        document = _carrier_solids(scene, read)
        free = carrier_solids(layout)
        assert [name for _, _, name in free] == [name for _, _, name in document]
        for (corners, _, _), (read_corners, triangles, _) in zip(free, document):
            assert triangles is None
            if carrier.front == (0.0, -1.0):
                assert corners == read_corners
            else:
                assert max(abs(a - b) for p, q in zip(corners, read_corners)
                           for a, b in zip(p, q)) < 1e-9


def test_freecad_is_not_imported(tmp_path):
    """The process scans the paper's scenario without importing FreeCAD (nor Part, nor Qt),
    and the console's quick exit loses none of its output."""
    code = ("import sys, waferscan.cli as c\n"
            f"status = c.main(['scan', {str(PAPER)!r}])\n"
            "loaded = sorted(m for m in sys.modules if m.split('.')[0] in "
            "('FreeCAD', 'FreeCADGui', 'Part', 'PySide', 'PySide2', 'shiboken2'))\n"
            "sys.stderr.write(f'status {status} loaded {loaded}\\n')\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert done.stderr.strip().endswith("status 0 loaded []"), done.stderr
    console = subprocess.run([sys.executable, "-m", "waferscan.cli", "scan", str(PAPER)],
                             cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert console.returncode == 0 and console.stdout == done.stdout
    assert console.stdout.splitlines()[-1].startswith("simulated duration: fast ")
