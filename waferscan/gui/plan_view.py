"""A slow scan's pocket seen from above (SPEC §13): the wafer's outline (and where a seated wafer
would be), the beam at the start pose, at the jab's first contact and deepest point, and at the
sweep's first and last blocked angles, with the points where it met the wafer, and where the
sweep turned a tine into the wafer, and the region the fork's collision boxes swept in the
jab and the sweep (SPEC §15: where the fork went, against the wafer). Drawn from
``core.scan.pocket_plan`` only; a slot chooser picks the pocket."""

from __future__ import annotations

from PySide import QtCore, QtGui

from ..core.scan import pocket_plan as plans

# (pen colour, pen style, width) of each beam; the contact points are dots of the same colour.
BEAM_STYLES = {
    plans.START: ((110, 110, 110), QtCore.Qt.DashLine, 1.5),
    plans.DEEPEST: ((60, 60, 60), QtCore.Qt.DotLine, 1.5),
    plans.FRONT: ((215, 25, 25), QtCore.Qt.SolidLine, 2.5),
    plans.SWEEP_FIRST: ((30, 80, 220), QtCore.Qt.SolidLine, 2.5),
    plans.SWEEP_LAST: ((0, 150, 110), QtCore.Qt.SolidLine, 2.5),
}
SEATED = (150, 150, 150)   # a seated wafer's outline, dashed
STRIKE = (190, 0, 110)     # a tine's path inside the wafer during the sweep (a fork strikes it)
WRIST = (120, 60, 0)
FORK = (110, 70, 170)      # the region the fork's parts swept: violet, filled see-through
FORK_FILL_ALPHA = 60
CONTACT_RADIUS_PX = 4.5
MARGIN_PX = 18


