"""A sweep's summary (summary.json's content): each rate with its 95 % interval over layouts,
the confusion table, the margins' percentiles and the extremes."""

from __future__ import annotations

import math

from .draws import PLACED
from .tally import (
    CORRECT_SLOTS,
    HOLDS_STATE,
    LACKS_STATE,
    ONE_LAYOUT,
    REPORTED_SLOTS,
    STATE_KEYS,
    TRUE_SLOTS,
)

# --- statistics ------------------------------------------------------------------------------

Z95 = 1.959963984540054


def wilson(k, n, z=Z95):
    """The Wilson score interval (low, high) of a proportion k/n at ~95 %; (None, None) when
    n = 0."""
    if n == 0:
        return (None, None)
    return _wilson(k / n, n, z, k == 0, k == n)


def _wilson(p, n, z, none, every):
    """The Wilson score interval of a proportion p over n trials (n may be a float, an
    effective number of trials); ``none`` (``every``): no trial (every trial) counted, so the
    low (high) end is 0 (1) exactly, not a rounding residue of it."""
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1.0 - p) / n + z * z / (4 * n * n)) / denom
    return (0.0 if none else max(0.0, centre - half), 1.0 if every else min(1.0, centre + half))


INTERVALS = ("95 % Wilson score intervals over the layouts: the number of trials is the "
             "slots counted divided by the design effect, the spread of the layouts' own "
             "rates (cluster-robust, by layout) over the spread independent slots would give, "
             "at least 1; a rate of 0 or 1 gives no spread to measure and counts one trial "
             "per layout")


def layout_interval(k, n, kk, kn, nn, layouts, z=Z95):
    """The ~95 % interval (low, high) of a rate k / n counted over layouts, layout i adding
    k_i of its n_i trials (slots): ``kk``, ``kn``, ``nn`` are the sums over layouts of k_i²,
    k_i n_i and n_i², ``layouts`` the number of layouts with n_i > 0 (integers). The slots of
    one layout share its draws (a beam's teach error moves them all), so they are not
    independent trials: the variance of the rate is estimated from the layouts' spread, the
    ratio estimator's cluster-robust variance L / (L − 1) Σ (k_i − p n_i)² / n², and the
    Wilson interval is taken with the effective number of trials n / deff, deff that variance
    over the binomial p (1 − p) / n, at least 1 (never narrower than independent slots). With
    k = 0 or k = n there is no spread to measure: one trial per layout, the widest the
    layouts allow. (None, None) when n = 0."""
    if n == 0:
        return (None, None)
    if 0 < k < n and layouts > 1:
        # n² Σ (k_i − p n_i)², p = k / n, in integers: exact, whatever the order of the sums
        spread = kk * n * n - 2 * k * n * kn + k * k * nn
        deff = (layouts * spread) / ((layouts - 1) * n * k * (n - k))
        trials = n / max(1.0, deff)
    else:
        trials = layouts
    return _wilson(k / n, trials, z, k == 0, k == n)


def rate_intervals(moments, state, slots):
    """(miss, false call) intervals of ``state`` from ``layout_moments``' sums (``slots`` a
    layout): a miss is a slot truly the state reported otherwise (k_i = true − correct of n_i =
    true), a false call a slot not truly the state reported as it (k_i = reported − correct of
    n_i = slots − true)."""
    M = [[int(v) for v in row] for row in moments[state]]
    T, R, C, H, L, O = TRUE_SLOTS, REPORTED_SLOTS, CORRECT_SLOTS, HOLDS_STATE, LACKS_STATE, ONE_LAYOUT
    miss = layout_interval(M[T][O] - M[C][O], M[T][O],
                           M[T][T] - 2 * M[T][C] + M[C][C], M[T][T] - M[T][C], M[T][T],
                           M[H][O])
    false_call = layout_interval(
        M[R][O] - M[C][O], slots * M[O][O] - M[T][O],
        M[R][R] - 2 * M[R][C] + M[C][C],
        slots * (M[R][O] - M[C][O]) - M[T][R] + M[T][C],
        slots * slots * M[O][O] - 2 * slots * M[T][O] + M[T][T],
        M[L][O])
    return miss, false_call




def clearance_summary(check, counts, least):
    """summary.json's ``clearance`` (core/sweep/clearance.py): the rate of layouts with a
    contact and its 95 % interval (``layout_interval``, one trial a layout; a layout's draws are
    its own), the layouts' least distances
    (``least``: the reduction's distribution, or None), the contacts by closest part and slot."""
    from .clearance import METHOD

    n, k = counts["layouts"], counts["contacts"]
    # One trial per layout: sums over layouts of k_i², k_i n_i, n_i² are k, k, n.
    low, high = layout_interval(k, n, k, k, n, n)
    parts = [p.name for p in check.body.parts]
    return {
        "clearance_min": check.clearance_min,
        "body": check.body.body,
        "motions": list(check.body.motions),
        "layouts": n,
        "contacts": k,
        "contact_rate": k / n if n else None,
        "contact_rate_95": [low, high],
        "least_distance": least,
        "contacts_by_part": {name: int(c) for name, c in zip(parts, counts["by_part"]) if c},
        "contacts_by_slot": {str(s + 1): int(c) for s, c in enumerate(counts["by_slot"]) if c},
        "method": METHOD,
    }


