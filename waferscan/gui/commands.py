"""The workbench's commands, one small class each (FreeCAD's command interface: GetResources,
IsActive, Activated), and ``register``, which adds them to FreeCAD.

A command does its work as FreeCAD's own do: it runs one line of Python through
``Gui.doCommand`` (``record``), so that the Python console shows, and a macro keeps, the call a
script would make, such as ``waferscan.gui.commands.run_scan(App.getDocument('MyCell'))``. The
functions those lines call live by subject: ``scanning`` (open_scenario), ``tagging``,
``playback`` (run_scan, replay_scan), ``frames_panel`` (set up carrier and sensor),
``results_view`` (Export CSV), ``tolerance_dialog`` (the study's Run and Stop), ``mcs_script``
(the MCS link's Start, Stop, Save), the scan panel's sections (Apply) and ``dialogs``
(results, cross-check, calibration, tolerance study, MCS link); docs/tutorials/gui.md lists
the lines. They are named in this module too, because recorded lines and users' macros name
them through it; a user's mistake (a WaferScanError) is reported by ``session.report``."""

from __future__ import annotations

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtGui

from ..addon import icon_path, paper_scenario
from ..core.errors import WaferScanError
# What recorded lines call, as waferscan.gui.commands.<name>: macros replay these names from
# here. ``session`` too: scripts and probes read what the workbench keeps through it.
from .dialogs import (apply_calibration, calibrate_layout, cross_check, open_tolerance_study,
                      save_calibration_recipe, show_results_dialogs)
from .frames_panel import open_frames_panel, set_frames
from .playback import replay_scan, run_scan
from .recipe_section import apply_recipe
from .results_view import export_results_csv
from .scanning import open_scenario
from .sensor_section import apply_sensor_settings
from .session import doc_ref, record, report, session
from .tagging import make_carrier_from_solids, record_tagging, tag_selection, untag_selection

# Named here too, but imported when a line first calls them (the MCS link's and the tolerance
# study's modules, and what they import, cost the workbench's start-up ~40 ms otherwise).
_LATER = {"open_mcs_panel": "mcs_script", "save_mcs_parameters": "mcs_script",
          "start_mcs_link": "mcs_script",
          "stop_mcs_link": "mcs_script", "store_mcs_scans": "mcs_script",
          "run_tolerance_study": "tolerance_dialog", "stop_tolerance_study": "tolerance_dialog",
          "open_host_panel": "host_panel"}


def __getattr__(name):
    """A name of ``_LATER``, imported from its module on first use (PEP 562)."""
    if name not in _LATER:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(f".{_LATER[name]}", __package__), name)
    globals()[name] = value
    return value


__all__ = ["open_scenario", "tag_selection", "untag_selection", "make_carrier_from_solids",
           "run_scan", "replay_scan", "export_results_csv", "calibrate_layout",
           "apply_calibration", "save_calibration_recipe",
           "show_results_dialogs", "cross_check", "open_tolerance_study", "open_frames_panel",
           "set_frames", "apply_recipe", "apply_sensor_settings", "session", "record",
           "COMMANDS", "TAG_COMMANDS", "register"]
__all__ += list(_LATER)


def _objects_ref(objects):
    return "[" + ", ".join(f"{doc_ref(o.Document)}.getObject({o.Name!r})"
                           for o in objects) + "]"


class _Command:
    """What FreeCAD asks of a command (GetResources, IsActive, Activated); a subclass's ``run``
    does its work, and a user's mistake it raises (a WaferScanError) is reported, not raised."""

    menu, tip, icon = "", "", "WaferScan.svg"
    shows_only = False  # True: usable even while another tool's task panel is open
    # True: the command's own transactions are the undo steps (FreeCAD otherwise folds every
    # step a command takes into one, named after the first: a split and its tagging).
    own_transactions = False

    def GetResources(self):
        resources = {"Pixmap": icon_path(self.icon), "MenuText": self.menu, "ToolTip": self.tip}
        kinds = ["ForEdit"] if self.shows_only else []
        if self.own_transactions:
            kinds.append("NoTransaction")
        if kinds:
            resources["CmdType"] = " ".join(kinds)
        return resources

    def Activated(self):
        try:
            self.run()
        except WaferScanError as exc:
            report(exc, error=True)

    def IsActive(self):
        return App.ActiveDocument is not None


