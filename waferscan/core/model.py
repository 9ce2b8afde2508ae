"""The simulator's model: wafers, the beam, carriers, scan parameters and a whole layout.

Lengths in mm, angles in degrees, times in seconds, speeds in mm/s. Base frame Z up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

FAST, SLOW = "fast", "slow"
MODES = (FAST, SLOW)
UP, DOWN, UPDOWN = "up", "down", "updown"
DIRECTIONS = (UP, DOWN, UPDOWN)

# The grid formula of SPEC §3 adds this before flooring, so that a final_z meant to lie on the
# grid is not lost to rounding.
GRID_EPSILON = 1e-9


def unit(vector, what="vector"):
    """The vector scaled to length 1; ValueError for a zero or non-finite vector."""
    x, y, z = (float(c) for c in vector)
    norm = math.hypot(x, y, z)  # no underflow or overflow for tiny or huge components
    if not math.isfinite(norm) or norm == 0.0:
        raise ValueError(f"{what} must be a finite, non-zero vector, got {list(vector)}")
    return (x / norm, y / norm, z / norm)


@dataclass(frozen=True)
class Wafer:
    """A wafer: a solid disc. ``center`` is the centre of its bottom (seating) face, ``normal``
    the unit axis pointing up through the thickness (FreeCAD's Part::Cylinder convention)."""

    name: str
    center: tuple
    normal: tuple
    diameter: float
    thickness: float
    carrier: str | None = None
    slot: int | None = None  # the slot it was loaded into, when known; not used by the scan
    # SPEC §10: the bottom surface is bow (1 - r²/R²) above the rim's bottom circle, whose
    # centre ``center`` then is (core/geometry/bow.py); 0: the flat disc.
    bow: float = 0.0

    @property
    def radius(self):
        return self.diameter / 2.0

    @property
    def mid_center(self):
        """Centre of the disc's mid-plane (the paper's r_c)."""
        h = self.thickness / 2.0
        return tuple(c + h * n for c, n in zip(self.center, self.normal))


@dataclass(frozen=True)
class Beam:
    """A through-beam: emitter point, unit direction towards the receiver, and length."""

    emitter: tuple
    direction: tuple
    length: float

    @property
    def receiver(self):
        return tuple(o + self.length * d for o, d in zip(self.emitter, self.direction))


@dataclass(frozen=True)
class Carrier:
    """A wafer carrier (FOUP or cassette): its nominal slots, as the MCS knows them.

    ``front`` is the unit XY vector from the carrier's centre out through its opening, towards the
    robot; ``support_span`` the distance between the left and right slot supports' inner edges.
    """

    name: str
    slot_count: int
    pitch: float
    first_slot_z: float
    center: tuple  # (x, y) of the wafers' centres
    wafer_diameter: float
    wafer_thickness: float
    front: tuple = (0.0, -1.0)
    support_span: float = 293.0

    def seat_z(self, slot):
        """Seat (bottom-face) Z of a slot, slot 1 being the bottom one."""
        return self.first_slot_z + (slot - 1) * self.pitch

    @property
    def lateral(self):
        """Unit XY vector across the carrier, from its left support to its right one."""
        fx, fy = self.front
        return (-fy, fx)


@dataclass(frozen=True)
class ScanParameters:
    """What the user (or the MCS) sets for one scan."""

    start_z: float
    final_z: float
    z_step: float = 0.05
    mode: str = FAST
    direction: str = UP
    scan_speed: float = 100.0  # mm/s
    sensor_response: float = 0.0  # s
    # SPEC §10: how the controller latches edges ("step": on the grid, as above; "encoder" or
    # "sampled": during a continuous stroke, see core/sensor/motion.py), the stroke's acceleration
    # (mm/s², inf: full speed at once) and the controller's read period (s) for "sampled".
    latch: str = "step"
    acceleration: float = math.inf
    sample_period: float = 0.0
    # SPEC §13, slow scanning's arm motions at each pocket (core/scan/slow_scan.py): the jab's reach
    # (mm, 0: none), the sweep's half-angle (deg, 0: none), the wrist axis's distance behind the
    # beam's midpoint (mm; the bundled robot's 260), and the arm's and the wrist's speed and
    # acceleration (mm/s, mm/s², deg/s, deg/s²) for the scan's simulated duration.
    jab: float = 0.0
    sweep: float = 0.0
    sweep_radius: float = 260.0
    arm_speed: float = 250.0
    arm_acceleration: float = 1000.0
    wrist_speed: float = 90.0
    wrist_acceleration: float = 360.0

    @property
    def exact(self):
        """z_step = 0 asks for the continuous edges instead of stepped positions."""
        return self.z_step == 0.0

    @property
    def last_step(self):
        """k of the last stepped position (SPEC §3): floor(x + 1e-9 max(1, x)), x = (final -
        start)/step. The tolerance is relative: at 10^7 steps and more a final_z on the grid is
        rounded a few 1e-9 steps below its k, and must stay in."""
        x = (self.final_z - self.start_z) / self.z_step
        return int(math.floor(x + GRID_EPSILON * max(1.0, x)))

    @property
    def position_count(self):
        return self.last_step + 1

    def position(self, k):
        """Scan position z_k = start_z + k * z_step; every engine uses exactly this."""
        return self.start_z + k * self.z_step

    @property
    def latch_lag(self):
        """How far (mm) a latched edge trails the true one in the direction of motion."""
        return self.scan_speed * self.sensor_response if self.mode == FAST else 0.0


@dataclass(frozen=True)
class MappingTolerances:
    """Tolerances of the slot mapping (SPEC §4). ``thickness_tolerance`` None means 0.5 t."""

    thickness_tolerance: float | None = None
    position_tolerance: float = 0.5
    protrusion_limit: float = 1.0
    # SPEC §11's recipe, as core.mapping.SlotPlan takes it (None: the SPEC §4 rule from t, Δt
    # and Δp); core/recipe.py lists the keys.
    thickness_min: float | None = None
    thickness_max: float | None = None
    double_threshold: float | None = None
    position_below: float | None = None
    position_above: float | None = None
    rules: str = "waferscan"
    thickness_correction: float = 1.0
    # SPEC §15: a motion of the scan closer than this (mm) to a wafer is a contact
    # (core/scan/clearance.py).
    clearance_min: float = 1.0

    def thickness_tolerance_for(self, thickness):
        if self.thickness_tolerance is None:
            return 0.5 * thickness
        return self.thickness_tolerance


@dataclass(frozen=True)
class RobotSpec:
    """The robot that carries the scanner: its URDF (None: the bundled robot) and where its
    base stands. Its start pose is taught so that its beam lies where the layout's beam is."""

    urdf: str | None = None
    base: tuple = (0.0, 0.0, 0.0)  # mm
    base_yaw: float = 0.0  # degrees about Z


@dataclass(frozen=True)
class Layout:
    """Everything one scan needs: carriers, wafers, the beam at the scan's start, the lift axis,
    the scan parameters, the mapping tolerances and which carrier the slot code describes."""

    carriers: tuple
    wafers: tuple
    beam: Beam
    scan: ScanParameters
    lift_axis: tuple = (0.0, 0.0, 1.0)
    mapping: MappingTolerances = field(default_factory=MappingTolerances)
    carrier: str | None = None  # name of the scanned carrier; None: the only one
    robot: RobotSpec | None = None  # what carries the scanner, when a robot does
    # SPEC §10: the beam's cross-section (core.sensor.spot.BeamSpot; None: the ideal line) and the
    # amplifier's thresholds (core.sensor.spot.Amplifier; None: 0.5, no hysteresis).
    spot: object = None
    amplifier: object = None

    @property
    def scanned_carrier(self):
        """The carrier whose slots the code describes."""
        # The clear choices first, as every scan asks: the one carrier, or the first so named.
        if self.carrier is None:
            if len(self.carriers) == 1:
                return self.carriers[0]
        else:
            for carrier in self.carriers:
                if carrier.name == self.carrier:
                    return carrier
        from .rules import SEVERAL_CARRIERS, carrier_choice_problem

        problem = carrier_choice_problem([c.name for c in self.carriers], self.carrier)
        if problem == SEVERAL_CARRIERS:
            raise ValueError("the layout has several carriers: say which one to scan")
        if problem:
            raise ValueError(f"no carrier named {self.carrier!r}")
        if self.carrier is None:
            return self.carriers[0]
        return next(c for c in self.carriers if c.name == self.carrier)

    def emitter_at(self, z):
        """The emitter at scan position z: the start beam translated along the lift axis.

        Written with scalar arithmetic only, so that it gives bit-identical numbers for a Python
        float and for a numpy array of positions (the engines rely on that)."""
        ox, oy, oz = self.beam.emitter
        ax, ay, az = self.lift_axis
        travel = (z - oz) / az
        return (ox + travel * ax, oy + travel * ay, z)

    def with_scan(self, **changes):
        return replace(self, scan=replace(self.scan, **changes))
