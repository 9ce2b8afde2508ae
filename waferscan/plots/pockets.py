"""A slow scan's pockets seen from above under the signal plot (SPEC §13, ``scan --plot``): the
same plans as the GUI's "Pockets from above" tab (core/scan/pocket_plan.py), drawn with matplotlib
by plots/signal.py when the scan made a jab or a sweep."""

from __future__ import annotations

from ..core.files.report import STATE_COLOURS
from ..core.scan import pocket_plan as plans

MOST = 4  # pockets drawn: the judged ones first (pocket_plan.chosen_slots)
# (colour, line style, width) of each beam, as in the GUI's plan view.
BEAM_STYLES = {
    plans.START: ("#6e6e6e", "--", 1.0),
    plans.DEEPEST: ("#3c3c3c", ":", 1.0),
    plans.FRONT: ("#d71919", "-", 1.8),
    plans.SWEEP_FIRST: ("#1e50dc", "-", 1.8),
    plans.SWEEP_LAST: ("#00966e", "-", 1.8),
}
STRIKE = "#be006e"  # a tine's path inside the wafer during the sweep, as in the GUI


def pocket_plans(result):
    """The PocketPlans to draw for a result: none without a jab or a sweep."""
    return [plans.pocket_plan(result, slot) for slot in plans.chosen_slots(result, MOST)]


def draw_pockets(figure, spec, result, drawn):
    """Draw the result's chosen pockets side by side in the gridspec cell ``spec``; their axes
    are returned. ``drawn`` collects (slot, what, label) for each item drawn (for tests)."""
    from matplotlib.patches import Circle

    shown = pocket_plans(result)
    states = {s.slot: s.state for s in result.slot_map.slots}
    cells = spec.subgridspec(1, max(1, len(shown)), wspace=0.15)
    axes = []
    for i, plan in enumerate(shown):
        axis = figure.add_subplot(cells[0, i])
        axes.append(axis)
        r, g, b = STATE_COLOURS[states[plan.slot]]
        seated = plan.seated
        axis.add_patch(Circle(seated.center, seated.radius, fill=False, ls="--", lw=0.8,
                              ec="#969696"))
        drawn.append((plan.slot, "seated", seated.name))
        for disc in plan.wafers:
            axis.add_patch(Circle(disc.center, disc.radius, fc=(r / 255, g / 255, b / 255, 0.45),
                                  ec=(r / 400, g / 400, b / 400), lw=0.8))
            drawn.append((plan.slot, "wafer", disc.name))
        for arc in plan.strikes:  # where the sweep turned a tine into the wafer
            axis.plot(*zip(*arc.points), "-", color=STRIKE, lw=2.4, solid_capstyle="butt")
            drawn.append((plan.slot, "strike", arc.label))
        for beam in plan.beams:
            colour, style, width = BEAM_STYLES[beam.role]
            (u0, v0), (u1, v1) = beam.ends
            axis.plot([u0, u1], [v0, v1], style, color=colour, lw=width)
            drawn.append((plan.slot, beam.role, beam.label))
            if beam.contact is not None:
                axis.plot(*beam.contact, "o", color=colour, ms=4.5)
                axis.annotate(beam.label, beam.contact, fontsize=6, color=colour,
                              xytext=(4, -10 if beam.role == plans.FRONT else 4),
                              textcoords="offset points")
                drawn.append((plan.slot, "contact", beam.label))
        axis.set_aspect("equal")
        axis.autoscale_view()
        axis.set_title(plan.title.replace(": ", "\n", 1).replace("; ", "\n")
                       .replace(", shift", "\nshift"), fontsize=6.5)
        axis.tick_params(labelsize=6)
        axis.set_xlabel("across the opening, mm", fontsize=6)
        if i == 0:
            axis.set_ylabel("into the carrier, mm", fontsize=6)
    return axes
