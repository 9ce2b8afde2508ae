"""A slow scan's settings met by a fast scan (SPEC §13): the engineer's trade-off, the simulated
durations of a fast and a slow scan, shown side by side whichever mode ran; and a word that
the jab and sweep were not made."""

import pytest
from scenarios import SLOW_JAB_WITHOUT_ROBOT as NO_ROBOT

from waferscan.core.files.scenario import parse_scenario


def test_a_fast_scan_with_a_jab_says_it_made_none_and_what_a_slow_one_would_take():
    from dataclasses import replace

    from waferscan.core.scan.layout_scan import scan_layout

    slow = parse_scenario(NO_ROBOT, "s.toml")
    fast = replace(slow, scan=replace(slow.scan, mode="fast"))
    slow_result, fast_result = scan_layout(slow), scan_layout(fast)
    assert fast_result.pockets == ()
    # The trade-off shown side by side: the same slow duration from either scan's result.
    assert fast_result.durations == slow_result.durations
    assert slow_result.durations["slow"] > 80.0 > 2.7 == pytest.approx(
        fast_result.durations["fast"])
    notices = [w for w in fast_result.warnings if "only a slow scan" in w]
    assert notices == ["a jab and a sweep are set but only a slow scan (mode = slow) makes "
                       "them: this fast scan's beam stayed at the start pose, and the slow "
                       "duration is what a slow scan with them would take at most (its "
                       "sweeps turned all the way: a sweep stops short where the fork would "
                       "come within clearance_min)"]
    assert not [w for w in slow_result.warnings if "only a slow scan" in w]
    only_jab = scan_layout(replace(fast, scan=replace(fast.scan, sweep=0.0)))
    assert any(w.startswith("a jab is set but only") for w in only_jab.warnings)


def test_without_a_lift_acceleration_the_durations_say_why_slow_can_be_shorter():
    """Issue 27 item 15: the paper's layout printed "fast 2.70 s, slow 2.59 s", a slow scan
    faster than a fast one, with no word why: its lift's acceleration is not set (SPEC §10's
    default, infinite), so a slow scan's stops from rest to rest cost nothing and it ends at
    the top slot's window, short of final_z. The line says so; with an acceleration set the
    stops cost their time and the note is gone."""
    from waferscan.core.files.report import format_durations
    from waferscan.core.scan.layout_scan import scan_layout
    from waferscan.core.scan.slow_scan import move_time
    from scenarios import PAPER_TEXT

    paper = scan_layout(parse_scenario(PAPER_TEXT, "paper.toml"))
    assert paper.durations["slow"] < paper.durations["fast"]
    assert format_durations(paper) == (
        "simulated duration: fast 2.70 s, slow 2.59 s (this scan: fast; lift acceleration not "
        "set ([scan] acceleration): the slow scan's stops take no time)")
    text = PAPER_TEXT.replace("[scan]\n", "[scan]\nacceleration = 2000.0\n", 1)
    accelerated = scan_layout(parse_scenario(text, "paper.toml"))
    fast, slow = accelerated.durations["fast"], accelerated.durations["slow"]
    # One stroke of 270 mm at 100 mm/s with 2,000 mm/s²: 2.7 s and v/a = 0.05 s more.
    assert fast == pytest.approx(270.0 / 100.0 + 100.0 / 2000.0) == move_time(270.0, 100.0, 2000.0)
    # A 0.05 mm step from rest to rest never reaches full speed: 2 sqrt(d/a) = 0.01 s each.
    assert move_time(0.05, 100.0, 2000.0) == pytest.approx(0.01)
    assert slow > 10 * fast
    assert format_durations(accelerated) == (
        f"simulated duration: fast {fast:.2f} s, slow {slow:.2f} s (this scan: fast)")
