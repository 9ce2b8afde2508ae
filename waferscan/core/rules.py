"""Rules every reader of a layout applies, each written once.

A scenario file, a parameters.txt and a FreeCAD document each say what is wrong in their own
words (a TOML key and line, a parameter's line, an object's property); the rule itself — when a
value is wrong — lives here, so changing it changes every reader.
"""

from __future__ import annotations

from .errors import EngineError

# The engine that gives exact edges (z_step = 0); the stepped engines need a step.
EXACT_EDGES_ENGINE = "analytic"
EXACT_EDGES_ONLY = "z_step = 0 (exact edges) is only offered by the analytic engine"

# How a FreeCAD property or a preference stores "half the wafer's thickness" (SPEC §4): a
# float cannot hold None, so any negative value means it.
HALF_THICKNESS_STORED = -1.0

# What is wrong with the choice of the carrier to scan (``carrier_choice_problem``).
SEVERAL_CARRIERS = "several"
UNKNOWN_CARRIER = "unknown"


def thickness_fits_pitch(thickness, pitch):
    """Whether a wafer of ``thickness`` (mm) fits a slot ``pitch`` (mm) apart: strictly less.

    >>> thickness_fits_pitch(0.775, 10.0), thickness_fits_pitch(10.0, 10.0)
    (True, False)
    """
    return thickness < pitch


def carrier_choice_problem(names, chosen):
    """What is wrong with scanning the carrier named ``chosen`` (None: not said) among the
    carriers ``names``: None when the choice is clear, ``SEVERAL_CARRIERS`` when it is not said
    and there are several, ``UNKNOWN_CARRIER`` when no carrier has that name.

    >>> carrier_choice_problem(["LP1"], None), carrier_choice_problem(["A", "B"], None)
    (None, 'several')
    >>> carrier_choice_problem(["A", "B"], "C")
    'unknown'
    """
    if chosen is None:
        return SEVERAL_CARRIERS if len(names) > 1 else None
    return None if chosen in names else UNKNOWN_CARRIER


def offers_exact_edges(engine):
    """Whether ``engine`` (its name) gives exact edges, the scan of z_step = 0."""
    return engine == EXACT_EDGES_ENGINE


def check_stepped(scan):
    """EngineError when a stepped engine is asked for exact edges (``scan.exact``)."""
    if scan.exact:
        raise EngineError(EXACT_EDGES_ONLY)


def thickness_tolerance_from_stored(value):
    """The mapping's thickness tolerance (mm, or None for half the thickness) from the float a
    property or preference stores: a negative value means half the thickness.

    >>> thickness_tolerance_from_stored(-1.0) is None, thickness_tolerance_from_stored(0.3)
    (True, 0.3)
    """
    return None if value < 0 else value


def stored_thickness_tolerance(tolerance):
    """The float a property or preference stores for ``tolerance`` (None: half the thickness).

    >>> stored_thickness_tolerance(None), stored_thickness_tolerance(0.35)
    (-1.0, 0.35)
    """
    return HALF_THICKNESS_STORED if tolerance is None else tolerance


# What a disc must look like to be taken for a wafer when WaferScan picks the wafers among many
# solids itself (a STEP file split into its solids): far thinner than it is wide, and one of the
# SEMI wafer sizes (SEMI M1) within a margin that allows for a model drawn a little off. A rod,
# a collar or a column is a disc to the B-rep (a cylinder with two flat ends), not a wafer.
SEMI_DIAMETERS = (100.0, 125.0, 150.0, 200.0, 300.0, 450.0)  # mm
DIAMETER_MARGIN = 1.0  # mm either side of a size
MIN_ASPECT = 20.0  # diameter / thickness; a 300 mm wafer's is 387, a 100 mm one's 190


def wafer_like(diameter, thickness, diameters=None, margin=DIAMETER_MARGIN):
    """Why a disc of ``diameter`` and ``thickness`` (mm) is not taken for a wafer, or None
    when it is: its diameter at least ``MIN_ASPECT`` times its thickness, and within
    ``margin`` of one of ``diameters`` (the sizes the user gives; None: the SEMI sizes).

    >>> wafer_like(300.0, 0.7) is None, wafer_like(200.2, 0.725) is None
    (True, True)
    >>> wafer_like(0.8, 160.0)
    'a cylinder 0.8 mm across and 160 mm high: a wafer is at least 20 times as wide as thick'
    >>> wafer_like(250.0, 0.775)
    'a disc 250 mm across: not a wafer size (100, 125, 150, 200, 300, 450 mm, ± 1 mm)'
    >>> wafer_like(250.0, 0.775, diameters=(250.0,)) is None
    True
    """
    if not diameter >= MIN_ASPECT * thickness:
        return (f"a cylinder {diameter:g} mm across and {thickness:g} mm high: a wafer is at "
                f"least {MIN_ASPECT:g} times as wide as thick")
    diameters = SEMI_DIAMETERS if diameters is None else diameters
    if not any(abs(diameter - size) <= margin for size in diameters):
        sizes = ", ".join(f"{size:g}" for size in diameters)
        return f"a disc {diameter:g} mm across: not a wafer size ({sizes} mm, ± {margin:g} mm)"
    return None


def slots_scan_range(carrier):
    """(start_z, final_z): the scan range that covers the windows of all of ``carrier``'s slots,
    from slot 1's seat − pitch/2 to the top slot's seat + pitch/2 (SPEC §3), wherever the
    sensor stands. The GUI's first Run scan takes it, and keeps following it.

    >>> from waferscan.core.model import Carrier
    >>> slots_scan_range(Carrier("FOUP", 5, 10.0, 10.0, (0.0, 0.0), 300.0, 0.775))
    (5.0, 55.0)
    """
    return (carrier.seat_z(1) - 0.5 * carrier.pitch,
            carrier.seat_z(carrier.slot_count) + 0.5 * carrier.pitch)
