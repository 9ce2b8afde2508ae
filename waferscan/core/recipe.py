"""A mapping recipe (SPEC §11): the keys a controller holds per carrier type beyond SPEC §4's
tolerances, how a layout's mapping carries them, and how they are listed and written.

The keys are the same everywhere: parameters.txt, a scenario's [mapping] table, the document's
ScanSettings (cad/recipe_properties.py), results.txt's header and ``--json``'s ``params``:

- ``thickness_min``, ``thickness_max`` (mm): a run of that diff (after the thickness correction)
  is a present wafer; shorter is thin, longer double (default t − Δt, t + Δt);
- ``double_threshold`` (mm): beyond it a run is cross-slotted (default 2t + Δt; 2.5 t under the
  ``boundary`` rules);
- ``position_below``, ``position_above`` (mm): how far a run's bottom edge may lie below or above
  its seat (default Δp each);
- ``rules``: ``waferscan`` (SPEC §4) or ``boundary`` (the open controller's rules, SPEC §11);
- ``thickness_correction``: measured diffs are divided by it before they are judged (1: none).

The scan start and end of a recipe are SPEC §3's ``start_z`` and ``final_z``; speed and the
amplifier's thresholds are ``scan_speed``, ``threshold_on`` and ``threshold_off``.
"""

from __future__ import annotations

from .mapping import WAFERSCAN

# In the order they are listed (results.txt, parameters.txt); the checks are schema.MAPPING_KEYS'.
RECIPE_KEYS = ("thickness_min", "thickness_max", "double_threshold", "position_below",
               "position_above", "rules", "thickness_correction")

# What each key is when not given: None for a limit that follows t, Δt and Δp.
DEFAULTS = {"thickness_min": None, "thickness_max": None, "double_threshold": None,
            "position_below": None, "position_above": None, "rules": WAFERSCAN,
            "thickness_correction": 1.0}


def recipe_fields(mapping):
    """The recipe's keys of a layout's ``MappingTolerances`` as ``SlotPlan`` fields."""
    return {key: getattr(mapping, key) for key in RECIPE_KEYS}


def given_values(mapping):
    """The recipe keys a layout's mapping sets to other than their defaults: what a scan lists
    in results.txt and ``--json`` besides SPEC §4's tolerances (a scan without a recipe lists
    what it always did)."""
    return {key: getattr(mapping, key) for key in RECIPE_KEYS
            if getattr(mapping, key) != DEFAULTS[key]}


def resolved_values(plan):
    """Every recipe key of a ``SlotPlan`` with the limit it judges by (defaults resolved from
    t, Δt and Δp): what a calibration reports and writes."""
    low, high = plan.thickness_window()
    below, above = plan.position_window()
    return {"thickness_min": low, "thickness_max": high, "double_threshold": plan.double_limit(),
            "position_below": below, "position_above": above, "rules": plan.rules,
            "thickness_correction": plan.thickness_correction}


def describe(plan):
    """One line of the recipe a ``SlotPlan`` judges by, for people (the GUI's scan panel)."""
    low, high = plan.thickness_window()
    below, above = plan.position_window()
    text = (f"{plan.rules} rules: present {low:g} to {high:g} mm, seat −{below:g}/+{above:g} mm, "
            f"cross-slotted beyond {plan.double_limit():g} mm")
    if plan.thickness_correction != 1.0:
        text += f", diffs divided by {plan.thickness_correction:g}"
    return text
