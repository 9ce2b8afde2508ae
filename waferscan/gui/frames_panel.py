"""The "Set up carrier and sensor" task panel (issue 27 item 8): the carrier's slots (count,
pitch, slot 1's seat) and the sensor's beam (emitter, receiver) shown in global coordinates in
the user's units, picked in the 3D view, and the slots derived from the cell's geometry
(``cad.carrier_geometry``) shown for the user to accept. OK writes them into each object's own
frame as one undo step, through one recorded line (``set_frames``), as a script would."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from ..addon import icon_path
from ..cad import carrier_geometry, roles
from ..cad.reader import DocumentScene
from ..core.errors import InputError, WaferScanError
from .inputs import format_length, length_input, value_in
from .qt import ClosableTaskPanel
from .session import (ask, check_no_other_task_panel, doc_ref, record, report,
                      show_task_panel, transaction)

__all__ = ["FramesTaskPanel", "open_frames_panel", "set_frames", "set_frames_call",
           "UNDO_NAME"]

UNDO_NAME = "Set carrier and sensor frames"
POINTS = {"seat": "Slot 1's seat", "emitter": "Emitter", "receiver": "Receiver"}
PICK_HINTS = {
    "seat": "Click slot 1's wafer, or the top of its support, in the 3D view.",
    "emitter": "Click where the beam leaves the sensor, in the 3D view.",
    "receiver": "Click where the beam arrives, in the 3D view.",
}
PICK_TIPS = {
    "seat": "Then click slot 1's wafer (its bottom centre is taken) or the top of slot 1's "
            "support (its height is taken; X and Y are kept)",
    "emitter": "Then click the point the beam leaves from in the 3D view",
    "receiver": "Then click the point the beam arrives at in the 3D view",
}


def set_frames(doc, carrier=None, slot_count=None, pitch=None, seat=None, front=None,
               scanner=None, emitter=None, receiver=None):
    """Set the carrier's slots (``slot_count``, ``pitch``, slot 1's ``seat``, and the ``front``
    its opening faces, global XY) and the scanner's beam (``emitter`` to ``receiver``), all in
    global coordinates, written into each object's own frame: one undo step. What is not given
    is left as it is."""
    if carrier is not None:
        if slot_count is None or int(slot_count) < 1:
            raise InputError(carrier.Label, None, "give the carrier at least one slot")
        if pitch is None or value_in(pitch, "mm", "pitch") <= 0.0:
            raise InputError(carrier.Label, None, "the pitch must be more than 0")
    if scanner is not None and (App.Vector(emitter) - App.Vector(receiver)).Length == 0.0:
        raise InputError(scanner.Label, None, "the beam's emitter and receiver coincide")
    with transaction(doc, UNDO_NAME):
        if carrier is not None:
            carrier_geometry.set_slot_frame(carrier, int(slot_count), value_in(pitch, "mm", "pitch"), seat, front)
        if scanner is not None:
            carrier_geometry.set_beam_ends(scanner, emitter, receiver)
    doc.recompute()


def open_frames_panel(doc):
    """The "Set up carrier and sensor" panel on ``doc``'s carrier and scanner; its OK records
    the line of Python that sets them (``set_frames``). Returns the panel."""
    check_no_other_task_panel()
    return show_task_panel(FramesTaskPanel(doc))


def _vector_ref(v):
    return f"App.Vector({v.x!r}, {v.y!r}, {v.z!r})"


def set_frames_call(doc, carrier=None, slot_count=None, pitch=None, seat=None, front=None,
                    scanner=None, emitter=None, receiver=None):
    """The recorded line of ``set_frames`` (the "Set up carrier and sensor" panel's OK): the
    pitch as a quantity in mm, points as App.Vectors in mm, global."""
    ref = doc_ref(doc)
    arguments = [ref]
    if carrier is not None:
        mm = value_in(pitch, "mm", "pitch")
        arguments += [f"carrier={ref}.getObject({carrier.Name!r})",
                      f"slot_count={int(slot_count)}",
                      f"pitch=App.Units.Quantity('{mm!r} mm')", f"seat={_vector_ref(seat)}"]
        if front is not None:
            arguments.append(f"front=({float(front[0])!r}, {float(front[1])!r})")
    if scanner is not None:
        arguments += [f"scanner={ref}.getObject({scanner.Name!r})",
                      f"emitter={_vector_ref(emitter)}", f"receiver={_vector_ref(receiver)}"]
    return f"set_frames({', '.join(arguments)})"


def _wrapped_label(text=""):
    label = QtGui.QLabel(text)
    label.setWordWrap(True)
    return label


class _Picks:
    """A selection observer: a click in the 3D view selects a sub-element with the point
    clicked, which FreeCAD hands to ``addSelection``."""

    def __init__(self, then):
        self.then = then

    def addSelection(self, doc, obj, sub, point):  # noqa: N802 (FreeCAD's name)
        self.then(doc, obj, sub, App.Vector(*point))


class _PointFields:
    """Three length fields (X, Y, Z, global, in the user's units) and a Pick button."""

    def __init__(self, panel, key, layout):
        self.key = key
        header = QtGui.QHBoxLayout()
        header.addWidget(QtGui.QLabel(f"<b>{POINTS[key]}</b>"), 1)
        self.pick = QtGui.QPushButton("Pick")
        self.pick.setCheckable(True)
        self.pick.setToolTip(PICK_TIPS[key])
        self.pick.clicked.connect(lambda checked: panel.start_pick(key if checked else None))
        header.addWidget(self.pick)
        layout.addLayout(header)
        grid = QtGui.QGridLayout()
        self.fields = []
        for row, axis in enumerate("XYZ"):
            field = length_input(0.0, f"{POINTS[key]}'s global {axis}", -1e6, 1e6)
            grid.addWidget(QtGui.QLabel(axis), row, 0)
            grid.addWidget(field, row, 1)
            self.fields.append(field)
        layout.addLayout(grid)

    def set(self, point):
        for field, value in zip(self.fields, (point.x, point.y, point.z)):
            field.set_mm(value)

    def value(self):
        """The point in mm (App.Vector); ValueError naming the field when one is not a length."""
        values = []
        for axis, field in zip("XYZ", self.fields):
            try:
                values.append(field.value_mm())
            except ValueError as exc:
                raise ValueError(f"{POINTS[self.key]} {axis}: {exc}") from None
        return App.Vector(*values)


class FramesTaskPanel(ClosableTaskPanel):
    """Slots and beam, global, picked or typed; the derived slots shown to accept; OK or
    Cancel."""

    def __init__(self, doc):
        scene = DocumentScene.of(doc)
        if not scene.carriers and not scene.scanners:
            raise InputError(doc.Label, None, "tag the carrier (Tag as carrier) and the sensor "
                             "(Tag as scanner) first")
        self.doc = doc
        self.carrier = _chosen_carrier(doc, scene)
        self.scanner = scene.scanners[0].obj if scene.scanners else None
        self.picking = None
        self.points = {}
        self.form = QtGui.QWidget()
        self.form.setWindowTitle("Set up carrier and sensor")
        self.form.setWindowIcon(QtGui.QIcon(icon_path("WaferScan_SetFrames.svg")))
        layout = QtGui.QVBoxLayout(self.form)
        intro = _wrapped_label("Points are global, in your units. Pick, then click in the 3D "
                              "view; OK writes them into each object's own frame.")
        layout.addWidget(intro)
        if self.carrier is not None:
            layout.addWidget(self._carrier_box())
        if self.scanner is not None:
            layout.addWidget(self._sensor_box())
        # Room for the longest message from the start: a wrapped label that grows later
        # squeezes the others in FreeCAD's task box, cutting off their last lines.
        self.status = _wrapped_label()
        self.status.setMinimumHeight(4 * self.status.fontMetrics().lineSpacing())
        self.alive_while_shown = self.status
        layout.addWidget(self.status)
        layout.addStretch(1)
        self._show_document_values()
        self._observer = None
        self._picks = _Picks(self.picked)
        Gui.Selection.addObserver(self._picks)
        self.follow_document(doc)

    # --- building ---------------------------------------------------------------------------

    def _carrier_box(self):
        box = QtGui.QGroupBox(f"Carrier: {self.carrier.Label}")
        layout = QtGui.QVBoxLayout(box)
        self.proposal = carrier_geometry.propose_slots(self.carrier)
        self.derived = _wrapped_label(_proposal_text(self.proposal))
        layout.addWidget(self.derived)
        self.use_derived = QtGui.QPushButton("Use derived")
        self.use_derived.setToolTip("Fill in the slot count, pitch and slot 1's seat the "
                                    "geometry gives; OK writes them")
        self.use_derived.setEnabled(self.proposal.slot_count is not None)
        self.use_derived.clicked.connect(self.accept_derived)
        layout.addWidget(self.use_derived)
        grid = QtGui.QGridLayout()
        self.slot_count = QtGui.QSpinBox()
        self.slot_count.setRange(1, 1000)
        self.slot_count.setToolTip("How many slots the carrier has, slot 1 the bottom one")
        self.pitch = length_input(10.0, "The distance between two slots' seats", 1e-3, 1e4)
        grid.addWidget(QtGui.QLabel("Slots"), 0, 0)
        grid.addWidget(self.slot_count, 0, 1)
        grid.addWidget(QtGui.QLabel("Pitch"), 1, 0)
        grid.addWidget(self.pitch, 1, 1)
        layout.addLayout(grid)
        self.points["seat"] = _PointFields(self, "seat", layout)
        self.face_beam = QtGui.QCheckBox("Front faces the beam")
        self.face_beam.setToolTip("Turn the slots so that the carrier's opening (its front, "
                                  "towards the robot) faces the sensor's beam")
        self.face_beam.setChecked(self.scanner is not None)
        self.face_beam.setEnabled(self.scanner is not None)
        layout.addWidget(self.face_beam)
        return box

    def _sensor_box(self):
        box = QtGui.QGroupBox(f"Sensor: {self.scanner.Label}")
        layout = QtGui.QVBoxLayout(box)
        self.points["emitter"] = _PointFields(self, "emitter", layout)
        self.points["receiver"] = _PointFields(self, "receiver", layout)
        return box

    def _show_document_values(self):
        """The document's values now, global."""
        if self.carrier is not None:
            holder = roles.role_holder(self.carrier)
            self.slot_count.setValue(int(holder.SlotCount))
            self.pitch.set_mm(float(holder.Pitch))
            anchor = carrier_geometry.instance_of(self.carrier).placement().multiply(
                holder.SlotOrigin)
            self.points["seat"].set(anchor.Base)
        if self.scanner is not None:
            holder = roles.role_holder(self.scanner)
            placement = carrier_geometry.instance_of(self.scanner).placement()
            self.points["emitter"].set(placement.multVec(App.Vector(holder.Emitter)))
            self.points["receiver"].set(placement.multVec(App.Vector(holder.Receiver)))

    # --- what the user does -----------------------------------------------------------------

    def accept_derived(self):
        """Fill in the derived slot count, pitch and seat (the document changes on OK)."""
        proposal = self.proposal
        self.slot_count.setValue(proposal.slot_count)
        self.pitch.set_mm(proposal.pitch)
        self.points["seat"].set(App.Vector(*proposal.seat))
        self.status.setText("Derived slots filled in: OK writes them.")

    def start_pick(self, key):
        """Take the next point clicked in the 3D view for ``key`` (None: stop picking)."""
        self.picking = key
        for name, point in self.points.items():
            point.pick.setChecked(name == key)
        self.status.setText(PICK_HINTS[key] if key else "")
        bar = Gui.getMainWindow().statusBar()
        if key:  # where FreeCAD's own tools say what to click
            bar.showMessage(f"WaferScan: {PICK_TIPS[key]}", 15000)
        elif bar.currentMessage().startswith("WaferScan: Then click"):
            bar.clearMessage()

    def picked(self, doc_name, obj_name, sub, point):
        """A click in the 3D view (a selection with its point, global) while picking."""
        key = self.picking
        if key is None or doc_name != self.doc.Name or not self.is_open():
            return
        # A click in the tree selects a whole object, with no point (FreeCAD hands 0, 0, 0):
        # only a wafer's seat can be taken from it; else the pick waits for the 3D view.
        tree_click = not sub
        if tree_click and not (key == "seat" and self._is_wafer(obj_name)):
            self.status.setText(f"{POINTS[key]}: that was a click in the tree, which gives no "
                                "point: click the point in the 3D view.")
            return
        self.start_pick(None)
        fields = self.points[key]
        if key != "seat":
            fields.set(point)
            self.status.setText(f"{POINTS[key]} picked: {_point_text(point)}.")
            return
        root = self.doc.getObject(obj_name)
        path = sub.rsplit(".", 1)[0] + "." if "." in sub else ""
        clicked = root.getSubObject(path, retType=1) if path else root
        if clicked is not None and roles.role_of(clicked) == roles.WAFER:
            import Part

            from ..cad.disc import NotADisc, disc_of
            try:
                center = App.Vector(*disc_of(Part.getShape(root, path))[0])
            except NotADisc:
                center = None
            if center is not None:
                fields.set(center)
                self.status.setText(f"Slot 1's seat: {clicked.Label}'s bottom centre.")
                return
        seat = fields.value()
        seat.z = point.z
        fields.set(seat)
        self.status.setText(f"Slot 1's seat height: {format_length(point.z)}, picked; X and Y "
                            "kept.")

    def _is_wafer(self, obj_name):
        obj = self.doc.getObject(obj_name)
        return obj is not None and roles.role_of(obj) == roles.WAFER

    def values(self):
        """The panel's values as ``set_frames``' keyword arguments (ValueError when a field is
        not a length)."""
        found = {}
        if self.carrier is not None:
            try:
                pitch = self.pitch.value_mm()
            except ValueError as exc:
                raise ValueError(f"Pitch: {exc}") from None
            found.update(carrier=self.carrier, slot_count=self.slot_count.value(),
                         pitch=App.Units.Quantity(pitch, App.Units.Length),
                         seat=self.points["seat"].value(), front=None)
        if self.scanner is not None:
            found.update(scanner=self.scanner, emitter=self.points["emitter"].value(),
                         receiver=self.points["receiver"].value())
            if self.carrier is not None and self.face_beam.isChecked():
                found["front"] = carrier_geometry.front_towards(
                    found["seat"], (found["emitter"], found["receiver"]))
        return found

    def accept(self):
        try:
            values = self.values()
        except ValueError as exc:
            report(exc, error=True)
            return False
        try:
            record(set_frames_call(self.doc, **values))
        except WaferScanError as exc:
            report(exc, error=True)
            return False
        return self.reject()

    def getStandardButtons(self):  # noqa: N802 (FreeCAD's name)
        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def shut_down(self):
        self.picking = None
        if self._picks is not None:
            picks, self._picks = self._picks, None
            # Later: FreeCAD may be calling this very observer now.
            QtCore.QTimer.singleShot(0, lambda: Gui.Selection.removeObserver(picks))


def _chosen_carrier(doc, scene):
    """The carrier ScanSettings names, the only one tagged, or the one the user chooses among
    several (as Run scan asks); None without any. InputError when the user cancels."""
    if not scene.carriers:
        return None
    chosen = next((getattr(i.obj, "Carrier", "") for i in scene.settings), "")
    for instance in scene.carriers:
        if instance.obj.Label == chosen:
            return instance.obj
    if len(scene.carriers) == 1:
        return scene.carriers[0].obj
    labels = [i.obj.Label for i in scene.carriers]
    answer = ask(f"{doc.Label} has {len(labels)} objects tagged as carriers: "
                 f"{', '.join(labels)}. Which one is to be set up?",
                 [(label, QtGui.QMessageBox.AcceptRole) for label in labels] +
                 [("Cancel", QtGui.QMessageBox.RejectRole)])
    if answer not in labels:
        raise InputError(doc.Label, None, f"several carriers ({', '.join(labels)}): choose "
                                          "the one to set up")
    return scene.carriers[labels.index(answer)].obj


def _point_text(point):
    return "(" + ", ".join(format_length(v) for v in (point.x, point.y, point.z)) + ")"


def _proposal_text(proposal):
    if proposal.slot_count is None:
        return f"Derived: nothing ({proposal.how})."
    x, y, z = proposal.seat
    return (f"Derived: {proposal.slot_count} slots, pitch {format_length(proposal.pitch)}, "
            f"slot 1's seat at {_point_text(App.Vector(x, y, z))}; from {proposal.how}.")
