# Run by FreeCAD's GUI (tests/addon/test_addon_manager_install.py) with the addon installed as
# the Addon Manager installs it (a clone, no venv, no pinocchio). "New paper layout" (a robot)
# must show the missing-pinocchio message and leave no half-built document; a scenario without
# a robot must build.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, later, result, start, wait_for  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402
from PySide import QtGui  # noqa: E402


def _message_boxes():
    return [w for w in QtGui.QApplication.topLevelWidgets()
            if isinstance(w, QtGui.QMessageBox) and w.isVisible()]


def robot_layout():
    import waferscan

    result["waferscan_file"] = os.path.realpath(waferscan.__file__)
    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    wait_for("the message box", lambda: _message_boxes(), message_shown)


def message_shown():
    result["messages"] = [box.text() for box in _message_boxes()]
    result["documents_after_robot"] = sorted(App.listDocuments())
    for box in _message_boxes():
        box.close()
    # The rest once the box's own (modal) event loop has returned: quitting from inside it
    # left FreeCAD 1.0 running until the test's timeout, once in a CI run.
    later(robotless)


def robotless():
    from waferscan.gui.commands import open_scenario

    doc = open_scenario(os.environ["WAFERSCAN_ROBOTLESS"])
    from waferscan.cad import roles

    result["wafers"] = sum(1 for o in doc.Objects if roles.role_of(o) == roles.WAFER)
    result["robots"] = sum(1 for o in doc.Objects if roles.role_of(o) == roles.ROBOT)
    finish()


start(robot_layout)
