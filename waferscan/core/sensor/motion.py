"""The lift's stroke and the controller's latch (SPEC §10 "Motion and latching").

A stroke goes from rest at one end to rest at the other with a trapezoidal speed profile:
constant acceleration up to ``scan_speed``, cruise, constant deceleration; a triangle when the
stroke is too short to reach full speed; infinite acceleration is a constant-speed stroke.
Position at a time and time at a position are closed form.

Latching: the sensor's output changes when the beam passes an edge; the amplifier passes the
change on ``sensor_response`` seconds later. ``encoder`` latching takes the axis position at that
moment; ``sampled`` latching takes it at the first read of the output (every ``sample_period``
seconds from the stroke's start) at or after it. After the stroke ends the axis stands still.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

STEP, ENCODER, SAMPLED = "step", "encoder", "sampled"
LATCHES = (STEP, ENCODER, SAMPLED)


@dataclass(frozen=True)
class Stroke:
    """One stroke of the lift from ``start`` to ``end`` (mm); ``speed`` mm/s, ``acceleration``
    mm/s² (math.inf: full speed at once)."""

    start: float
    end: float
    speed: float
    acceleration: float = math.inf

    @property
    def length(self):
        return abs(self.end - self.start)

    @property
    def _profile(self):
        """(peak speed, time accelerating, time cruising) of the stroke."""
        length, v, a = self.length, self.speed, self.acceleration
        if math.isinf(a):
            return v, 0.0, length / v
        if v * v / a >= length:  # a triangle: it never reaches full speed
            peak = math.sqrt(a * length)
            return peak, peak / a, 0.0
        return v, v / a, length / v - v / a

    @property
    def duration(self):
        """s, from rest to rest."""
        _, t_acc, t_cruise = self._profile
        return 2.0 * t_acc + t_cruise

    def travelled(self, t):
        """Distance (mm) from the start at time t (s) after it."""
        peak, t_acc, t_cruise = self._profile
        if t <= 0.0:
            return 0.0
        a = self.acceleration
        if t < t_acc:
            return 0.5 * a * t * t
        d_acc = 0.5 * peak * t_acc
        if t < t_acc + t_cruise:
            return d_acc + peak * (t - t_acc)
        total = self.duration
        if t < total:
            left = total - t
            return self.length - (0.5 * a * left * left if t_acc > 0.0 else 0.0)
        return self.length

    def position(self, t):
        """Axis position (mm) at time t (s) after the stroke's start."""
        sign = 1.0 if self.end >= self.start else -1.0
        return self.start + sign * self.travelled(t)

    def time_at(self, z):
        """When (s after the start) the axis passes position z, which lies on the stroke."""
        d = min(self.length, max(0.0, abs(z - self.start)))
        peak, t_acc, t_cruise = self._profile
        a = self.acceleration
        d_acc = 0.5 * peak * t_acc
        if d <= d_acc and t_acc > 0.0:
            return math.sqrt(2.0 * d / a)
        if d <= d_acc + peak * t_cruise:
            return t_acc + (d - d_acc) / peak
        left = self.length - d
        return self.duration - math.sqrt(max(0.0, 2.0 * left / a))

    def latched(self, z, response, latch=ENCODER, sample_period=0.0):
        """The position the controller latches for a change of the output at position z: the
        axis position ``response`` s later (``encoder``), or at the first read of the output at
        or after that moment (``sampled``, reads every ``sample_period`` s from the start)."""
        t = self.time_at(z) + response
        if latch == SAMPLED and sample_period > 0.0:
            # The read at k*P counts when it is not before t (a 1e-12 relative allowance keeps
            # a change exactly on a read from slipping to the next one through rounding).
            k = math.ceil(t / sample_period - 1e-12)
            t = k * sample_period
        return self.position(t)
