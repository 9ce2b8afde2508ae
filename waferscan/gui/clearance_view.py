"""SPEC §15's clearance shown while a scan plays, and the fork's outline for the pocket plan.

The scan's ``ClearanceReport`` (``result.clearance``, made by ``cad.document_scan``) says the
least distance of every motion. While the animation plays, the panels say the least distance at
the frame shown, asked of the same body that measured the report (``body.nearest`` at the
frame's motion and parameter: its scan position, advance or wrist angle), and the fork is drawn
red while that frame is closer than ``clearance_min``. The body is made once per scan
(``scan_body``) and a frame costs one ``nearest`` (about 0.1 to 0.2 ms on the bundled robot).

Nothing here changes the document: the fork's colour is a view property, put back after.
"""

from __future__ import annotations

from PySide import QtGui

from ..core.scan import clearance as core

__all__ = ["scan_body", "LiveClearance", "ForkColour", "clearance_words",
           "clearance_labels", "show_clearance", "FORK_CONTACT"]

FORK_CONTACT = (0.9, 0.1, 0.1)  # the fork's colour while closer than clearance_min
_KEPT = [None, None]  # [the result, its body]: one body per scan, the last scan's kept


def scan_body(result, doc=None, scene=None):
    """The body that makes ``result``'s scan (``robot.clearance``): the document's robot with
    its URDF, base and taught start pose, as ``cad.document_scan.with_clearance`` builds it, or
    the scanner's heads; without a document, the layout's own (``body_for``). Made once for a
    result and kept for the last one; None when pinocchio (and coal) are missing or the robot
    cannot be read (the scan said so already)."""
    if _KEPT[0] is result:
        return _KEPT[1]
    measured = getattr(result.clearance, "measured_by", None)
    if measured is not None:  # the body that made the scan's own check
        _KEPT[:] = [result, measured]
        return measured
    from ..addon import pinocchio_available

    body = None
    if pinocchio_available():
        try:
            body = _make_body(result.layout, doc, scene)
        except Exception:  # noqa: BLE001 (the scan's own check reported it; nothing to show)
            body = None
    _KEPT[:] = [result, body]
    return body


def _make_body(layout, doc, scene):
    """A result without its check's body (a replay's): the document's, as the CAD layer's check
    makes it (the robot or the scanner's heads, and the carrier's solids), else the layout's."""
    if doc is None:
        from ..robot.clearance import body_for

        return body_for(layout)
    from ..cad.document_scan import clearance_body
    from ..cad.reader import DocumentScene

    return clearance_body(scene or DocumentScene.of(doc), layout)


def clearance_words(nearest):
    """'0.650 mm (tine_left – LP1_W10)' for a ``nearest`` answer (distance, part, obstacle,
    slot); '—' when there is nothing to be near."""
    distance, part, obstacle, _ = nearest
    if part == "" or distance == float("inf"):
        return "—"
    return f"{distance:.3f} mm ({part} – {obstacle})"


class LiveClearance:
    """The least distance at any frame of a scan's animation: ``at(motion, s)`` asks the body
    (None when the scan's clearance was not checked). ``motion_at(z, frame, up_frames)``: the
    scan's motion a stroke frame belongs to; ``pocket_motion(kind, slot)``: a pocket's jab or
    sweep, as the report measured them."""

    def __init__(self, report, body):
        self.report, self.body = report, body
        self.clearance_min = report.clearance_min
        self.motions = [c.motion for c in report.closest]
        self.now = None  # (distance, part, obstacle, slot) at the frame shown last

    @classmethod
    def of(cls, result, doc=None, scene=None):
        """The LiveClearance of ``result``'s scan, or None (no report, no body)."""
        if getattr(result, "clearance", None) is None:
            return None
        body = scan_body(result, doc, scene)
        return None if body is None else cls(result.clearance, body)

    @property
    def least(self):
        """The report's least distance over the whole scan (a ``Closest``), or None."""
        return self.report.least

    def at(self, motion, s):
        """(distance, part, obstacle, slot) of the body at parameter ``s`` of ``motion``; kept
        in ``now``."""
        self.now = self.body.nearest(motion, s)
        return self.now

    @property
    def contact(self):
        """Whether the frame shown last is closer than clearance_min."""
        return self.now is not None and self.now[0] < self.clearance_min

    def words(self):
        return "" if self.now is None else clearance_words(self.now)

    def motion_at(self, z, second_stroke=False):
        """The motion a frame of the Z animation at scan position ``z`` shows: a fast scan's
        stroke (``second_stroke``: updown's way down), a slow scan's Z steps over the pocket
        whose window holds z (the fork advanced by the jab, as the robot makes them), else a
        stroke of the fork in its start pose (between scanned pockets)."""
        strokes = [m for m in self.motions if m.kind == core.STROKE]
        if strokes:
            return strokes[min(len(strokes) - 1, 1 if second_stroke else 0)]
        for m in self.motions:
            if m.kind == core.STEPS and min(m.start, m.end) <= z <= max(m.start, m.end):
                return m
        return core.Motion(core.STROKE, "between pockets", None, z, z)

    def pocket_motion(self, kind, slot, z, advance, turn_range):
        """A pocket's jab (``kind`` JAB) or sweep (SWEEP) as the report measured it; made
        from the frame's values when the report has none (a pocket it did not check)."""
        for m in self.motions:
            if m.kind == kind and m.slot == slot:
                return m
        if kind == core.JAB:
            return core.Motion(core.JAB, f"slot {slot} jab", slot, 0.0, advance, z)
        return core.Motion(core.SWEEP, f"slot {slot} sweep", slot, turn_range[0], turn_range[1],
                           z, advance)


