"""Degenerate geometry: the engines still agree, and what makes no sense is refused."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from waferscan.core.errors import InputError
from waferscan.core.files.scenario import parse_scenario
from waferscan.core.model import Beam, Carrier, Layout, ScanParameters, Wafer, unit
from waferscan.core.scan.engines import analytic_engine, loop_engine, vector_engine
from waferscan.core.scan.layout_scan import scan_layout

CARRIER = Carrier("C", 3, 10.0, 100.0, (0.0, 0.0), 300.0, 0.7)


def layout(wafers, emitter=(-80.0, -133.4, 90.0), direction=(1.0, 0.0, 0.0), length=160.0,
           lift=(0.0, 0.0, 1.0), start=90.0, final=130.0, step=0.05):
    return Layout((CARRIER,), tuple(wafers), Beam(emitter, unit(direction), length),
                  ScanParameters(start, final, step), lift_axis=unit(lift))


def agree(lay):
    reference = loop_engine(lay)
    assert vector_engine(lay) == reference
    assert analytic_engine(lay) == reference
    return reference


def seated(z, name="W", thickness=0.7, normal=(0.0, 0.0, 1.0), xy=(0.0, 0.0)):
    return Wafer(name, (xy[0], xy[1], z), unit(normal), 300.0, thickness)


def test_beam_in_the_plane_of_the_faces_touches():
    # Seats on the grid: the beam lies exactly in the bottom face, then exactly in the top face.
    hits = agree(layout([seated(100.0, thickness=0.5)]))
    assert hits.wafer_steps == ((200, 210),)


def test_zero_length_beam_is_a_point():
    lay = layout([seated(100.0)], emitter=(0.0, 0.0, 90.0), length=0.0)
    assert agree(lay).wafer_steps == ((200, 214),)


def test_beam_starting_inside_a_wafer():
    lay = layout([seated(100.0)], emitter=(0.0, 0.0, 90.0), length=20.0)
    assert agree(lay).wafer_steps == ((200, 214),)


def test_vertical_beam_along_the_lift_axis():
    lay = layout([seated(100.0)], emitter=(0.0, -100.0, 70.0), direction=(0, 0, 1), length=20.0,
                 start=70.0, final=110.0)
    hits = agree(lay)
    # Blocked from when the beam's top end reaches the wafer until its bottom end leaves it.
    assert hits.wafer_steps == ((200, 614),)


def test_wafer_standing_on_edge_and_beam_along_its_axis():
    standing = Wafer("S", (0.0, -140.0, 110.0), (0.0, 1.0, 0.0), 20.0, 0.7)
    lay = layout([standing], emitter=(0.0, -150.0, 90.0), direction=(0, 1, 0), length=30.0)
    assert agree(lay).wafer_steps == ((200, 600),)


def test_overlapping_wafers_make_one_run():
    lay = layout([seated(100.0, "A"), seated(100.3, "B"), seated(100.0, "T", normal=(0.05, 0, 1))])
    hits = agree(lay)
    assert len(hits.runs) == 1
    result = scan_layout(lay)
    assert len(result.runs) == 1 and set(result.runs[0].wafers) == {"A", "B", "T"}


@settings(max_examples=300, deadline=None)
@given(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1),
       st.floats(-1, 1), st.floats(0.0, 1.0), st.sampled_from([0.0, 0.3, 160.0]),
       st.sampled_from([0.05, 0.25, 1.0]))
def test_engines_agree_on_arbitrary_directions(dx, dy, dz, nx, ny, nz, length, step):
    if math.hypot(dx, dy, dz) < 1e-3 or math.hypot(nx, ny, nz) < 1e-3:
        return
    wafer = Wafer("W", (0.0, 0.0, 110.0), unit((nx, ny, nz)), 300.0, 0.7)
    agree(layout([wafer], emitter=(-20.0, -100.0, 90.0), direction=(dx, dy, dz), length=length,
                 step=step))


SENSOR = """
[scan]
final_z = 130.0
[sensor]
emitter = [-80.0, -133.4, 90.0]
direction = {direction}
length = {length}
[[carrier]]
first_slot_z = 100.0
center = [0.0, 0.0]
slots = 3
"""


@pytest.mark.parametrize("direction, length, message", [
    ("[0.0, 0.0, 0.0]", "160.0", "direction: must not be the zero vector"),
    ("[1.0, 0.0, 0.0]", "0.0", "length: must be greater than 0"),
    ("[1.0, 0.0, 0.0]", "nan", "length: expected a finite number"),
    ("[1.0, 0.0, 0.0]", "inf", "length: expected a finite number"),
    ("[1.0, nan, 0.0]", "160.0", "direction: expected a finite number"),
    ("[1.0, 0.0, 0.0]", "-5", "length: must be greater than 0"),
])
def test_nonsense_beams_are_refused(direction, length, message):
    with pytest.raises(InputError, match=message):
        parse_scenario(SENSOR.format(direction=direction, length=length))


def test_model_refuses_a_zero_direction():
    with pytest.raises(ValueError, match="non-zero"):
        unit((0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="finite"):
        unit((float("nan"), 0.0, 1.0))