class NewPaperLayout(_Command):
    menu, icon = "New paper layout", "WaferScan_NewPaperLayout.svg"
    tip = "Build the paper's experiment: a 25-slot FOUP with ten wafers and the robot"

    def run(self):
        record(f"open_scenario({str(paper_scenario())!r})")

    def IsActive(self):
        return True


class OpenScenario(_Command):
    menu, icon = "Open scenario…", "WaferScan_OpenScenario.svg"
    tip = "Build a layout from a scenario file (.toml)"

    def run(self):
        path, _ = QtGui.QFileDialog.getOpenFileName(Gui.getMainWindow(), "Open scenario",
                                                    str(paper_scenario().parent),
                                                    "Scenario (*.toml)")
        if path:
            record(f"open_scenario({path!r})")

    def IsActive(self):
        return True


class Tag(_Command):
    own_transactions = True

    def __init__(self, role, tip):
        self.role, self.menu, self.tip = role, f"Tag as {role}", tip
        self.icon = f"WaferScan_Tag{role.capitalize()}.svg"

    def run(self):
        record_tagging(self.role, Gui.Selection.getSelection())  # its questions asked first

    def IsActive(self):
        return bool(Gui.Selection.getSelection())


class SelectionCommand(_Command):
    """A command on the selection whose call ``function`` is recorded with the selected
    objects (Untag, Make carrier from solids)."""

    own_transactions = True

    def __init__(self, function, menu, icon, tip):
        self.function, self.menu, self.icon, self.tip = function, menu, icon, tip

    def run(self):
        selection = Gui.Selection.getSelection()
        record(f"{self.function}({_objects_ref(selection)})")

    def IsActive(self):
        return bool(Gui.Selection.getSelection())


class TagGroup:
    """The three tag commands as one toolbar button with a drop-down."""

    def GetCommands(self):
        return tuple(TAG_COMMANDS)

    def GetResources(self):
        return {"Pixmap": icon_path("WaferScan_TagSelection.svg"), "MenuText": "Tag selection",
                "ToolTip": "Give the selected solids a WaferScan role"}

    def IsActive(self):
        return bool(Gui.Selection.getSelection())


class SetFrames(_Command):
    menu, icon = "Set up carrier and sensor…", "WaferScan_SetFrames.svg"
    tip = ("Pick the carrier's slot 1 seat and the beam's emitter and receiver in the 3D view, "
           "and take the slot count and pitch from the carrier's geometry")

    def run(self):
        record(f"open_frames_panel({doc_ref(App.ActiveDocument)})")


class RunScan(_Command):
    menu, icon = "Run scan", "WaferScan_RunScan.svg"
    tip = ("Scan the active layout, animated (play, pause, stop, speed in the task panel); "
           "then show the results and the slot code")

    def run(self):
        record(f"run_scan({doc_ref(App.ActiveDocument)})")


class CalibrateCommand(_Command):
    menu, icon = "Calibrate", "WaferScan_Calibrate.svg"
    tip = ("Calibrate the recipe from reference wafers in the bottom and top slots: slot-1 seat, "
           "pitch, scan range, thickness correction, then a check scan (SPEC §11)")

    def run(self):
        record(f"calibrate_layout({doc_ref(App.ActiveDocument)})")


class McsLinkCommand(_Command):
    menu, icon = "MCS link…", "WaferScan_McsLink.svg"
    tip = ("Talk to the robot's motion control software through parameters.txt, commands.txt "
           "and results.txt in a folder")

    def run(self):
        record(f"open_mcs_panel({doc_ref(App.ActiveDocument)})")


class HostLinkCommand(_Command):
    menu, icon = "Host link…", "WaferScan_HostLink.svg"
    tip = ("Make the layout's carriers SEMI E87 load ports of an HSMS equipment that a factory "
           "host connects to and verifies the slot maps of (SECS/GEM)")

    def run(self):
        record(f"open_host_panel({doc_ref(App.ActiveDocument)})")


