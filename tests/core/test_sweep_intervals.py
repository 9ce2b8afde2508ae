"""A sweep's 95 % intervals hold over layouts (SPEC §12, issue 24 item 5): the slots of one
layout share its sensor's draws (``beam_z`` shifts all 25 together), so a rate's interval must
come from the spread between layouts, not from counting slots as independent trials.

The truth is closed form. A 25-slot FOUP whose seats lie on the 0.05 mm step grid (seat 300,
start 280), t = 0.7, a ±0.5 mm position window, no latch lag: a wafer whose bottom sits d mm
above its seat (d = seat offset − beam_z on the scan's scale) is read at the first step at or
above it, 0.05·ceil(d / 0.05) above the seat, so it reads present iff −0.55 < d ≤ 0.5 and a
position error otherwise (its length, 0.65 or 0.70, is always inside t ± t/2). Then

- ``beam_z`` ~ N(0, σ) (drawn per layout):  P(miss) = Φ(−0.5/σ) + 1 − Φ(0.55/σ);
- ``seat_offset`` ~ U(−a, a) (drawn per wafer): P(miss) = (max(0, a − 0.55) + max(0, a − 0.5)) / 2a;
- both: P(miss) = E over beam_z of the uniform's share outside (beam_z − 0.55, beam_z + 0.5],
  by mpmath's quadrature.

Each case is swept with SEEDS seeds of LAYOUTS layouts; at least 90 % of its intervals must
hold the true rate."""

import math

import mpmath
import numpy as np
import pytest
from scenarios import normal, one_carrier, uniform

from waferscan.core.files.scenario import parse_scenario
from waferscan.core import sweep
from waferscan.core.sweep.distributions import parse_tolerances

SEEDS = 100
LAYOUTS = 200
LOW, HIGH = -0.55, 0.5   # present iff LOW < d <= HIGH (d: bottom above seat, mm)


def foup(load="1" * 25):
    return parse_scenario(one_carrier(load, start=280.0, final=560.0, first_slot_z=300.0,
                                      name="F", scan="sensor_response = 0.0\n",
                                      mapping="position_tolerance = 0.5\n", slots=25))


def phi(x):
    return mpmath.ncdf(x)


def miss_beam_z(sigma):
    return float(phi(-HIGH / sigma) + 1 - phi(-LOW / sigma))


def miss_seat(a):
    a = mpmath.mpf(a)
    return float((max(0, a + LOW) + max(0, a - HIGH)) / (2 * a))


def miss_both(sigma, a):
    """d = o − b with o ~ U(−a, a), b ~ N(0, σ): 1 − E_b[ |(b + LOW, b + HIGH] ∩ [−a, a]| / 2a ]."""
    def inside(b):
        return max(0, min(b + HIGH, a) - max(b + LOW, -a)) / (2 * a)

    held = mpmath.quad(lambda b: inside(b) * mpmath.npdf(b, 0, sigma),
                       [-mpmath.inf, -a - HIGH, -a - LOW, a - HIGH, a - LOW, mpmath.inf])
    return float(1 - held)


def beam_z(sigma):
    return normal("beam_z", 0.0, sigma)


def seat_offset(a):
    return uniform("seat_offset", -a, a)


CASES = {
    # per layout: all of a layout's slots fail together
    "beam_z near 0.5": (beam_z(0.75), "1" * 25, miss_beam_z(0.75)),
    "beam_z near 0": (beam_z(0.2), "1" * 25, miss_beam_z(0.2)),
    # per wafer: independent slots
    "seat_offset at 0.5": (seat_offset(1.05), "1" * 25, miss_seat(1.05)),
    "seat_offset near 0": (seat_offset(0.52), "1" * 25, miss_seat(0.52)),
    # both, on a carrier with empty slots (the layouts' numbers of wafers differ)
    "both, half loaded": (beam_z(0.3) + seat_offset(0.5), "10" * 12 + "1",
                          miss_both(0.3, 0.5)),
}


