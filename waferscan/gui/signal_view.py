"""The sensor's signal in the GUI (SPEC §10): the blocked fraction b(z) against the scan
position, the amplifier's thresholds, the latched edges and a cursor at the beam's position.
Drawn from the ScanResult only (``signal_plot.signal_samples``, the same samples as the
command line's ``--plot``); the GUI computes nothing.

``live_trace(animation)`` is the trace beside the animated scan: it follows the beam, a few
millimetres either side, as the animation moves it. The slot-code dialog shows the whole scan.
"""

from __future__ import annotations

import math

from PySide import QtCore, QtGui

from ..core.scan.sensing import scan_edges
from ..plots.signal import signal_of, signal_samples

TRACE = (30, 100, 200)
ON_EDGE, OFF_EDGE = (40, 150, 60), (140, 70, 170)
THRESHOLD_ON, THRESHOLD_OFF = (200, 40, 40), (230, 130, 30)


class SignalView(QtGui.QWidget):
    """b(z) of a scan result. ``span`` (mm) set: a window that far either side of the cursor;
    None: the whole scan."""

    def __init__(self, result, parent=None, span=None):
        super().__init__(parent)
        self.result = result
        self.z, self.b = signal_samples(result)
        signal = signal_of(result)
        self.thresholds = (signal.threshold_on, signal.threshold_off)
        self.edges = scan_edges(result)
        self.span = span
        self.cursor = None
        self.ticks = []  # (z, label) of the Z ticks, as last painted
        self.setMinimumSize(150, 100)  # fits the scan panel in the default combo view
        spot = result.layout.spot
        what = "an ideal line beam (b is 0 or 1)" if spot is None or spot.ideal else \
            "the share of the beam spot blocked"
        self.setToolTip(f"Blocked fraction b(z): {what}; dashed: the amplifier's thresholds; "
                        f"ticks: the latched ON (green) and OFF (purple) edges")

    def window(self):
        """(low, high) scan Z drawn now."""
        scan = self.result.layout.scan
        if self.span is None or self.cursor is None:
            return scan.start_z, scan.final_z
        return self.cursor - self.span, self.cursor + self.span

    def set_position(self, z):
        """Move the cursor (the beam's scan position) and redraw."""
        self.cursor = z
        self.update()

    def samples_in_window(self):
        """The (z, b) samples drawn now, one past each end so the line reaches the edges."""
        low, high = self.window()
        import numpy as np

        first = max(0, int(np.searchsorted(self.z, low)) - 1)
        last = min(len(self.z), int(np.searchsorted(self.z, high, side="right")) + 1)
        return self.z[first:last], self.b[first:last]

    def paintEvent(self, event):  # noqa: N802 (Qt's name)
        painter = QtGui.QPainter(self)
        painter.setRenderHint(QtGui.QPainter.Antialiasing)
        painter.fillRect(self.rect(), QtGui.QColor(255, 255, 255))
        low, high = self.window()
        left, right, top, bottom = 28, self.width() - 6, 6, self.height() - 28
        width = max(high - low, 1e-9)

        def x(z):
            return left + (z - low) / width * (right - left)

        def y(b):
            return bottom - b * (bottom - top)

        small = painter.font()
        small.setPointSize(7)
        painter.setFont(small)
        painter.setPen(QtGui.QColor(150, 150, 150))
        painter.drawRect(QtCore.QRectF(left, top, right - left, bottom - top))
        for level in (0.0, 0.5, 1.0):
            painter.drawText(QtCore.QRectF(0, y(level) - 6, left - 3, 12),
                             QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter, f"{level:g}")
        on, off = self.thresholds
        for level, colour in ((on, THRESHOLD_ON), (off, THRESHOLD_OFF)):
            pen = QtGui.QPen(QtGui.QColor(*colour), 1, QtCore.Qt.DashLine)
            painter.setPen(pen)
            painter.drawLine(QtCore.QPointF(left, y(level)), QtCore.QPointF(right, y(level)))
        for edge in self.edges:
            if low <= edge["z"] <= high:
                colour = ON_EDGE if edge["edge"] == "on" else OFF_EDGE
                painter.setPen(QtGui.QPen(QtGui.QColor(*colour), 1))
                painter.drawLine(QtCore.QPointF(x(edge["z"]), top),
                                 QtCore.QPointF(x(edge["z"]), top + 8))
        z, b = self.samples_in_window()
        if len(z) > 1:
            path = QtGui.QPainterPath(QtCore.QPointF(x(z[0]), y(b[0])))
            for zi, bi in zip(z[1:], b[1:]):
                path.lineTo(QtCore.QPointF(x(zi), y(bi)))
            painter.setPen(QtGui.QPen(QtGui.QColor(*TRACE), 1.5))
            painter.drawPath(path)
        if self.cursor is not None and low <= self.cursor <= high:
            painter.setPen(QtGui.QPen(QtGui.QColor(0, 0, 0), 1))
            painter.drawLine(QtCore.QPointF(x(self.cursor), top),
                             QtCore.QPointF(x(self.cursor), bottom))
        self._z_ticks(painter, low, high, x, bottom)
        painter.setPen(QtGui.QColor(60, 60, 60))
        painter.drawText(QtCore.QRectF(left, bottom + 13, right - left, 14), QtCore.Qt.AlignCenter,
                         f"b(z), Z {low:.2f} to {high:.2f} mm")
        painter.end()


    def _z_ticks(self, painter, low, high, x, bottom):
        """Ticks and labels of Z (mm) under the plot, at a round step (1, 2 or 5 × 10^k) that
        leaves room for each label."""
        metrics = QtGui.QFontMetricsF(painter.font())
        span = max(high - low, 1e-9)
        pixels = max(x(high) - x(low), 1.0)
        self.ticks = []
        values = labels = ()
        for exponent in range(-3, 7):
            for mantissa in (1.0, 2.0, 5.0):
                step = mantissa * 10.0 ** exponent
                if step / span * pixels < 8.0:
                    # Ticks closer than the 8 px gap alone: no label fits, whatever its width
                    # (measuring each label of every fine step was 16 ms of each frame).
                    continue
                decimals = max(0, -exponent)
                first = math.ceil(low / step - 1e-9)
                values = [k * step for k in range(first, math.floor(high / step + 1e-9) + 1)]
                labels = [f"{v:.{decimals}f}" for v in values]
                widest = max((metrics.horizontalAdvance(t) if hasattr(metrics, "horizontalAdvance")
                              else metrics.width(t) for t in labels), default=0.0)
                if step / span * pixels >= widest + 8.0:
                    break
            else:
                continue
            break
        painter.setPen(QtGui.QColor(110, 110, 110))
        for value, label in zip(values, labels):
            at = x(value)
            painter.drawLine(QtCore.QPointF(at, bottom), QtCore.QPointF(at, bottom + 3))
            painter.drawText(QtCore.QRectF(at - 40, bottom + 2, 80, 11), QtCore.Qt.AlignCenter,
                             label)
            self.ticks.append((value, label))


def live_trace(animation, span=None):
    """A SignalView that follows the animation's beam: ``span`` mm either side (default: the
    spot's height and a wafer's thickness, at least 1.5 mm)."""
    result = animation.result
    if span is None:
        spot = result.layout.spot
        reach = 0.0 if spot is None or spot.ideal else spot.half_height
        span = max(1.5, 2.0 * reach + result.plan.wafer_thickness)
    view = SignalView(result, span=span)
    view.set_position(animation.z)
    animation.moved.connect(lambda frame, z: view.set_position(z))
    return view