class PlanCanvas(QtGui.QWidget):
    """Paints one PocketPlan, fitted to its wafers and beams, the opening at the bottom (the
    robot's side). ``drawn`` lists what the last paint drew: (what, label) pairs."""

    def __init__(self, colours, parent=None):
        super().__init__(parent)
        self.colours = colours
        self.plan = None
        self.state = None
        self.swept = ()  # the fork's parts' swept regions (pocket_plan.PlanSwept)
        self.drawn = []
        self.legend_box = None  # (x, y, width, height) of the legend, as last painted
        self.setMinimumSize(260, 260)
        self.setToolTip("The pocket seen from above, the carrier's opening at the bottom: the "
                        "wafer (filled), a seated wafer (dashed), the beam at the start pose, at "
                        "the jab's first contact (red) and at the sweep's first (blue) and last "
                        "(green) blocked angles, a tine's path inside the wafer (crimson: a real "
                        "fork would strike it), the region the fork's tines swept in the jab "
                        "and the sweep (violet); dots: where the beam met the wafer")

    def set_plan(self, plan, state, swept=()):
        """Show ``plan`` (a PocketPlan) of a slot in ``state``, with the fork's ``swept``
        regions (PlanSwept)."""
        self.plan, self.state, self.swept = plan, state, tuple(swept)
        self.update()

    def fork_path(self, swept):
        """The outline of a part's swept region as a QPainterPath in widget pixels: the union
        of its convex pieces."""
        path = QtGui.QPainterPath()
        path.setFillRule(QtCore.Qt.WindingFill)
        for piece in swept.pieces:
            path.addPolygon(QtGui.QPolygonF([QtCore.QPointF(*self.to_pixel(*p)) for p in piece]))
            path.closeSubpath()
        return path.simplified()

    def _bounds(self):
        plan = self.plan
        us, vs = [], []
        for disc in (plan.seated, *plan.wafers):
            us += [disc.center[0] - disc.radius, disc.center[0] + disc.radius]
            vs += [disc.center[1] - disc.radius, disc.center[1] + disc.radius]
        for beam in plan.beams:
            for u, v in beam.ends:
                us.append(u)
                vs.append(v)
        u0, u1, v0, v1 = min(us), max(us), min(vs), max(vs)
        if self.swept:
            # The fork's swept regions too, as far as a wafer's radius beyond the rest: the
            # tines straddling the wafer show whole, the palm at the wrist stays off the page.
            reach = max(d.radius for d in (plan.seated, *plan.wafers))
            points = [p for s in self.swept for piece in s.pieces for p in piece]
            u0 = min(u0, max(min(p[0] for p in points), u0 - reach))
            u1 = max(u1, min(max(p[0] for p in points), u1 + reach))
            v0 = min(v0, max(min(p[1] for p in points), v0 - reach))
            v1 = max(v1, min(max(p[1] for p in points), v1 + reach))
        return u0, u1, v0, v1

    def legend(self):
        """What the line styles and colours mean, for what this plan draws."""
        plan = self.plan
        legend = "dashed: start pose and a seated wafer · dotted: jab's deepest · red: front"
        if plan.wrist is not None:
            legend += " · blue/green: sweep's first/last"
        if plan.strikes:
            legend += " · crimson: a tine inside the wafer"
        if self.swept:
            legend += " · violet: where the fork went"
        return legend

    def _wrapped_height(self, text):
        """The height ``text`` takes wrapped onto lines of the widget's width."""
        metrics = QtGui.QFontMetricsF(self._small_font())
        return metrics.boundingRect(QtCore.QRectF(0, 0, self.width() - 8, 1000),
                                    QtCore.Qt.AlignCenter | QtCore.Qt.TextWordWrap,
                                    text).height()

    def _legend_rect(self):
        """Where the legend goes: the bottom of the widget, wrapped onto as many lines as its
        width needs (one line at 900 px, three at the dialog's default size)."""
        needed = self._wrapped_height(self.legend())
        return QtCore.QRectF(4, self.height() - needed - 2, self.width() - 8, needed)

    def _title_rect(self):
        """Where the title goes: the top, wrapped as the legend is."""
        return QtCore.QRectF(4, 2, self.width() - 8, self._wrapped_height(self.plan.title))

    def _small_font(self):
        small = QtGui.QFont(self.font())
        small.setPointSize(7)
        return small

    def to_pixel(self, u, v):
        """The widget pixel (x, y) of the plan point (u, v) mm, as last fitted."""
        u0, u1, v0, v1 = self._bounds()
        top = MARGIN_PX + self._title_rect().height()  # the title's lines
        width = self.width() - 2 * MARGIN_PX
        # and the legend's lines at the bottom
        height = self.height() - top - MARGIN_PX - self._legend_rect().height()
        scale = min(width / max(u1 - u0, 1e-9), height / max(v1 - v0, 1e-9))
        x0 = MARGIN_PX + 0.5 * (width - scale * (u1 - u0))
        y0 = top + 0.5 * (height - scale * (v1 - v0))
        return (x0 + (u - u0) * scale, y0 + (v1 - v) * scale)

    def scale(self):
        """Pixels per mm of the current fit."""
        a, b = self.to_pixel(0.0, 0.0), self.to_pixel(1.0, 0.0)
        return b[0] - a[0]

    def paintEvent(self, event):  # noqa: N802 (Qt's name)
        painter = QtGui.QPainter(self)
        painter.setRenderHint(QtGui.QPainter.Antialiasing)
        painter.fillRect(self.rect(), QtGui.QColor(255, 255, 255))
        self.drawn = []
        painter.setFont(self._small_font())
        if self.plan is None:
            painter.drawText(self.rect(), QtCore.Qt.AlignCenter, "no pocket was probed")
            painter.end()
            return
        plan, k = self.plan, self.scale()

        def point(p):
            return QtCore.QPointF(*self.to_pixel(*p))

        # A seated wafer's outline, dashed: what the jab and the sweep are compared with.
        pen = QtGui.QPen(QtGui.QColor(*SEATED), 1.2, QtCore.Qt.DashLine)
        painter.setPen(pen)
        painter.setBrush(QtCore.Qt.NoBrush)
        painter.drawEllipse(point(plan.seated.center), plan.seated.radius * k,
                            plan.seated.radius * k)
        self.drawn.append(("seated", plan.seated.name))
        # The wafers the beam can reach at this height, filled in the slot's colour.
        fill = QtGui.QColor(*self.colours.get(self.state, (200, 200, 200)))
        for disc in plan.wafers:
            painter.setPen(QtGui.QPen(fill.darker(150), 1.5))
            light = QtGui.QColor(fill)
            light.setAlpha(110)
            painter.setBrush(light)
            painter.drawEllipse(point(disc.center), disc.radius * k, disc.radius * k)
            self.drawn.append(("wafer", disc.name))
        painter.setBrush(QtCore.Qt.NoBrush)
        if plan.wrist is not None:
            x, y = self.to_pixel(*plan.wrist)
            inside = 0 <= x <= self.width() and 0 <= y <= self.height()
            painter.setPen(QtGui.QPen(QtGui.QColor(*WRIST), 1.5))
            if inside:
                painter.drawLine(QtCore.QPointF(x - 5, y - 5), QtCore.QPointF(x + 5, y + 5))
                painter.drawLine(QtCore.QPointF(x - 5, y + 5), QtCore.QPointF(x + 5, y - 5))
            self.drawn.append(("wrist", "inside" if inside else "below"))
        # Where the fork's parts went in the jab and the sweep, under the beams (SPEC §15).
        fork = QtGui.QColor(*FORK)
        fill = QtGui.QColor(fork)
        fill.setAlpha(FORK_FILL_ALPHA)
        if self.swept:  # kept off the title and the legend: the fork runs off the page
            top = self._title_rect().bottom() + 2
            painter.setClipRect(QtCore.QRectF(0, top, self.width(),
                                              self._legend_rect().top() - 2 - top))
        for swept in self.swept:
            painter.setPen(QtGui.QPen(fork, 1.2))
            painter.setBrush(fill)
            painter.drawPath(self.fork_path(swept))
            self.drawn.append(("fork", swept.part))
        painter.setClipping(False)
        painter.setBrush(QtCore.Qt.NoBrush)
        # Where the sweep turns a tine into the wafer: its path there, under the beams.
        painter.setPen(QtGui.QPen(QtGui.QColor(*STRIKE), 3.5))
        for arc in plan.strikes:
            painter.drawPolyline(QtGui.QPolygonF([point(p) for p in arc.points]))
            self.drawn.append(("strike", arc.label))
        for beam in plan.beams:
            colour, style, width = BEAM_STYLES[beam.role]
            painter.setPen(QtGui.QPen(QtGui.QColor(*colour), width, style))
            painter.drawLine(point(beam.ends[0]), point(beam.ends[1]))
            self.drawn.append((beam.role, beam.label))
        # The contact points last, over everything, with their labels.
        for beam in plan.beams:
            if beam.contact is None:
                continue
            colour = QtGui.QColor(*BEAM_STYLES[beam.role][0])
            painter.setPen(QtGui.QPen(colour.darker(130), 1.0))
            painter.setBrush(colour)
            at = point(beam.contact)
            painter.drawEllipse(at, CONTACT_RADIUS_PX, CONTACT_RADIUS_PX)
            painter.setBrush(QtCore.Qt.NoBrush)
            painter.setPen(colour.darker(140))
            right = at.x() < self.width() / 2
            below = beam.role == plans.FRONT  # the front's label clear of the rim above it
            box = QtCore.QRectF(at.x() + (8 if right else -128), at.y() + (7 if below else -17),
                                120, 14)
            align = (QtCore.Qt.AlignLeft if right else QtCore.Qt.AlignRight) | \
                QtCore.Qt.AlignVCenter
            shown = painter.boundingRect(box, align, beam.label).adjusted(-2, 0, 2, 0)
            painter.fillRect(shown, QtGui.QColor(255, 255, 255, 210))  # readable on the wafer
            painter.drawText(box, align, beam.label)
            self.drawn.append(("contact", beam.label))
        self._scale_bar(painter, k)
        painter.setPen(QtGui.QColor(30, 30, 30))
        painter.drawText(self._title_rect(), QtCore.Qt.AlignCenter | QtCore.Qt.TextWordWrap,
                         plan.title)
        self.drawn.append(("title", plan.title))
        painter.setPen(QtGui.QColor(80, 80, 80))
        box = self._legend_rect()
        painter.drawText(box, QtCore.Qt.AlignCenter | QtCore.Qt.TextWordWrap, self.legend())
        self.legend_box = (box.x(), box.y(), box.width(), box.height())
        self.drawn.append(("legend", self.legend()))
        painter.end()


    def _scale_bar(self, painter, k):
        """A bar of a round length (10, 20, 50, 100 mm…), at least 40 px, top left (clear of
        the wafer, which is round, and of the beams, which are at the bottom)."""
        steps = [m * 10.0 ** e for e in range(1, 7) for m in (1.0, 2.0, 5.0)]
        length = next((s for s in steps if s * k >= 40.0), steps[-1])
        x, y = MARGIN_PX, MARGIN_PX + self._title_rect().height() + 18
        painter.setPen(QtGui.QPen(QtGui.QColor(40, 40, 40), 1.5))
        painter.drawLine(QtCore.QPointF(x, y), QtCore.QPointF(x + length * k, y))
        for end in (x, x + length * k):
            painter.drawLine(QtCore.QPointF(end, y - 3), QtCore.QPointF(end, y + 3))
        painter.drawText(QtCore.QRectF(x, y - 16, 80, 14), QtCore.Qt.AlignLeft,
                         f"{length:g} mm")
        self.drawn.append(("scale bar", f"{length:g} mm"))