def test_the_closed_forms_are_near_0_and_near_half():
    rates = {name: case[2] for name, case in CASES.items()}
    assert rates["seat_offset at 0.5"] == 0.5
    assert 0.45 < rates["beam_z near 0.5"] < 0.5
    assert rates["beam_z near 0"] < 0.01
    assert rates["seat_offset near 0"] == pytest.approx(0.02 / 1.04, rel=1e-15)
    # the mixed case's quadrature against a direct average over many normal draws
    b = np.random.default_rng(0).normal(0.0, 0.3, 400_000)
    inside = np.clip(np.minimum(b + HIGH, 0.5) - np.maximum(b + LOW, -0.5), 0, None) / 1.0
    assert abs((1 - inside.mean()) - rates["both, half loaded"]) < 5e-4


def intervals(tolerances, load, seeds=SEEDS):
    layout = foup(load)
    tol = parse_tolerances(tolerances)
    for seed in range(seeds):
        summary = sweep.run_sweep(layout, tol, LAYOUTS, seed=seed)
        yield summary


@pytest.mark.parametrize("name", CASES)
def test_95_percent_intervals_hold_the_true_rate(name):
    tolerances, load, truth = CASES[name]
    share = load.count("1") / len(load)
    missed = called = calls = 0
    for summary in intervals(tolerances, load):
        low, high = summary["rates"]["present"]["miss_rate_95"]
        missed += low <= truth <= high
        # every present wafer missed was called a position error, the only other state here
        # (the empty slots of the half loaded carrier read empty): the false-call rate of 5 is
        # the share of all slots, present and empty, that were present and read 5. A sweep
        # that read no 5 has no rate of it.
        if "position_error" in summary["rates"]:
            low, high = summary["rates"]["position_error"]["false_call_rate_95"]
            called += low <= share * truth <= high
            calls += 1
    assert missed >= 0.9 * SEEDS, (name, truth, missed)
    assert called >= 0.9 * calls, (name, share * truth, called, calls)


def wilson_by_hand(p, n, z=1.959963984540054):
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def test_the_intervals_are_the_cluster_robust_formula_on_each_layouts_own_counts():
    """The sums a partition sends (``layout_moments``) give the interval that the layouts' own
    counts give, written out: p = Σk/Σn, V = L/(L−1) Σ(k_i − p n_i)²/(Σn)², deff = V over
    p(1 − p)/Σn (at least 1), Wilson at Σn/deff trials; one trial a layout at p = 0 or 1."""
    rng = np.random.default_rng(7)
    m, S = 300, 25
    truth = rng.choice(7, size=(m, S), p=[0.2, 0.5, 0.0, 0.1, 0.1, 0.05, 0.05])
    reported = truth.copy()
    # a third of the layouts misread most of their present wafers as 5 (a layout's own draw),
    # a few slots anywhere read wrong on their own
    shifted = rng.random(m) < 1 / 3
    reported[shifted[:, None] & (truth == 1) & (rng.random((m, S)) < 0.8)] = 5
    noise = rng.random((m, S)) < 0.03
    reported[noise] = rng.choice(8, size=noise.sum())
    moments = sweep.layout_moments(truth, reported)
    checked = 0
    for state in range(8):
        miss, false_call = sweep.rate_intervals(moments, state, S)
        t, r = truth == state, reported == state
        for got, k_i, n_i in ((miss, (t & ~r).sum(1), t.sum(1)),
                              (false_call, (~t & r).sum(1), (~t).sum(1))):
            k, n = int(k_i.sum()), int(n_i.sum())
            if n == 0:
                assert got == (None, None)
                continue
            p, layouts = k / n, int((n_i > 0).sum())
            if 0 < k < n:
                v = layouts / (layouts - 1) * ((k_i - p * n_i) ** 2).sum() / n ** 2
                trials = n / max(1.0, v / (p * (1 - p) / n))
            else:
                trials = layouts
            low, high = wilson_by_hand(p, trials)
            want = (0.0 if k == 0 else low, 1.0 if k == n else high)
            assert got == pytest.approx(want, rel=1e-12, abs=1e-15), (state, k, n)
            checked += 1
    assert checked >= 13
    # the shared misreading widens present's miss interval well beyond Wilson's over slots
    k, n = int(((truth == 1) & (reported != 1)).sum()), int((truth == 1).sum())
    slot_low, slot_high = sweep.wilson(k, n)
    low, high = sweep.rate_intervals(moments, 1, S)[0]
    assert high - low > 2 * (slot_high - slot_low)
