# Run by FreeCAD's GUI (tests/gui/test_gui_settings.py): FreeCAD's preferences dialog opened with
# the workbench's command and accepted untouched, in the mm and in an inch unit schema, then with
# one field edited; the MCS link panel with no folder set, whose Save and Start watching ask for
# one.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    accept_preferences, artifact, finish, later, result, start)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

FOLDER = os.environ["WAFERSCAN_GUI_MCS"]
PARAMETERS = "User parameter:BaseApp/Preferences/Mod/WaferScan"
UNITS = "User parameter:BaseApp/Preferences/Units"
# Tolerances a user set that two decimals cannot show: 0.125 mm is "0.13 mm" or "0.00 in".
EXACT = {"ThicknessTolerance": 0.125, "PositionTolerance": 0.2, "ProtrusionLimit": 2.0}
FIELDS = ("ThicknessTolerance", "PositionTolerance", "ProtrusionLimit")


def stored():
    group = App.ParamGet(PARAMETERS)
    return {name: group.GetFloat(name) for name in EXACT} | {
        "McsFolder": group.GetString("McsFolder"),
        "PlaybackSeconds": group.GetFloat("PlaybackSeconds")}


def use_schema(number):
    """The unit schema as Preferences → General → Units sets it (kept in the parameters, so that
    the dialog's own General page keeps it when accepted)."""
    App.ParamGet(UNITS).SetInt("UserSchema", number)
    App.Units.setSchema(number)


def open_preferences(key, edit=None, then=None):
    """Open the preferences with the workbench's command; on the WaferScan page record the
    fields' text, type ``edit`` {field: text} if given, and click OK."""

    def on_page(dialog):
        fields = {name: dialog.findChild(QtGui.QLineEdit, name) for name in FIELDS}
        result[key] = {"texts": {name: field.text() for name, field in fields.items()}}
        for name, text in (edit or {}).items():
            fields[name].setText(text)
        os.makedirs(os.path.dirname(artifact("x")), exist_ok=True)
        dialog.grab().save(artifact(f"gui-preferences-{key}.png"))

    accept_preferences(on_page)
    result[key]["stored"] = stored()
    later(then, 50)


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    group = App.ParamGet(PARAMETERS)
    for name, value in EXACT.items():
        group.SetFloat(name, value)
    group.SetFloat("PlaybackSeconds", 7.25)  # the field shows one decimal: 7.2 or 7.3
    use_schema(0)
    open_preferences("mm", then=inch)


def inch():
    use_schema(3)  # Imperial decimal (in/lb)
    open_preferences("inch", then=inch_edited)


def inch_edited():
    open_preferences("inch_edited", edit={"PositionTolerance": "0.01"}, then=mcs_without_folder)


def choose_folder(folder, log):
    """Answer the next folder dialog with ``folder`` (None: cancel it)."""

    def answer():
        dialog = QtGui.QApplication.activeModalWidget()
        if not isinstance(dialog, QtGui.QFileDialog):
            QtCore.QTimer.singleShot(50, answer)
            return
        log.append(dialog.windowTitle())
        if folder is None:
            dialog.reject()
        else:
            # The whole path typed into the name field, as a user may: what the dialog
            # returns does not depend on its folder view having loaded.
            dialog.setDirectory(folder)
            for field in dialog.findChildren(QtGui.QLineEdit):
                field.setText(folder)
            dialog.accept()

    QtCore.QTimer.singleShot(50, answer)


def mcs_without_folder():
    use_schema(0)
    Gui.runCommand("WaferScan_NewPaperLayout")
    Gui.runCommand("WaferScan_McsLink")
    from waferscan.gui.session import session
    panel = session.task_panel
    result["mcs_folder_shown"] = panel.folder.text()
    asked = []
    choose_folder(None, asked)
    result["start_cancelled"] = [panel.start(events=False, poll_ms=0), panel.state.text()]
    choose_folder(None, asked)
    result["save_cancelled"] = [panel.save_parameters(), panel.check.text()]
    result["cwd_parameters"] = os.path.exists(os.path.join(os.getcwd(), "parameters.txt"))
    choose_folder(FOLDER, asked)
    result["saved"] = panel.save_parameters()
    result["folder_after_save"] = panel.folder.text()
    result["asked"] = asked
    result["saved_file"] = os.path.exists(os.path.join(FOLDER, "parameters.txt"))
    Gui.Control.closeDialog()
    finish()


start(begin)
