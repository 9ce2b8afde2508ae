"""Many obstacles (a stocker's stack of FOUPs): the nearest pair is looked for among the
obstacles within NEAR_BAND mm of the parts along Z first (robot/clearance.py), which made a
10,000-wafer scan's clearance linear instead of quadratic in the wafers (254 s). The same
reports, to the last bit, as weighing every obstacle at every pose."""

import json

import pytest

from waferscan.bench.workloads import stack_scenario
from waferscan.core.files.scenario import parse_scenario
from waferscan.core.scan import clearance as core
from waferscan.core.scan.clearance import closest_dict
from waferscan.robot import clearance
from waferscan.robot.clearance import clearance_for


def _report(layout, carrier):
    report = clearance_for(layout, carrier=carrier)
    return json.dumps([closest_dict(c) for c in report.closest], sort_keys=True)


@pytest.mark.parametrize("foups, with_carrier", [(10, False), (10, True), (2, False)])
def test_the_band_gives_every_obstacles_answer(monkeypatch, foups, with_carrier):
    """A stack of FOUPs scanned by the scanner's heads: with the FOUPs' solids the heads run
    through every roof (contacts, so the motion is searched pose by pose, thousands of poses);
    without them the stroke's swept answer is exact at once."""
    from waferscan.robot.scenario_scan import carrier_solids

    layout = parse_scenario(stack_scenario(foups), "stack.toml")
    carrier = carrier_solids(layout) if with_carrier else ()
    calls = []
    among = clearance._Body._nearest_among
    monkeypatch.setattr(clearance._Body, "_nearest_among",
                        lambda self, *a: calls.append(a[3] is not None) or among(self, *a))
    monkeypatch.setattr(core, "SPAN", 10 ** 9)  # every pose of the stroke (no clear spans)
    banded = _report(layout, carrier)
    obstacles = len(clearance.body_for(layout, carrier).obstacles.items)
    assert any(calls) == (obstacles > clearance.NEAR_BAND_FROM)
    if with_carrier:
        assert len(calls) > 1000 and '"distance": -' in banded  # through the roofs
    monkeypatch.setattr(clearance, "NEAR_BAND_FROM", 10 ** 9)  # every obstacle, every pose
    assert _report(layout, carrier) == banded


def test_an_obstacle_outside_the_band_is_still_found():
    """Nothing within the band nearer than NEAR_BAND: every obstacle is weighed (a lone wafer
    200 mm above the parts is the nearest, as it is without the band)."""
    from dataclasses import replace

    from waferscan.core.model import Wafer

    layout = parse_scenario(stack_scenario(10), "stack.toml")
    far = [Wafer(f"FAR{i:03d}", (0.0, 3000.0 + 400.0 * i, 5000.0), (0.0, 0.0, 1.0), 300.0, 0.7)
           for i in range(250)]
    layout = replace(layout, wafers=tuple(far), robot=None)
    body = clearance.body_for(layout)
    motion = next(iter(clearance_for(layout).closest)).motion
    banded = body.nearest(motion, motion.start)
    clearance.NEAR_BAND_FROM, saved = 10 ** 9, clearance.NEAR_BAND_FROM
    try:
        assert body.nearest(motion, motion.start) == banded
    finally:
        clearance.NEAR_BAND_FROM = saved
    assert banded[0] > clearance.NEAR_BAND and banded[2].startswith("FAR")


def _counted(monkeypatch):
    calls = []
    nearest = clearance._Body.nearest
    monkeypatch.setattr(clearance._Body, "nearest",
                        lambda self, *a: calls.append(a[1]) or nearest(self, *a))
    return calls


def test_clear_spans_of_a_stack_give_every_poses_answer(monkeypatch):
    """The heads through the roofs of 10 FOUPs' solids (a contact, so the stroke is searched):
    the spans they sweep clear of everything are not sampled pose by pose (core/scan/
    clearance.py ``_clear_spans``), and the report is the same to the last bit."""
    from waferscan.robot.scenario_scan import carrier_solids

    layout = parse_scenario(stack_scenario(10), "stack.toml")
    carrier = carrier_solids(layout)
    calls = _counted(monkeypatch)
    spanned = _report(layout, carrier)
    asked = len(calls)
    calls.clear()
    monkeypatch.setattr(core, "SPAN", 10 ** 9)
    assert _report(layout, carrier) == spanned and '"distance": -' in spanned
    assert len(calls) > 2000 and asked < len(calls) / 4


def test_clear_spans_of_the_robots_fork_give_every_poses_answer(monkeypatch):
    """The paper's robot lifted to 1,500 mm past a wafer pulled 8 mm out of its slot into the
    fork's path: the same report as every pose, from a fraction of the poses."""
    from dataclasses import replace

    from waferscan.core.files.scenario import read_scenario
    from scenarios import PAPER

    layout = read_scenario(PAPER)
    wafers = list(layout.wafers)
    x, y, z = wafers[3].center
    wafers[3] = replace(wafers[3], center=(x, y - 8.0, z))
    layout = replace(layout, wafers=tuple(wafers), scan=replace(layout.scan, final_z=1500.0))
    calls = _counted(monkeypatch)
    spanned = _report(layout, ())
    asked = len(calls)
    calls.clear()
    monkeypatch.setattr(core, "SPAN", 10 ** 9)
    assert _report(layout, ()) == spanned
    assert '"distance": -2.4486' in spanned and '"obstacle": "LP1_W04"' in spanned
    assert len(calls) > 1200 and asked < len(calls) / 3


def test_the_wafers_solids_made_once_name_the_slots_of_the_carrier_scanned():
    """The coal solids of a layout's wafers are made once for the same wafers
    (``_wafer_items``), but the slots they name are the scanned carrier's: the same wafers
    scanned as another carrier (an MCS ``carrier =`` parameter) report that carrier's slots, as
    a body made afresh does (a second reader's case: S2's wafers had no slot)."""
    from dataclasses import replace

    layout = parse_scenario(stack_scenario(2), "stack.toml")
    other = replace(layout, carrier="S2")
    assert other.wafers is layout.wafers
    _report(layout, ())  # S1 scanned first: its wafers' solids made
    after = _report(other, ())
    clearance._WAFERS_MADE.clear()
    assert _report(other, ()) == after
    assert '"obstacle": "S2_' in after and '"slot": null' not in after