class PocketPlanView(QtGui.QWidget):
    """A slot chooser over a PlanCanvas: each probed pocket of a slow scan, seen from above."""

    def __init__(self, result, colours, parent=None, doc=None):
        super().__init__(parent)
        self.result = result
        self.doc = doc  # the document scanned (its robot's fork is drawn), or None
        self._footprints = None
        self.states = {s.slot: s.state for s in result.slot_map.slots}
        self.chooser = QtGui.QComboBox(self)
        self.chooser.setToolTip("The pocket to show: its jab and sweep seen from above")
        self.slots = [p.slot for p in result.pockets]
        for slot in self.slots:
            self.chooser.addItem(f"slot {slot}  ({self.states.get(slot)})", slot)
        self.canvas = PlanCanvas(colours, self)
        top = QtGui.QHBoxLayout()
        top.addWidget(QtGui.QLabel("Pocket seen from above:", self))
        top.addWidget(self.chooser, 1)
        layout = QtGui.QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(top)
        layout.addWidget(self.canvas, 1)
        self.chooser.currentIndexChanged.connect(self._chosen)
        first = plans.chosen_slots(result, 1)
        self.show_slot(first[0] if first else (self.slots[0] if self.slots else None))

    def show_slot(self, slot):
        """Show the pocket of ``slot`` (a probed one)."""
        if slot is None:
            self.canvas.set_plan(None, None)
            return
        index = self.slots.index(slot)
        if self.chooser.currentIndex() != index:
            self.chooser.setCurrentIndex(index)  # calls _chosen
        else:
            self._chosen(index)

    def _chosen(self, index):
        slot = self.slots[index]
        self.canvas.set_plan(plans.pocket_plan(self.result, slot), self.states.get(slot),
                             plans.fork_swept(self.result, slot, self.footprints()))

    def footprints(self):
        """The fork's collision boxes seen from above in the start pose (read once), or []
        without a robot (or pinocchio)."""
        if self._footprints is None:
            from ..robot.clearance import fork_footprints
            from .clearance_view import scan_body

            body = scan_body(self.result, self.doc)
            self._footprints = fork_footprints(body) if body is not None else []
        return self._footprints
