"""SPEC §13 amended through the document and the command line: slow_jab.toml's sweep stops where
the fork comes within clearance_min, the angles reached are in JSON, results.txt and the table,
its sweep never comes closer, and a sweep that cannot turn at all is bad input naming the file,
the line and the pocket (hand geometry: tests/robot/test_sweep_reach.py)."""

import json
import math

import pytest
from commands import waferscan
from scenarios import SLOW_JAB, SLOW_JAB_TEXT


def _limit(gap, depth):
    """Hand: the turn at which a tine's inner tip corner comes within ``gap`` of a seated
    wafer's rim (tests/robot/test_sweep_reach.py)."""
    def corner(phi):
        p = math.radians(phi)
        x = 70.0 * math.cos(p) - 260.0 * math.sin(p)
        y = depth - 20.0 + 70.0 * math.sin(p) + 260.0 * math.cos(p)
        return math.hypot(x, y - 400.0) - 150.0

    lo, hi = 0.0, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if corner(mid) > gap else (lo, mid)
    return lo


def test_slow_jab_sweeps_only_as_far_as_the_fork_stays_clear(tmp_path):
    out = tmp_path / "results.txt"
    done = waferscan("scan", SLOW_JAB, "--json", "--out", out)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    limit = _limit(1.0, 20.0)  # clearance_min's default, 1 mm
    slots = {s["slot"]: s for s in data["slots"]}
    for slot in (1, 2, 4, 7, 10, 16, 18, 24):  # seated wafers
        low, high = slots[slot]["sweep_reached"]
        assert -limit - 1e-3 < low < -limit + 1e-3 and limit - 1e-3 < high <= limit
        assert slots[slot]["sweep"] == pytest.approx([low, high], abs=1e-6)  # blocked throughout
        assert slots[slot]["sweep_strike"] is None
    low, high = slots[3]["sweep_reached"]  # the wafer 3 mm to the right
    assert high < limit - 0.2 and -low > limit + 0.2
    assert slots[9]["sweep_reached"] == [-40.0, 40.0] and slots[9]["sweep"] is None  # empty
    clearance = data["clearance"]
    assert clearance["contacts"] == 0 and clearance["least"] >= 1.0
    sweeps = [m for m in clearance["motions"] if m["motion"] == "sweep"]
    assert len(sweeps) == 25 and all(m["distance"] >= 1.0 for m in sweeps)
    assert "strike" not in done.stderr and "a real fork would strike" not in done.stdout
    assert "slots 1, 2, 4, 7, 10, 16, 18, 24: the sweep stopped where the fork comes within " \
           "clearance_min (1 mm)" in done.stderr
    # results.txt: the angles reached per pocket, after the sweep's first and last.
    lines = out.read_text().splitlines()
    header = next(line for line in lines if line.startswith("slot\t"))
    columns = header.split("\t")
    assert columns[-5:] == ["front", "sweep_first", "sweep_last", "sweep_low", "sweep_high"]
    row = next(line.split("\t") for line in lines if line.startswith("1\t"))
    assert float(row[-2]) == pytest.approx(slots[1]["sweep_reached"][0], abs=1e-4)
    assert float(row[-1]) == pytest.approx(slots[1]["sweep_reached"][1], abs=1e-4)
    assert "status = ok" in lines


def test_a_sweep_that_cannot_turn_is_bad_input_naming_the_line_and_the_pocket(tmp_path):
    # At the paper's 26.6 mm the corners are 0.650 mm from every seated rim: under the default
    # clearance_min (1 mm) the first wafer's pocket, slot 1, cannot turn.
    scenario = tmp_path / "deep.toml"
    scenario.write_text(SLOW_JAB_TEXT.replace("jab = 20.0 ", "jab = 26.6 ", 1))
    line = next(i for i, text in enumerate(scenario.read_text().splitlines(), 1)
                if text.startswith("sweep = "))
    done = waferscan("scan", scenario)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    touch = _limit(0.0, 26.6)
    message = done.stderr.strip()
    assert message.startswith(f"waferscan: error: {scenario}:{line}: sweep: cannot turn at slot "
                              f"1: before it turns, tine_")
    assert "is 0.650 mm from LP1_W01, under clearance_min 1 mm; turning, the fork would touch " \
           "at -0.20" in message
    angles = [float(a) for a in message.split("touch at ")[1].replace(" deg", "").split(" or ")]
    assert angles == pytest.approx([-touch, touch], abs=2e-3)
    # A sweep set by parameters.txt is named by its line there.
    params = tmp_path / "parameters.txt"
    params.write_text("jab = 26.6\nsweep = 30\n")
    done = waferscan("scan", SLOW_JAB, "--params", params)
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {params}:2: sweep: cannot turn at slot 1")
    # Held to 0.5 mm (the corner 0.650 mm away) it turns a little, and runs.
    params.write_text("jab = 26.6\nclearance_min = 0.5\n")
    shifted_away = SLOW_JAB_TEXT.replace("jab = 20.0 ", "jab = 26.6 ", 1)
    scenario.write_text(shifted_away.replace('[[wafer]]\nname = "shifted"\ncenter = [3.0, 400.0, '
                                             '313.94]\n', "").replace(
        'load = "1101221601220001010000010"', 'load = "1101221001220001010000010"'))
    done = waferscan("scan", scenario, "--params", params, "--json")
    assert done.returncode == 0, done.stderr
    reached = json.loads(done.stdout)["slots"][0]["sweep_reached"]
    assert reached[1] == pytest.approx(_limit(0.5, 26.6), abs=1e-3) and reached[1] < 0.1