class ResultsTableCommand(_Command):
    shows_only = True
    menu, icon = "Results table", "WaferScan_Results.svg"
    tip = "The scan's results, slot by slot (the paper's Table 1); selecting a row selects the wafer"

    def run(self):
        record(f"show_results_dialogs({doc_ref(App.ActiveDocument)}, ('table',))")


class SlotCodeCommand(_Command):
    shows_only = True
    menu, icon = "Slot code", "WaferScan_SlotCode.svg"
    tip = "The slot code, its per-slot strip, a side view of the runs and the E87 map"

    def run(self):
        record(f"show_results_dialogs({doc_ref(App.ActiveDocument)}, ('code',))")


class CrossCheckCommand(_Command):
    shows_only = True
    menu, icon = "Cross-check with CAD", "WaferScan_CrossCheck.svg"
    tip = "Confirm every IN and OUT of the scan with FreeCAD's B-rep geometry (OpenCASCADE)"

    def run(self):
        record(f"cross_check({doc_ref(App.ActiveDocument)})")


class ToleranceStudyCommand(_Command):
    shows_only = True
    menu, icon = "Tolerance study…", "WaferScan_ToleranceStudy.svg"
    tip = ("Monte Carlo sweep of the recipe under tolerances (seat, thickness, beam...): how "
           "often each state is misread, the margins and safer windows (SPEC §12)")

    def run(self):
        record("open_tolerance_study()")

    def IsActive(self):
        return True


class PreferencesCommand(_Command):
    shows_only = True
    menu, icon = "Preferences…", "WaferScan_Preferences.svg"
    tip = "Default tolerances, the MCS folder and the playback speed"

    def run(self):
        Gui.showPreferences("WaferScan")

    def IsActive(self):
        return True


TAG_COMMANDS = {
    "WaferScan_TagWafer": Tag("wafer", "Tag the selected solids as wafers (each must be a disc)"),
    "WaferScan_TagCarrier": Tag("carrier", "Tag the selected object as a wafer carrier"),
    "WaferScan_TagScanner": Tag("scanner", "Tag the selected object as the through-beam scanner"),
    "WaferScan_MakeCarrier": SelectionCommand(
        "make_carrier_from_solids", "Make carrier from solids", "WaferScan_MakeCarrier.svg",
        "Gather the selected solids (a carrier's walls and base) into one part, tagged as the "
        "carrier"),
    "WaferScan_Untag": SelectionCommand(
        "untag_selection", "Untag", "WaferScan_Untag.svg",
        "Take the WaferScan role off the selected objects, as they were before tagging"),
}

COMMANDS = {
    "WaferScan_NewPaperLayout": NewPaperLayout(),
    "WaferScan_OpenScenario": OpenScenario(),
    "WaferScan_Tag": TagGroup(),
    "WaferScan_SetFrames": SetFrames(),
    "WaferScan_RunScan": RunScan(),
    "WaferScan_Calibrate": CalibrateCommand(),
    "WaferScan_McsLink": McsLinkCommand(),
    "WaferScan_HostLink": HostLinkCommand(),
    "WaferScan_Results": ResultsTableCommand(),
    "WaferScan_SlotCode": SlotCodeCommand(),
    "WaferScan_CrossCheck": CrossCheckCommand(),
    "WaferScan_ToleranceStudy": ToleranceStudyCommand(),
    "WaferScan_Preferences": PreferencesCommand(),
}


def register():
    """Add the commands to FreeCAD; returns the toolbar's and the menu's command names: the
    toolbar has the tag commands behind one drop-down, the menu lists them."""
    for name, command in {**TAG_COMMANDS, **COMMANDS}.items():
        Gui.addCommand(name, command)
    toolbar = list(COMMANDS)
    menu = []
    for name in toolbar:
        menu += ["Separator", *TAG_COMMANDS, "Separator"] if name == "WaferScan_Tag" else [name]
    return toolbar, menu
