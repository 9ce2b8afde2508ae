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
from .inputs import folder_row, length_input, length_value, set_length
from .sensor_preferences import SensorDefaultsBox, sensor_defaults  # noqa: F401 (for scanning)

PARAMETERS = "User parameter:BaseApp/Preferences/Mod/WaferScan"
_DEFAULTS = MappingTolerances()
PLAYBACK_S = 10.0  # seconds of real time for a whole scan's animation, when nothing is set
POLL_MS = 500  # the MCS panel's polling fallback


def _group():
    return App.ParamGet(PARAMETERS)


def mapping_tolerances():
    """The default MappingTolerances: the preferences', FreeCAD's parameters being the store.
    A negative thickness tolerance means "half the nominal thickness" (the core's None)."""
    group = _group()
    thickness = group.GetFloat("ThicknessTolerance", HALF_THICKNESS_STORED)
    return MappingTolerances(
        thickness_tolerance=thickness_tolerance_from_stored(thickness),
        position_tolerance=group.GetFloat("PositionTolerance", _DEFAULTS.position_tolerance),
        protrusion_limit=group.GetFloat("ProtrusionLimit", _DEFAULTS.protrusion_limit))


def mcs_folder():
    return _group().GetString("McsFolder", "")


def playback_seconds():
    """How long the animation of a whole scan lasts, in seconds of real time."""
    return max(0.5, _group().GetFloat("PlaybackSeconds", PLAYBACK_S))


def set_values(thickness_tolerance=None, position_tolerance=None, protrusion_limit=None,
               folder=None, speed=None):
    """Store the given preferences (None leaves one as it is)."""
    group = _group()
    if thickness_tolerance is not None:
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
    """The page FreeCAD's preferences dialog shows; it calls loadSettings and saveSettings."""

    def __init__(self, parent=None):
        self.form = QtGui.QWidget(parent)
        self.form.setWindowTitle("WaferScan")
        tolerances = QtGui.QGroupBox("Slot mapping (layouts that do not set their own)")
        form = QtGui.QFormLayout(tolerances)
        self.half_thickness = QtGui.QCheckBox("half the nominal wafer thickness")
        self.half_thickness.setToolTip("A run thicker or thinner than nominal by more than this "
                                       "is a double (code 3) or a thin wafer (code 4)")
        self.thickness = length_input(0.35, "Thickness tolerance of a sensor run")
        self.half_thickness.toggled.connect(lambda on: self.thickness.setEnabled(not on))
        row = QtGui.QHBoxLayout()
        row.addWidget(self.thickness)
        row.addWidget(self.half_thickness)
        form.addRow("Thickness tolerance", row)
        self.position = length_input(_DEFAULTS.position_tolerance,
                                     "How far a run's lower edge may lie from its slot's "
                                     "seat before it is a position error (code 5)")
        form.addRow("Position tolerance", self.position)
        self.protrusion = length_input(_DEFAULTS.protrusion_limit,
                                       "How far a wafer may stick out of the carrier's front "
                                       "before it is reported protruding (code 6)")
        form.addRow("Protrusion limit", self.protrusion)
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
        layout = QtGui.QVBoxLayout(self.form)
        for box in (tolerances, self.sensor.box, link, animation):
            layout.addWidget(box)
        layout.addStretch(1)

    def loadSettings(self):
        mapping = mapping_tolerances()
        self.half_thickness.setChecked(mapping.thickness_tolerance is None)
        set_length(self.thickness, 0.35 if mapping.thickness_tolerance is None
                   else mapping.thickness_tolerance)
        set_length(self.position, mapping.position_tolerance)
        set_length(self.protrusion, mapping.protrusion_limit)
        self.folder.setText(mcs_folder())
        self._loaded_speed = playback_seconds()
        self.speed.setValue(self._loaded_speed)
        self._shown_speed = self.speed.value()  # rounded to the field's decimals
        self.sensor.load()

    def saveSettings(self):
        """Store what the page shows. A field the user left alone stores the exact value it
        was loaded with (not its rounded text); one typed wrong keeps its old value, and says
        so in the report view (the dialog is closing)."""

        def typed(field, name):
            try:
                return length_value(field)
            except ValueError as exc:
                App.Console.PrintError(f"WaferScan preferences: {name} not changed: {exc}\n")
                return None

        thickness = HALF_THICKNESS_STORED if self.half_thickness.isChecked() else \
            typed(self.thickness, "thickness tolerance")
        speed = self.speed.value()
        if self._loaded_speed is not None and speed == self._shown_speed:
            speed = self._loaded_speed  # shown rounded, not edited: kept exactly
        set_values(thickness_tolerance=thickness,
                   position_tolerance=typed(self.position, "position tolerance"),
                   protrusion_limit=typed(self.protrusion, "protrusion limit"),
                   folder=self.folder.text().strip(), speed=speed)
        self.sensor.save()


def register():
    Gui.addPreferencePage(PreferencesPage, "WaferScan")
