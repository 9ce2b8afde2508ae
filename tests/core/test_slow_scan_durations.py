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
                       "duration is what a slow scan with them would take"]
    assert not [w for w in slow_result.warnings if "only a slow scan" in w]
    only_jab = scan_layout(replace(fast, scan=replace(fast.scan, sweep=0.0)))
    assert any(w.startswith("a jab is set but only") for w in only_jab.warnings)
