"""The scenarios the tests start from, written once: where the examples lie (the paper's above
all) and what the paper's scan reads, the paper's text with a line changed or added, a small
one-carrier scenario like the paper's and its free wafers, the tables of a tolerance file
(TOL.toml), and random beams beside random wafers."""

import math
import re
from dataclasses import replace
from pathlib import Path

__all__ = [
    "ROOT", "EXAMPLES", "PAPER", "PAPER_TEXT", "PAPER_CODE", "PAPER_E87",
    "PAPER_WITHOUT_ROBOT", "SLOW_JAB",
    "SLOW_JAB_TEXT", "SLOW_JAB_WITHOUT_ROBOT", "paper_with", "drifted_paper", "with_lines",
    "one_carrier", "free_wafer", "uniform", "normal", "SWEEP_TOLERANCES", "beams_and_wafers",
    "fab_with",
]

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "resources" / "examples"

# --- The paper's experiment (resources/examples/paper.toml) -----------------------------------

PAPER = EXAMPLES / "paper.toml"
PAPER_TEXT = PAPER.read_text(encoding="utf-8")
# The paper with a second carrier, LP2, above the paper's scan: a layout of several carriers
# (parameters.txt's carrier = NAME, the host link's ports).
TWO_CARRIERS_TEXT = PAPER_TEXT + """
[[carrier]]
name = "LP2"
slots = 13
pitch = 20.0
first_slot_z = 600.0
center = [0.0, 400.0]
wafer_diameter = 300.0
wafer_thickness = 0.775
"""
PAPER_CODE = "1101221001220001010000010"  # the paper's Table 1, one digit a slot
PAPER_E87 = "3313553113551113131111131"   # the same map in SEMI E87's digits

# --- The slow scan with a jab and a sweep (resources/examples/slow_jab.toml) -----------------

SLOW_JAB = EXAMPLES / "slow_jab.toml"
SLOW_JAB_TEXT = SLOW_JAB.read_text(encoding="utf-8")
# Without its [robot]: a robot refuses a beam that is not horizontal before the scanner's own
# checks are reached; the scanner alone is moved by its placement (SPEC §13).
SLOW_JAB_WITHOUT_ROBOT = re.sub(r"\[robot\]\n(?:[^\[\n].*\n)*", "", SLOW_JAB_TEXT)
# The example at the paper's depth (a 26.6 mm jab: the beam 16.6 mm into the wafers, the tines'
# inner corners 0.650 mm from the rims), as the example was before its sweep stopped at
# clearance_min (SPEC §13 amended): the core's closed forms alone (``scan_layout``, no robot
# body) still turn its whole ±40° there, where the hand computations of the pocket plots and
# the tines' strikes are made.
SLOW_JAB_DEEP_TEXT = SLOW_JAB_TEXT.replace("jab = 20.0 ", "jab = 26.6 ", 1)
assert SLOW_JAB_DEEP_TEXT != SLOW_JAB_TEXT


def slow_jab_deep():
    """SLOW_JAB_DEEP_TEXT read as a Layout."""
    from waferscan.core.files.scenario import parse_scenario

    return parse_scenario(SLOW_JAB_DEEP_TEXT, "slow_jab_deep.toml", folder=EXAMPLES)


# The paper's scanner alone, moved by its placement, the same way.
PAPER_WITHOUT_ROBOT = re.sub(r"\[robot\]\n(?:[^\[\n].*\n)*", "", PAPER_TEXT)


def paper_with(folder, old, new, name="s.toml"):
    """The paper's scenario with the first ``old`` replaced by ``new``, written to
    ``folder/name``; its path."""
    assert old in PAPER_TEXT, old  # a change that changes nothing would test nothing
    path = Path(folder) / name
    path.write_text(PAPER_TEXT.replace(old, new, 1))
    return path


def drifted_paper(load, offset=0.3, pitch=10.02, z_step=0.05):
    """The paper's scenario text with its carrier built ``offset`` mm above the taught slot-1
    seat (293.94 mm) at a real ``pitch`` (taught 10.0 mm), loaded with ``load``: what
    calibration finds."""
    return (PAPER_TEXT.replace("first_slot_z = 293.94", f"first_slot_z = {293.94 + offset!r}")
            .replace("pitch = 10.0\n", f"pitch = {pitch!r}\n")
            .replace(f'load = "{PAPER_CODE}"', f'load = "{load}"')
            .replace("z_step = 0.05", f"z_step = {z_step!r}"))


def with_lines(text, table, *lines):
    """``text`` with ``lines`` added at the top of its first ``[table]``."""
    return text.replace(f"[{table}]\n", f"[{table}]\n" + "".join(f"{x}\n" for x in lines), 1)


# --- A small scenario like the paper's ---------------------------------------------------------

