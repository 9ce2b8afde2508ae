"""``waferscan scan … --plot FILE.png`` of a slow scan with a jab or a sweep (SPEC §13): the
chosen pockets seen from above under the signal plot, in the venv and inside FreeCAD; the beams
drawn where the hand computation puts them on resources/examples/slow_jab.toml."""

import pytest
from commands import cli_in_freecad, freecadcmd, waferscan
from figures import pocket_panels, png_size
from scenarios import SLOW_JAB, slow_jab_deep

from waferscan.cli import paper_scenario
from waferscan.core.scan.layout_scan import scan_layout

RESULT = scan_layout(slow_jab_deep())  # the paper's depth, the whole ±40° (scenarios.py)


def test_the_panels_draw_the_beams_where_they_met_the_wafer():
    from waferscan.plots.pockets import BEAM_STYLES

    with pocket_panels(RESULT) as (axes, drawn):
        assert [a.get_title().split("\n")[0] for a in axes] == [
            "slot 3 at Z 314.290 mm", "slot 8 at Z 364.290 mm", "slot 1 at Z 294.290 mm",
            "slot 2 at Z 304.290 mm"]
        slot8 = axes[1]
        red = BEAM_STYLES["front"][0]
        lines = [(list(l.get_xdata()), list(l.get_ydata())) for l in slot8.get_lines()
                 if l.get_color() == red]
        # The front: the beam 5 mm in from the start pose (v = 240 - 400 + 5), and its dot at the
        # rim's front point of the wafer pushed 5 mm out (v = -5 - 150).
        assert lines[0][0] == pytest.approx([-80.0, 80.0])
        assert lines[0][1] == pytest.approx([-155.0, -155.0], abs=1e-6)
        assert lines[1][0] == pytest.approx([0.0]) and lines[1][1] == pytest.approx([-155.0])
        circles = [(p.center, p.radius) for p in slot8.patches]
        assert circles[0][0] == pytest.approx((0.0, 0.0)) and circles[0][1] == 150.0  # seated
        assert circles[1][0] == pytest.approx((0.0, -5.0))                           # the wafer
    assert (8, "contact", "front 5.000 mm") in drawn
    assert (3, "contact", "-33.022°") in drawn and (3, "wafer", "shifted") in drawn


def test_the_command_line_adds_the_panels_to_a_slow_scans_plot(tmp_path):
    for scenario, name in ((SLOW_JAB, "slow.png"), (paper_scenario(), "fast.png")):
        done = waferscan("scan", scenario, "--plot", tmp_path / name)
        assert done.returncode == 0, done.stderr
    # 110 dpi: 11 x 6.5 in without pockets, 3.8 in taller with their row.
    assert png_size(tmp_path / "fast.png") == (1210, 715)
    assert png_size(tmp_path / "slow.png") == (1210, 1133)


def test_the_panels_inside_freecad(tmp_path):
    # Debian's matplotlib inside FreeCAD draws them too.
    target = tmp_path / "fc.png"
    done = freecadcmd(cli_in_freecad("scan", SLOW_JAB, "--plot", target))
    assert png_size(target) == (1210, 1133), done.stdout + done.stderr
