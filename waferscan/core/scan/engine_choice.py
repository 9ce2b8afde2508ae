"""Whether an engine can scan a layout, said as bad input: one check for every command that
scans (``waferscan scan``, ``waferscan calibrate``) so each refuses the same choices in the
same words, naming the parameters.txt line that set the value when it came from one."""

from __future__ import annotations

from ..errors import InputError
from ..rules import offers_exact_edges
from .sensing import ideal_sensor


def check_engine(layout, engine, source, parameters=None):
    """InputError when ``engine`` cannot scan ``layout``: exact edges (z_step = 0) come from the
    analytic engine only, and so do a beam spot's blocked fraction and latching in motion
    (SPEC §10). ``source`` is the layout's file; ``parameters`` (core.files.mcs.Parameters) the
    parameters.txt put over it, whose z_step line is named when it set z_step."""
    if layout.scan.exact and not offers_exact_edges(engine):
        message = (f"z_step = 0 asks for exact edges, which only the analytic engine gives "
                   f"(not {engine})")
        if parameters is not None and "z_step" in parameters.values:
            raise InputError(parameters.source, parameters.lines.get("z_step"), message)
        raise InputError(source, None, message)
    if not ideal_sensor(layout) and engine != "analytic":
        raise InputError(source, None, f"a beam spot or latch = {layout.scan.latch} is "
                                       f"computed by the analytic engine only (not {engine})")
