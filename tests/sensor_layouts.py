"""Layouts and closed forms shared by the tests of SPEC §10 (beam spot, amplifier, latching)."""

import math

from waferscan.core.model import Beam, Carrier, Layout, ScanParameters, Wafer, unit

SEAT = 300.0
T = 0.7


def one_wafer(spot, amplifier=None, thickness=T, direction="up", z_step=0.0, depth=16.6,
              normal=(0.0, 0.0, 1.0), **scan):
    """A 300 mm wafer seated at SEAT, the beam along X crossing it ``depth`` mm inside its rim."""
    carrier = Carrier("C", 1, 10.0, SEAT, (0.0, 0.0), 300.0, thickness)
    wafer = Wafer("W", (0.0, 0.0, SEAT), unit(normal), 300.0, thickness, "C", 1)
    beam = Beam((-200.0, -150.0 + depth, SEAT - 5.0), (1.0, 0.0, 0.0), 400.0)
    params = ScanParameters(SEAT - 5.0, SEAT + 5.0, z_step, direction=direction, **scan)
    return Layout((carrier,), (wafer,), beam, params, spot=spot, amplifier=amplifier)


def band_fraction(spot, z):
    """Closed form: the share of the spot (centre at z) inside the band [SEAT, SEAT + T]."""
    low, high = SEAT - z, SEAT + T - z
    if spot.round:
        r = spot.diameter / 2

        def below(y):  # area of the disc below the chord at height y
            y = max(-r, min(r, y))
            return r * r * math.acos(-y / r) + y * math.sqrt(r * r - y * y)
        return (below(high) - below(low)) / (math.pi * r * r)
    h = spot.height / 2
    return (min(h, max(-h, high)) - min(h, max(-h, low))) / spot.height


def solve(f, a, b):
    """The z in [a, b] where f changes sign, by bisection to 1e-13 mm."""
    fa = f(a)
    for _ in range(200):
        m = 0.5 * (a + b)
        if (f(m) >= 0) == (fa >= 0):
            a, fa = m, f(m)
        else:
            b = m
        if b - a < 1e-13:
            break
    return 0.5 * (a + b)


def oracle_edges(spot, on, off, up):
    """(IN, OUT) as latched moving up or down, or None if the output never turns on."""
    peak_z = SEAT + T / 2
    if band_fraction(spot, peak_z) < on:
        return None
    reach = spot.half_height + 1.0
    rise_on = solve(lambda z: band_fraction(spot, z) - on, SEAT - reach, peak_z)
    fall_on = solve(lambda z: band_fraction(spot, z) - on, peak_z, SEAT + T + reach)
    rise_off = solve(lambda z: band_fraction(spot, z) - off, SEAT - reach, peak_z)
    fall_off = solve(lambda z: band_fraction(spot, z) - off, peak_z, SEAT + T + reach)
    return (rise_on, fall_off) if up else (fall_on, rise_off)
