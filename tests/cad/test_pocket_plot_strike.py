"""``scan --plot`` of a slow scan (SPEC §13): each panel marks where the sweep turned a tine into
the wafer, on the tine's circle about the wrist (resources/examples/slow_jab.toml)."""

import math

import pytest
from figures import pocket_panels
from scenarios import slow_jab_deep

from waferscan.core.scan.layout_scan import scan_layout

RESULT = scan_layout(slow_jab_deep())  # the paper's depth, the whole ±40° (scenarios.py)
WRIST = (0.0, 240.0 + 26.6 - 400.0 - 260.0)  # 260 mm behind the deepest beam, from above


def test_the_panels_mark_each_tines_path_inside_the_wafer():
    from waferscan.plots.pockets import STRIKE

    with pocket_panels(RESULT) as (axes, drawn):
        slot8 = axes[1]  # the wafer pushed 5 mm out: centre (0, -5)
        arcs = [(list(l.get_xdata()), list(l.get_ydata())) for l in slot8.get_lines()
                if l.get_color() == STRIKE]
        assert len(arcs) == 2
        for us, vs in arcs:
            points = list(zip(us, vs))
            assert all(math.dist(p, WRIST) == pytest.approx(math.hypot(80.0, 260.0), abs=1e-9)
                       for p in points)
            assert all(math.dist(p, (0.0, -5.0)) <= 150.0 + 1e-6 for p in points)
        # The emitter's tine (left) swings right across the front, the receiver's left.
        assert arcs[0][0][0] > 0.0 > arcs[0][0][-1] and arcs[1][0][0] > 0.0 > arcs[1][0][-1]
    assert (8, "strike", "emitter tine in the wafer -33.845° to -0.360°") in drawn
    assert (8, "strike", "receiver tine in the wafer +0.360° to +33.845°") in drawn
