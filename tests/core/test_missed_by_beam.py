"""Issue 27, item 3: a beam that crosses no wafer gave a silent all-empty map. The scanned
carrier's wafers that the beam meets at no height are warned about (SPEC §3: JSON, results.txt,
stderr, the GUI), naming how many and by how much the beam passes beside them. The distance is
checked against the closed form itself: moved towards the wafer by a hair less it still misses,
by a hair more it meets it."""

import json
import re
from dataclasses import replace

import pytest
from commands import waferscan as run
from scenarios import PAPER_CODE, PAPER_TEXT, with_lines

from waferscan.core.files.mcs import format_results
from waferscan.core.files.scenario import read_scenario
from waferscan.core.geometry.ranges import translation_range
from waferscan.core.model import Beam
from waferscan.core.scan.layout_scan import scan_layout

PAPER_EMITTER = "emitter = [-80.0, 266.6, 280.0]"


def moved(folder, emitter, extra=()):
    """The paper's scenario with its beam's emitter at ``emitter`` (no robot: the scanner
    alone), with ``extra`` lines added to its [sensor] table."""
    text = re.sub(r"\[robot\]\n(?:[^\[\n].*\n)*", "", PAPER_TEXT)
    text = text.replace(PAPER_EMITTER, f"emitter = {list(emitter)}")
    path = folder / "moved.toml"
    path.write_text(with_lines(text, "sensor", *extra))
    return path


def warning_of(result):
    found = [w for w in result.warnings if w.startswith("the beam misses")]
    assert len(found) <= 1
    return found[0] if found else None


def test_the_paper_has_no_such_warning():
    from scenarios import PAPER

    result = scan_layout(read_scenario(PAPER))
    assert result.code == PAPER_CODE and warning_of(result) is None


@pytest.mark.parametrize("y, miss", [(240.0, 10.0), (245.0, 5.0), (100.0, 150.0)])
def test_a_beam_in_front_of_the_wafers_is_said_with_its_distance(tmp_path, y, miss):
    # The wafers' centres are at y = 400, their radius 150: a beam along X at y misses each
    # level wafer by 400 - 150 - y.
    result = scan_layout(read_scenario(moved(tmp_path, [-80.0, y, 280.0])))
    assert result.code == "0" * 25 and result.runs == ()
    assert warning_of(result) == (
        f"the beam misses 10 of the 10 wafers at every height (LP1_W01, LP1_W02, LP1_W03 and 7 "
        f"more), passing {miss:.3f} mm beside them: their slots read empty; check where the "
        "scanner's emitter and receiver are")


def test_a_beam_that_stops_short_is_measured_from_its_end(tmp_path):
    # The beam from x = 200 to 360 at y = 266.6: its nearest point to the centres (0, 400) is
    # its emitter; the level wafers are missed by |(200, 133.4)| - 150 (the two tilted ones by
    # a little more, the nearest).
    result = scan_layout(read_scenario(moved(tmp_path, [200.0, 266.6, 280.0])))
    miss = (200.0 ** 2 + 133.4 ** 2) ** 0.5 - 150.0
    low, high = re.search(r"passing ([0-9.]+) to ([0-9.]+) mm beside them",
                          warning_of(result)).groups()
    assert float(low) == pytest.approx(miss, abs=5e-4) and miss < float(high) < miss + 0.1


@pytest.mark.parametrize("y", [240.0, 249.0])
def test_the_distance_is_where_the_beam_starts_to_meet_each_wafer(tmp_path, y):
    layout = read_scenario(moved(tmp_path, [-80.0, y, 280.0]))
    result = scan_layout(layout)
    shown = float(re.search(r"passing ([0-9.]+) mm", warning_of(result)).group(1))
    # Every wafer, the two cross-slotted (tilted) ones included: moved by the distance less
    # 1 µm the beam still misses it, by the distance plus 1 µm it meets it.
    from waferscan.core.scan.scan_result import beam_miss

    for wafer in layout.wafers:
        distance = beam_miss(layout.beam, layout.lift_axis, wafer)
        assert distance == pytest.approx(shown, abs=5e-4)
        for step, meets in ((distance - 1e-3, False), (distance + 1e-3, True)):
            emitter = (layout.beam.emitter[0], layout.beam.emitter[1] + step,
                       layout.beam.emitter[2])
            beam = Beam(emitter, layout.beam.direction, layout.beam.length)
            assert (translation_range(emitter, beam, layout.lift_axis, wafer) is not None) \
                == meets, (wafer.name, step)


def test_some_wafers_missed_are_counted_and_the_others_scanned(tmp_path):
    layout = read_scenario(moved(tmp_path, [-80.0, 266.6, 280.0]))
    assert warning_of(scan_layout(layout)) is None
    # One wafer pushed back 20 mm (y + 20): the beam passes 3.4 mm in front of it.
    wafers = list(layout.wafers)
    w = wafers[0]
    wafers[0] = replace(w, center=(w.center[0], w.center[1] + 20.0, w.center[2]))
    result = scan_layout(replace(layout, wafers=tuple(wafers)))
    assert warning_of(result) == (
        "the beam misses 1 of the 10 wafers at every height (LP1_W01), passing 3.400 mm beside "
        "it: their slots read empty; check where the scanner's emitter and receiver are")
    assert result.code[0] == "0" and result.code[1:] == PAPER_CODE[1:]


def test_a_beam_spot_scan_warns_too(tmp_path):
    path = moved(tmp_path, [-80.0, 240.0, 280.0], ["spot_diameter = 1.0"])
    result = scan_layout(read_scenario(path))
    assert result.layout.spot is not None
    assert "passing 10.000 mm beside them" in warning_of(result)


def test_every_channel_says_it(tmp_path):
    path = moved(tmp_path, [-80.0, 240.0, 280.0])
    result = scan_layout(read_scenario(path))
    warning = warning_of(result)
    done = run("scan", path)
    assert done.returncode == 0
    assert f"waferscan: warning: {warning}\n" in done.stderr
    done = run("scan", path, "--json")
    assert warning in json.loads(done.stdout)["warnings"]
    assert f"warning = {warning}\n" in format_results(1, "SCF", result=result)
