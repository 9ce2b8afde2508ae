"""A side view of the scanned carrier, as the paper's Fig. 6: every slot's seat drawn as its pair
of supports, and every sensor run drawn at its Z against them, coloured by the state of the slot
that claimed it. Drawn from the ScanResult only."""

from __future__ import annotations

from PySide import QtCore, QtGui

from ..core.mapping import STATE_NAMES

UNCLAIMED = (90, 90, 90)  # a run no slot claimed


class SideView(QtGui.QWidget):
    """Slots and sensor runs on a common Z scale (Z up)."""

    def __init__(self, result, colours, parent=None):
        super().__init__(parent)
        self.result, self.colours = result, colours
        self.carrier = result.layout.scanned_carrier
        owner = {}
        for slot in result.slot_map.slots:
            for index in slot.runs:
                owner[index] = slot
        self.owner = owner
        self.setMinimumSize(260, 300)  # the dialog fits a 1024×700 screen
        self.setToolTip("Side view of the carrier: the slots' supports (grey) and the sensor "
                        "runs (bars, IN to OUT) coloured by slot state")

    def z_range(self):
        c = self.carrier
        low = c.seat_z(1) - 0.6 * c.pitch
        high = c.seat_z(c.slot_count) + 0.8 * c.pitch
        for run in self.result.runs:
            low, high = min(low, run.bottom - 1.0), max(high, run.top + 1.0)
        return low, high

    def paintEvent(self, event):  # noqa: N802 (Qt's name)
        painter = QtGui.QPainter(self)
        painter.setRenderHint(QtGui.QPainter.Antialiasing)
        painter.fillRect(self.rect(), QtGui.QColor(255, 255, 255))
        low, high = self.z_range()
        top_px, bottom_px = 14, self.height() - 22
        scale = (bottom_px - top_px) / (high - low)

        def y(z):
            return bottom_px - (z - low) * scale

        left, right = 44, self.width() - 150  # the carrier's opening, seen from the side
        small = painter.font()
        small.setPointSize(7)
        painter.setFont(small)
        # The carrier's walls and every slot's supports at its seat.
        painter.setPen(QtGui.QPen(QtGui.QColor(120, 120, 120), 2))
        painter.drawLine(left - 6, y(high), left - 6, y(low))
        painter.drawLine(right + 6, y(high), right + 6, y(low))
        label_every = 1 if self.carrier.pitch * scale >= 11 else 5
        for slot in range(1, self.carrier.slot_count + 1):
            seat = self.carrier.seat_z(slot)
            painter.setPen(QtGui.QPen(QtGui.QColor(150, 150, 150), 2))
            painter.drawLine(left - 6, y(seat), left + 14, y(seat))
            painter.drawLine(right - 14, y(seat), right + 6, y(seat))
            if slot % label_every == 0 or slot == 1:
                painter.setPen(QtGui.QColor(60, 60, 60))
                painter.drawText(QtCore.QRectF(2, y(seat) - 7, left - 12, 14),
                                 QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter, str(slot))
        # The runs: a bar from IN to OUT (at least 4 px, so a thin wafer stays visible).
        for index, run in enumerate(self.result.runs):
            slot = self.owner.get(index)
            colour = QtGui.QColor(*(self.colours[slot.state] if slot else UNCLAIMED))
            top, bottom = y(run.top), y(run.bottom)
            bar = QtCore.QRectF(left + 16, bottom - max(bottom - top, 4.0), right - left - 32,
                                max(bottom - top, 4.0))
            painter.fillRect(bar, colour)
            if bar.height() > 8:
                painter.setPen(colour.darker(160))
                painter.drawRect(bar)
            painter.setPen(QtGui.QColor(30, 30, 30))
            what = f"{run.z_in:.2f}→{run.z_out:.2f}"
            if slot is not None and slot.state != 1:
                what += f"  {STATE_NAMES[slot.state]}"
            painter.drawText(QtCore.QRectF(right + 10, (top + bottom) / 2 - 7, 140, 14),
                             QtCore.Qt.AlignLeft | QtCore.Qt.AlignVCenter, what)
        painter.setPen(QtGui.QColor(60, 60, 60))
        painter.drawText(QtCore.QRectF(0, self.height() - 18, self.width(), 16),
                         QtCore.Qt.AlignCenter,
                         f"{self.carrier.name}: Z {low:.0f} to {high:.0f} mm, slots at their "
                         f"seats; bars are the sensor runs (IN→OUT)")
        painter.end()
