# Run by FreeCAD's GUI (tests/gui/test_gui_preferences_refuse.py): issue 27 item 14, the
# WaferScan preferences page as a user meets it. Open Edit → Preferences (the workbench's
# command) on a fresh configuration and click OK untouched; open it again, type "−1 mm" as the
# position tolerance, an OFF threshold above ON and a response time that is not one; try OK;
# then correct them with a German decimal comma and click OK.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    artifact, finish, later, open_preferences, result, start)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtCore, QtGui  # noqa: E402

PARAMETERS = "User parameter:BaseApp/Preferences/Mod/WaferScan"
BAD = {"PositionTolerance": "\u22121 mm", "ThresholdOff": "0.9", "SensorResponse": "abc"}
GOOD = {"PositionTolerance": "0,25 mm", "ThresholdOff": "0,4", "SensorResponse": "0,5 ms"}


def stored():
    """Every parameter the WaferScan group holds, {name: value}."""
    return {name: value for _, name, value in App.ParamGet(PARAMETERS).GetContents() or ()}


def buttons(dialog):
    return {b.text().replace("&", ""): b for b in dialog.findChildren(QtGui.QPushButton)}


def page_state(dialog):
    """What the user sees of the page: OK and Apply enabled, the message at its top, and each
    field of BAD with its red mark and the reason beside it."""
    shown = buttons(dialog)
    problem = dialog.findChild(QtGui.QLabel, "Problem")
    fields = {}
    for name in BAD:
        field = dialog.findChild(QtGui.QLineEdit, name)
        reason = [w for w in field.parentWidget().findChildren(QtGui.QLabel)]
        fields[name] = {"text": field.text(), "red": "#c01010" in field.styleSheet(),
                        "reason": reason[0].text() if reason else None,
                        "reason_visible": bool(reason) and reason[0].isVisible()}
    return {"ok_enabled": shown["OK"].isEnabled(),
            "apply_enabled": shown["Apply"].isEnabled() if "Apply" in shown else None,
            "problem": problem.text() if problem is not None and problem.isVisible() else "",
            "fields": fields}


def begin():
    Gui.activateWorkbench("WaferScanWorkbench")
    result["stored_before"] = stored()

    def untouched(dialog):
        result["untouched_page"] = page_state(dialog)
        buttons(dialog)["OK"].click()

    open_preferences(untouched)
    result["stored_untouched"] = stored()
    later(refuse, 50)


def refuse():
    def bad_then_good(dialog):
        for name, text in BAD.items():
            dialog.findChild(QtGui.QLineEdit, name).setText(text)
        QtGui.QApplication.processEvents()
        result["bad_page"] = page_state(dialog)
        page = dialog.findChild(QtGui.QLineEdit, "PositionTolerance").window()
        page.grab().save(artifact("gui-preferences-refused.png"))
        buttons(dialog)["OK"].click()  # a user clicking the greyed OK
        QtGui.QApplication.processEvents()
        result["open_after_ok"] = dialog.isVisible()
        result["stored_while_bad"] = stored()
        if not dialog.isVisible():
            return  # the dialog closed with the bad values (as before issue 27)
        QtCore.QLocale.setDefault(QtCore.QLocale(QtCore.QLocale.German))
        for name, text in GOOD.items():
            dialog.findChild(QtGui.QLineEdit, name).setText(text)
        QtGui.QApplication.processEvents()
        result["good_page"] = page_state(dialog)
        buttons(dialog)["OK"].click()
        result["open_after_good_ok"] = dialog.isVisible()

    open_preferences(bad_then_good)
    result["stored_good"] = stored()
    later(stored_by_hand, 50)


def stored_by_hand():
    """A bad value set by hand in the parameter editor: marked when the page opens, but OK
    (for every page of the dialog) waits only once this page is edited."""
    App.ParamGet(PARAMETERS).SetFloat("ThresholdOn", 2.0)  # a fraction of the spot: 0 to 1

    def look(dialog):
        result["hand_page"] = page_state(dialog)
        on = dialog.findChild(QtGui.QLineEdit, "ThresholdOn")
        result["hand_on_red"] = "#c01010" in on.styleSheet()
        dialog.findChild(QtGui.QLineEdit, "PositionTolerance").setText("0,3 mm")
        QtGui.QApplication.processEvents()
        result["hand_edited_page"] = page_state(dialog)
        buttons(dialog)["Cancel"].click()

    open_preferences(look)
    finish()


start(begin)