def one_carrier(load, *, slots=None, start=90.0, final=200.0, step=0.05, first_slot_z=100.0,
                pitch=10.0, thickness=0.7, name="A", scan="", mapping="", extra=""):
    """The text of a scenario of one carrier of 300 mm wafers at (0, 400) loaded as ``load``
    (a digit a slot; ``slots`` defaults to its length), the beam along X 16.6 mm inside the
    wafers' rim as in the paper, scanned from ``start`` to ``final``. ``scan`` adds lines to
    [scan], ``mapping`` a [mapping] table's lines, ``extra`` text at the end ([[wafer]]s);
    ``name=None`` leaves the carrier unnamed."""
    mapping_table = f"[mapping]\n{mapping}" if mapping else ""
    name_line = f'name = "{name}"\n' if name is not None else ""
    return f"""
[scan]
start_z = {start!r}
final_z = {final!r}
z_step = {step!r}
{scan}[sensor]
emitter = [-80.0, 266.6, {start!r}]
direction = [1.0, 0.0, 0.0]
length = 160.0
{mapping_table}[[carrier]]
{name_line}slots = {len(load) if slots is None else slots}
pitch = {pitch!r}
first_slot_z = {first_slot_z!r}
center = [0.0, 400.0]
wafer_diameter = 300.0
wafer_thickness = {thickness!r}
load = "{load}"
{extra}"""


def free_wafer(name, y, z, thickness=0.7):
    """A [[wafer]] table: a level 300 mm wafer of no carrier, its centre at (0, ``y``, ``z``)."""
    return f"""
[[wafer]]
name = "{name}"
center = [0.0, {y!r}, {z!r}]
normal = [0.0, 0.0, 1.0]
diameter = 300.0
thickness = {thickness!r}
"""


# --- Tolerance files (TOL.toml, SPEC §12) -----------------------------------------------------

def uniform(quantity, lo, hi):
    """A TOL.toml table: ``quantity`` drawn uniformly from [lo, hi]."""
    return f'[{quantity}]\ndist = "uniform"\nlo = {lo!r}\nhi = {hi!r}\n'


def normal(quantity, mean, sigma):
    """A TOL.toml table: ``quantity`` drawn from a normal distribution."""
    return f'[{quantity}]\ndist = "normal"\nmean = {mean!r}\nsigma = {sigma!r}\n'


# Every quantity and every state at once, wide enough that each one matters somewhere.
SWEEP_TOLERANCES = ("\n" + uniform("seat_offset", -0.7, 0.7) + normal("thickness", 0.7, 0.08)
                    + uniform("tilt", 0.0, 0.4) + uniform("protrusion", 0.0, 1.6)
                    + normal("beam_z", 0.0, 0.3) + uniform("beam_tilt", -0.3, 0.3)
                    + uniform("sensor_response", 0.0, 0.003)
                    + "[states]\npresent = 0.55\nempty = 0.15\ncross = 0.08\ndouble = 0.08\n"
                      "thin = 0.06\nposition_error = 0.04\nprotruding = 0.04\n")



# --- Beams and wafers -----------------------------------------------------------------------

def beams_and_wafers(rng, count, lengths=(400.0, 250.0, 120.0), bowed=False):
    """(emitter, beam, wafer) triples of every kind a translation range meets in a sweep, from a
    numpy ``rng``: kind 0 a level beam over a level wafer (the closed form), 1 a tilted beam over
    a level wafer (the rim as two lines), 2 and 3 tilted wafers (the rim a conic); beams of
    ``lengths`` (some ending inside a wafer); ``bowed`` gives every third wafer a bow."""
    from waferscan.core.model import Beam, Wafer

    def unit(v):
        n = math.sqrt(sum(x * x for x in v))
        return tuple(x / n for x in v)

    cases = []
    for i in range(count):
        kind = i % 4
        tilt = 0.0 if kind in (0, 1) else rng.uniform(-0.05, 0.05)
        normal = unit((tilt, rng.uniform(-0.05, 0.05) if kind == 3 else 0.0, 1.0))
        beam_tilt = 0.0 if kind == 0 else rng.uniform(-0.01, 0.01)
        direction = unit((1.0, rng.uniform(-0.2, 0.2), beam_tilt))
        length = rng.choice(lengths)
        emitter = (rng.uniform(-210.0, -150.0), rng.uniform(-160.0, 160.0),
                   rng.uniform(295.0, 305.0))
        wafer = Wafer("W", (rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), 300.0), normal,
                      300.0, rng.uniform(0.1, 1.5))
        if bowed and i % 3 == 0:
            wafer = replace(wafer, bow=rng.uniform(-0.3, 0.3))
        cases.append((emitter, Beam(emitter, direction, length), wafer))
    return cases


def fab_with(states=None, foups=4, **scan):
    """The bench's fab (``foups`` FOUPs at 0.001 mm unless ``scan`` says otherwise), LP1 loaded
    slot by slot with ``states`` (scenario states; None: as the bench loads it)."""
    from waferscan.bench.workloads import fab_layout, paper_layout
    from waferscan.core.files.scenario import seated_wafers

    fab = fab_layout(paper_layout(PAPER), foups=foups)
    if states is not None:
        lp1 = fab.carriers[0]
        wafers, n = [], 1
        for slot, state in enumerate(states, start=1):
            made = seated_wafers(lp1, slot, state, n)
            wafers += made
            n += len(made)
        fab = replace(fab, wafers=tuple(wafers) + tuple(w for w in fab.wafers
                                                         if w.carrier != "LP1"))
    return fab.with_scan(**scan) if scan else fab
