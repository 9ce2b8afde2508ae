"""FreeCAD's own B-rep geometry (OpenCASCADE) as the judge: the ``brep`` engine and the CAD
measurement the cross-check (crosscheck.py) uses, as the paper confirmed its numbers with the CAD
measure tool.

OpenCASCADE quirk, handled here: ``solid.distToShape(edge)`` measures to the solid's faces, so
a beam lying wholly inside a wafer would show a gap. The beam is blocked when it touches the
solid (distance within ``Part.Precision.confusion()``) or when its emitter lies inside it.
"""

from __future__ import annotations

import FreeCAD as App
import Part

from .bowed_solid import bowed_blocked, bowed_wafer_solid
from .stepping import stepper_through_document

TOUCH = Part.Precision.confusion()  # 1e-7 mm


def beam_edge(emitter, beam):
    end = tuple(o + beam.length * d for o, d in zip(emitter, beam.direction))
    return Part.makeLine(App.Vector(*emitter), App.Vector(*end))


def brep_gap(solid, emitter, beam):
    """Distance (mm) between the beam and the solid by OpenCASCADE; 0 when the beam is inside."""
    if solid.isInside(App.Vector(*emitter), 0.0, True):
        return 0.0
    return solid.distToShape(beam_edge(emitter, beam))[0]


def beam_box(emitter, beam):
    """The beam's bounding box from its ends, with room for the edge's own tolerance and a
    touch. (FreeCAD 0.20 leaks ~80 B on each read of a shape's ``BoundBox`` attribute: read at
    every step of every scan, ~30 kB a command, 115 MB over 4,000.)"""
    end = [o + beam.length * d for o, d in zip(emitter, beam.direction)]
    box = App.BoundBox(*map(min, emitter, end), *map(max, emitter, end))
    box.enlarge(11 * TOUCH)
    return box


def brep_blocked(solid, emitter, beam):
    return brep_gap(solid, emitter, beam) <= TOUCH


def brep_stepper(scene, mover):
    """The ``brep`` engine: step by step, the beam as an edge against each wafer's solid. Only
    wafers whose bounding box meets the beam's are asked, since each question costs ~0.3 ms."""

    def prepare(layout, reachable):
        solids = {i: scene.wafers[i].shape() for i in reachable}
        tests = {i: brep_blocked for i in reachable}
        for i in reachable:
            if layout.wafers[i].bow:  # SPEC §10: the document's disc stands for a bowed wafer
                solids[i], tests[i] = bowed_wafer_solid(layout.wafers[i]), bowed_blocked
        # (optimalBoundingBox, not BoundBox: see beam_box)
        boxes = {i: s.optimalBoundingBox() for i, s in solids.items()}

        def wafers_hit(beam):
            box = beam_box(beam.emitter, beam)
            return [i for i, solid in solids.items()
                    if box.intersect(boxes[i]) and tests[i](solid, beam.emitter, beam)]

        return wafers_hit

    return stepper_through_document(scene, mover, prepare)