def summarise(base, tolerances, n, seed, tally):
    """The sweep's summary (the dict written as summary.json) from ``reduce_partitions``'s
    tally."""
    from ..files.scenario import MISPLACED_RISE, THIN_FACTOR

    plan = base.plan
    conf = tally["confusion"]
    names = STATE_KEYS
    confusion = {names[i]: {names[j]: int(conf[i, j]) for j in range(8)} for i in range(8)
                 if conf[i].sum() > 0}
    total = int(conf.sum())
    rates = {}
    for i, name in enumerate(names):
        true_n = int(conf[i].sum())
        reported_n = int(conf[:, i].sum())
        hits = int(conf[i, i])
        if true_n == 0 and reported_n == 0:
            continue
        missed = true_n - hits
        false_calls = reported_n - hits
        others = total - true_n
        miss_95, false_call_95 = rate_intervals(tally["moments"], i, plan.slot_count)
        rates[name] = {
            "true": true_n, "reported": reported_n, "correct": hits,
            "miss_rate": missed / true_n if true_n else None,
            "miss_rate_95": list(miss_95),
            "false_call_rate": false_calls / others if others else None,
            "false_call_rate_95": list(false_call_95),
        }
    low, high = plan.thickness_window()
    below, above = plan.position_window()
    ends = tally["extremes"]
    # Safer thresholds: each limit halfway between the present wafers' extreme and the nearest
    # reading of the state on the other side (or, with none drawn, that state's nominal reading:
    # a thin wafer THIN_FACTOR t, a double 2 t, a misplaced wafer MISPLACED_RISE off its seat).
    t = plan.wafer_thickness
    suggested = None
    if ends["thickness"] is not None:
        th_min, th_max = ends["thickness"]
        off_min, off_max = ends["offset"]
        thin, double, mis = (ends["thin_thickness"], ends["double_thickness"],
                             ends["misplaced_offset"])
        lo_ref = thin[1] if thin else THIN_FACTOR * t
        hi_ref = double[0] if double else 2.0 * t
        pos_ref = mis[0] if mis else MISPLACED_RISE
        t_min = 0.5 * (th_min + lo_ref)
        t_max = 0.5 * (th_max + hi_ref)
        worst_below = float(max(0.0, -off_min))
        worst_above = float(max(0.0, off_max))
        suggested = {
            "thickness_min": t_min, "thickness_max": t_max,
            "position_below": 0.5 * (worst_below + pos_ref),
            "position_above": 0.5 * (worst_above + pos_ref),
            # Halfway between an empty slot's blocked fraction (0) and the weakest peak a wafer
            # gave: the largest margin to both. The ideal beam blocks all or nothing: 0.5.
            "threshold_on": 0.5 * tally.get("weakest_peak", 1.0),
            "weakest_peak": tally.get("weakest_peak", 1.0),
            "worst_thickness_margin": min(th_min - t_min, t_max - th_max),
        }
    layout = base.layout
    margins = tally["margins"]
    clearance = None
    if base.clearance is not None:  # the [clearance] report (core/sweep/clearance.py)
        margins = {k: v for k, v in margins.items() if k != "clearance"}
        clearance = clearance_summary(base.clearance, tally["clearance"],
                                      tally["margins"].get("clearance"))
    summary = {
        "n": int(n), "seed": int(seed), "slots": int(plan.slot_count),
        "slot_count_total": total,
        "rules": plan.rules,
        "recipe": {"thickness_min": low, "thickness_max": high, "position_below": below,
                   "position_above": above, "double_threshold": plan.double_limit(),
                   "protrusion_limit": plan.protrusion_limit,
                   "threshold_on": (layout.amplifier.threshold_on if layout.amplifier
                                    else 0.5)},
        "tolerances": {name: {"dist": d.kind, "a": d.a, "b": d.b}
                       for name, d in tolerances.quantities.items()},
        "states": ({STATE_KEYS[PLACED[state]]: p for state, p in tolerances.states}
                   if tolerances.states else "INPUT's load"),
        "confusion": confusion,
        "rates": rates,
        "intervals": INTERVALS,
        "margins": margins,
        "suggested": suggested,
    }
    if clearance is not None:
        summary["clearance"] = clearance
    return summary
