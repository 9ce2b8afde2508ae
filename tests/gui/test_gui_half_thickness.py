"""Issue 27 item 13 in the preferences: the thickness tolerance's "half the nominal wafer
thickness" is a box stored as its own parameter (HalfThickness), not a -1 in the length; the
length is kept while the box is ticked, and what earlier versions stored (ThicknessTolerance
alone, negative for half the thickness) reads as it did. Real FreeCAD GUI, the page's own
widgets (half_thickness_probe.py)."""

from pathlib import Path

import pytest

PROBE = Path(__file__).resolve().with_name("half_thickness_probe.py")


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    return run_gui_probe(PROBE)


def test_nothing_stored_is_half_the_thickness(gui):
    # [box ticked, length field enabled, length shown (mm), the scans' tolerance]
    assert gui["nothing"] == [True, False, 0.35, None]


def test_what_an_earlier_version_stored_reads_as_it_did(gui):
    assert gui["old_half"] == [True, False, 0.35, None]
    assert gui["old_half_untouched"] == [None, -1.0]  # OK untouched: nothing written
    assert gui["old_length"] == [False, True, 0.3, 0.3]


def test_ticking_the_box_keeps_the_length(gui):
    assert gui["ticked_stored"] == [True, 0.3]
    assert gui["ticked"] == [True, False, 0.3, None]
    assert gui["unticked_stored"] == [False, 0.3]
    assert gui["unticked"] == [False, True, 0.3, 0.3]


def test_an_earlier_half_unticked_with_a_length_typed(gui):
    assert gui["from_old_stored"] == [False, pytest.approx(0.254)]
    assert gui["from_old"] == [False, True, pytest.approx(0.254), pytest.approx(0.254)]


def test_a_negative_length_is_refused_by_the_store(gui):
    assert gui["negative"].startswith("a thickness tolerance cannot be negative, got -1 mm")
