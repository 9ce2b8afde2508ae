"""The workbench's preferences (Edit → Preferences → WaferScan): the mapping tolerances given to
layouts that do not set their own, the sensor defaults of new scan settings (sensor_preferences),
the MCS folder the link panel opens with, and the animation's playback time. They live in
FreeCAD's parameters under ``Mod/WaferScan``."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtGui

from ..core.model import MappingTolerances
from ..core.rules import HALF_THICKNESS_STORED, thickness_tolerance_from_stored
from .qt import alive
from .inputs import folder_row, length_input, length_value, mark, marked_row, set_length
from .sensor_preferences import SensorDefaultsBox, sensor_defaults  # noqa: F401 (for scanning)

PARAMETERS = "User parameter:BaseApp/Preferences/Mod/WaferScan"
_DEFAULTS = MappingTolerances()
PLAYBACK_S = 10.0  # seconds of real time for a whole scan's animation, when nothing is set
POLL_MS = 500  # the MCS panel's polling fallback


def _group():
    return App.ParamGet(PARAMETERS)


# "Half the nominal wafer thickness" is a box of its own (HalfThickness, a bool parameter),
# ThicknessTolerance the length in mm used when it is not ticked (kept while it is). Earlier
# versions stored only ThicknessTolerance, a negative value meaning half the thickness: without
# HalfThickness, that is what is read.
HALF_THICKNESS = "HalfThickness"


def half_thickness(group=None):
    """Whether the preferred thickness tolerance is half the nominal wafer thickness."""
    group = group or _group()
    stored = group.GetFloat("ThicknessTolerance", HALF_THICKNESS_STORED)
    if HALF_THICKNESS in group.GetBools():
        return group.GetBool(HALF_THICKNESS) or stored < 0.0
    return thickness_tolerance_from_stored(stored) is None


def stored_thickness_tolerance():
    """The length (mm) stored for the thickness tolerance, ticked or not; None when none is
    (an earlier version's "half the thickness")."""
    return thickness_tolerance_from_stored(
        _group().GetFloat("ThicknessTolerance", HALF_THICKNESS_STORED))


def mapping_tolerances():
    """The default MappingTolerances: the preferences', FreeCAD's parameters being the store.
    HalfThickness ticked (or an earlier version's negative ThicknessTolerance) is "half the
    nominal thickness" (the core's None)."""
    group = _group()
    return MappingTolerances(
        thickness_tolerance=None if half_thickness(group) else stored_thickness_tolerance(),
        position_tolerance=group.GetFloat("PositionTolerance", _DEFAULTS.position_tolerance),
        protrusion_limit=group.GetFloat("ProtrusionLimit", _DEFAULTS.protrusion_limit))


def mcs_folder():
    return _group().GetString("McsFolder", "")


def playback_seconds():
    """How long the animation of a whole scan lasts, in seconds of real time."""
    return max(0.5, _group().GetFloat("PlaybackSeconds", PLAYBACK_S))


def set_values(thickness_tolerance=None, position_tolerance=None, protrusion_limit=None,
               folder=None, speed=None, half=None):
    """Store the given preferences (None leaves one as it is): ``half`` True or False ticks or
    unticks "half the nominal wafer thickness", ``thickness_tolerance`` (mm) is the tolerance
    used when it is not ticked."""
    group = _group()
    if half is not None:
        group.SetBool(HALF_THICKNESS, bool(half))
    if thickness_tolerance is not None:
        if thickness_tolerance < 0.0:
            raise ValueError(f"a thickness tolerance cannot be negative, got "
                             f"{thickness_tolerance:g} mm (half=True: half the thickness)")
        group.SetFloat("ThicknessTolerance", float(thickness_tolerance))
    if position_tolerance is not None:
        group.SetFloat("PositionTolerance", float(position_tolerance))
    if protrusion_limit is not None:
        group.SetFloat("ProtrusionLimit", float(protrusion_limit))
    if folder is not None:
        group.SetString("McsFolder", str(folder))
    if speed is not None:  # seconds for a whole scan
        group.SetFloat("PlaybackSeconds", max(0.5, float(speed)))


class PreferencesPage:
    """The page FreeCAD's preferences dialog shows; it calls loadSettings and saveSettings.
    FreeCAD's dialog lets only its C++ pages refuse OK (their checkSettings slot), so the page
    checks each edit as it is typed: a refused field is marked red with the reason beside it,
    the top of the page says so, and the dialog's OK and Apply are greyed out until it is
    corrected. OK stores only what was edited."""

    def __init__(self, parent=None):
        self.form = QtGui.QWidget(parent)
        self.form.setWindowTitle("WaferScan")
        self.reasons = {}  # field: the label beside it that says why its text is refused
        self._loaded = {}
        tolerances = QtGui.QGroupBox("Slot mapping (layouts that do not set their own)")
        form = QtGui.QFormLayout(tolerances)
        self.half_thickness = QtGui.QCheckBox("half the nominal wafer thickness")
        self.half_thickness.setToolTip("A run thicker or thinner than nominal by more than this "
                                       "is a double (code 3) or a thin wafer (code 4)")
        self.thickness = length_input(0.35, "Thickness tolerance of a sensor run")
        self.half_thickness.toggled.connect(lambda on: self.thickness.setEnabled(not on))
        row = QtGui.QHBoxLayout()
        row.addWidget(marked_row(self.thickness, self.reasons), 1)
        row.addWidget(self.half_thickness)
        form.addRow("Thickness tolerance", row)
        self.position = length_input(_DEFAULTS.position_tolerance,
                                     "How far a run's lower edge may lie from its slot's "
                                     "seat before it is a position error (code 5)")
        form.addRow("Position tolerance", marked_row(self.position, self.reasons))
        self.protrusion = length_input(_DEFAULTS.protrusion_limit,
                                       "How far a wafer may stick out of the carrier's front "
                                       "before it is reported protruding (code 6)")
        form.addRow("Protrusion limit", marked_row(self.protrusion, self.reasons))
        link = QtGui.QGroupBox("MCS link")
        link_form = QtGui.QFormLayout(link)
        self.folder = QtGui.QLineEdit()
        self.folder.setToolTip("The folder of parameters.txt, commands.txt and results.txt "
                               "that the MCS link panel opens with")
        link_form.addRow("Folder", folder_row(self.folder, self.form, self.folder.setText))
        animation = QtGui.QGroupBox("Animation")
        animation_form = QtGui.QFormLayout(animation)
        self.speed = QtGui.QDoubleSpinBox()
        self.speed.setRange(0.5, 3600.0)
        self.speed.setDecimals(1)
        self.speed.setSuffix(" s")
        self.speed.setToolTip("Seconds of real time the animation of a whole scan lasts, on any "
                              "machine")
        animation_form.addRow("Playback time", self.speed)
        self._loaded_speed = self._shown_speed = None
        # Names for scripts and tests, as FreeCAD's own preference widgets have.
        for widget, name in ((self.half_thickness, "HalfThickness"),
                             (self.thickness, "ThicknessTolerance"),
                             (self.position, "PositionTolerance"),
                             (self.protrusion, "ProtrusionLimit"), (self.folder, "McsFolder"),
                             (self.speed, "PlaybackSeconds")):
            widget.setObjectName(name)
        self.sensor = SensorDefaultsBox()
        # Said at the top of the page while a field is refused (and OK cannot store it).
        self.problem = QtGui.QLabel()
        self.problem.setObjectName("Problem")
        self.problem.setStyleSheet("color: #c01010; font-weight: bold;")
        self.problem.setWordWrap(True)
        self.problem.hide()
        layout = QtGui.QVBoxLayout(self.form)
        layout.addWidget(self.problem)
        for box in (tolerances, self.sensor.box, link, animation):
            layout.addWidget(box)
        layout.addStretch(1)
        # Each edit is checked at once: a refused field is marked with its reason beside it,
        # and the dialog's OK and Apply wait until it is corrected (FreeCAD's preferences
        # dialog stores every page on OK, and only its C++ pages can refuse there).
        for field in (self.thickness, self.position, self.protrusion, *self.sensor.fields.values()):
            field.textChanged.connect(self.check)
        for combo in (self.sensor.shape, self.sensor.latch):
            combo.currentIndexChanged.connect(self.check)
        self.half_thickness.toggled.connect(self.check)

    def loadSettings(self):
        mapping = mapping_tolerances()
        self.half_thickness.setChecked(mapping.thickness_tolerance is None)
        kept = stored_thickness_tolerance()  # the length kept while the box is ticked
        set_length(self.thickness, 0.35 if kept is None else kept)
        set_length(self.position, mapping.position_tolerance)
        set_length(self.protrusion, mapping.protrusion_limit)
        self.folder.setText(mcs_folder())
        self._loaded_speed = playback_seconds()
        self.speed.setValue(self._loaded_speed)
        self._shown_speed = self.speed.value()  # rounded to the field's decimals
        self._loaded = {"half": self.half_thickness.isChecked(), "folder": self.folder.text()}
        self.sensor.load()
        self._loaded_choices = self._choices()
        self.check()

    def _choices(self):
        return [self.half_thickness.isChecked(), self.sensor.shape.currentIndex(),
                self.sensor.latch.currentIndex()]

    def touched(self):
        """Whether anything on the page was changed since it was loaded."""
        fields = (self.thickness, self.position, self.protrusion, *self.sensor.fields.values())
        return (any(field.edited() for field in fields if hasattr(field, "edited"))
                or self._choices() != getattr(self, "_loaded_choices", self._choices()))

    def problems(self):
        """{field: why} for every field whose text is refused (the sensor group's included)."""
        problems = {}
        fields = (self.position, self.protrusion) if self.half_thickness.isChecked() else \
            (self.thickness, self.position, self.protrusion)
        for field in fields:
            try:
                length_value(field)
            except ValueError as exc:
                problems[field] = str(exc)
        for field, reason in self.reasons.items():
            mark(field, reason, problems.get(field))
        problems.update(self.sensor.problems())
        return problems

    def check(self, *_):
        """Mark the refused fields with their reasons, say so at the top of the page and keep
        the dialog's OK and Apply from storing them. True when every field is sound."""
        problems = self.problems()
        count = len(problems)
        # A bad value stored before (set by hand in the parameter editor) is marked, but keeps
        # OK from being pressed only once the page is edited: left alone, the page stores
        # nothing, and the other pages' OK must not wait for this one.
        blocking = count and self.touched()
        self.problem.setText("" if not count else
                             f"{count} field{'s' if count > 1 else ''} marked in red "
                             f"{'need' if count > 1 else 'needs'} correcting: OK stores "
                             "nothing of this page until then (Cancel keeps what is stored)."
                             if blocking else
                             f"{count} stored value{'s' if count > 1 else ''} marked in red "
                             f"{'are' if count > 1 else 'is'} not used (scans take the ideal "
                             "sensor and say so): correct, or leave the page as it is.")
        self.problem.setVisible(bool(count))
        for button in self._dialog_buttons():
            try:
                button.setEnabled(not blocking)
            except RuntimeError:  # a stale PySide2 wrapper of a button the dialog replaced
                pass
        return not count

    def _dialog_buttons(self):
        """The preferences dialog's OK and Apply buttons (none before the page is in it)."""
        if not alive(self.form):
            return []
        dialog = self.form.window()
        if dialog is self.form or not alive(dialog):
            return []
        buttons = []
        roles = (QtGui.QDialogButtonBox.AcceptRole, QtGui.QDialogButtonBox.ApplyRole)
        for box in dialog.findChildren(QtGui.QDialogButtonBox):
            buttons += [b for b in box.findChildren(QtGui.QPushButton)
                        if alive(b) and box.buttonRole(b) in roles]
        return buttons

    def saveSettings(self):
        """Store what the user changed on the page: a field left alone stores nothing (not
        even its exact value again). With a field refused nothing of the page is stored (OK is
        kept from being pressed then; this is the last guard)."""
        problems = self.problems()
        if problems:
            App.Console.PrintError("WaferScan preferences: nothing stored: " + "; ".join(
                problems.values()) + "\n")
            return
        half = self.half_thickness.isChecked()
        thickness = None
        if not half and (self._loaded.get("half") or self.thickness.edited()):
            thickness = length_value(self.thickness)
        speed = self.speed.value()
        folder = self.folder.text().strip()
        set_values(thickness_tolerance=thickness,
                   position_tolerance=length_value(self.position)
                   if self.position.edited() else None,
                   protrusion_limit=length_value(self.protrusion)
                   if self.protrusion.edited() else None,
                   folder=folder if folder != self._loaded.get("folder", "").strip() else None,
                   speed=speed if speed != self._shown_speed else None,
                   half=half if half != self._loaded.get("half") else None)
        self.sensor.save()


def register():
    Gui.addPreferencePage(PreferencesPage, "WaferScan")