def fork_objects(doc):
    """The document objects that draw the robot's fork (the link carrying the scanner)."""
    from ..cad.robot import SCANNER_LINK

    return [o for o in doc.Objects
            if "RobotLink" in o.PropertiesList and o.RobotLink == SCANNER_LINK]


class ForkColour:
    """The fork drawn red while a frame is closer than clearance_min (``show(contact)``), its
    own colours put back by ``restore``; ``release`` forgets them (the document is closing:
    its views go with it and must not be written)."""

    def __init__(self, doc):
        self.saved = []
        for obj in fork_objects(doc):
            view = getattr(obj, "ViewObject", None)
            # FreeCAD 1.0 lists ShapeAppearance, not ShapeColor and DiffuseColor, among the
            # properties; both are still there to read and set.
            if view is not None and hasattr(view, "ShapeColor"):
                self.saved.append((view, tuple(view.ShapeColor), list(view.DiffuseColor)))
        self.red = False

    def show(self, contact):
        """Red while ``contact``, else the fork's own colours (set only on a change)."""
        if bool(contact) == self.red:
            return
        self.red = bool(contact)
        for view, shape, diffuse in self.saved:
            if self.red:
                view.ShapeColor = FORK_CONTACT
                # FreeCAD 1.0 keeps a link's per-face colours over its ShapeColor (its
                # ShapeAppearance): the whole shape red, face by face too. The fourth value is
                # the fork's own (a transparency in 0.20 and 1.0.0, an alpha in later ones).
                fourth = diffuse[0][3] if diffuse and len(diffuse[0]) > 3 else 0.0
                view.DiffuseColor = [(*FORK_CONTACT, fourth)]
            else:
                view.ShapeColor = shape
                view.DiffuseColor = diffuse

    def restore(self):
        """The fork's own colours again (once)."""
        self.show(False)
        self.saved = []

    def release(self):
        self.saved = []
        self.red = False


CONTACT_STYLE = "color: #c01010; font-weight: bold;"


def clearance_labels(live):
    """(now, least): labels for the clearance at the frame shown (``show_clearance`` fills it)
    and the least over the whole scan with clearance_min, from a ``LiveClearance`` (or None)."""
    now = QtGui.QLabel("")
    now.setWordWrap(True)
    least = QtGui.QLabel("")
    least.setWordWrap(True)
    if live is None:
        return now, least
    now.setToolTip("SPEC §15: the least distance between the robot (its URDF's collision "
                   "geometry) and every wafer at this frame; red, and the fork red in the 3D "
                   f"view, while closer than clearance_min {live.clearance_min:g} mm")
    closest = live.least
    if closest is not None:
        from ..core.scan.clearance import describe

        least.setText(f"{closest.distance:.3f} mm, min {live.clearance_min:g} mm")
        least.setToolTip(f"The least along the whole scan: {describe(closest)}; "
                         f"{len(live.report.contacts)} contact(s) under clearance_min "
                         f"{live.clearance_min:g} mm")
        if live.report.contacts:
            least.setStyleSheet(CONTACT_STYLE)
    return now, least


def show_clearance(label, live):
    """The frame's clearance in ``label`` (set only on a change: a label set, even to the same
    text, lays the panel out again), red while a contact."""
    if live is None:
        return
    text = live.words()
    if text != label.text():
        label.setText(text)
        style = CONTACT_STYLE if live.contact else ""
        if style != label.styleSheet():
            label.setStyleSheet(style)
