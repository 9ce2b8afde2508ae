# Run by FreeCAD's GUI (tests/gui/test_gui_lazy_imports.py): the workbench activated, which of
# its modules are loaded; then the lines a macro runs on the MCS link and the tolerance study,
# which load theirs when first called.
import os
import sys
import time

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, start  # noqa: E402

import FreeCADGui as Gui  # noqa: E402

LATER = ("waferscan.gui.mcs_script", "waferscan.gui.mcs_panel", "waferscan.gui.link_watch",
         "waferscan.gui.tolerance_dialog")


def begin():
    started = time.perf_counter()
    Gui.activateWorkbench("WaferScanWorkbench")
    result["activate_ms"] = round(1000 * (time.perf_counter() - started), 1)
    result["commands_loaded"] = "waferscan.gui.commands" in sys.modules
    result["loaded_at_start"] = [m for m in LATER if m in sys.modules]
    Gui.doCommand("import waferscan.gui.commands")
    Gui.doCommand("waferscan.gui.commands.stop_tolerance_study()")  # no dialog: nothing to stop
    result["after_study_line"] = [m for m in LATER if m in sys.modules]
    import waferscan.gui.commands as commands
    from waferscan.gui.commands import start_mcs_link
    from waferscan.gui.mcs_script import start_mcs_link as defined

    result["same_function"] = start_mcs_link is defined
    result["after_mcs_name"] = [m for m in LATER if m in sys.modules]
    result["listed"] = sorted(n for n in commands.__all__ if not hasattr(commands, n))
    try:
        commands.no_such_name
        result["unknown"] = "no error"
    except AttributeError as exc:
        result["unknown"] = str(exc)
    finish()


start(begin)
