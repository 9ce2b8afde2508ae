# Run by FreeCAD's GUI (tests/gui/test_gui_mcs_parity.py): for each layout of
# WAFERSCAN_GUI_PARITY (a JSON list of [scenario, folder, [[parameters.txt, commands.txt]...]]),
# the layout opened as `waferscan watch --layout` opens it, the MCS link panel watching the
# folder (polling), and the folder put in each state in turn, each state's commands answered
# before the next. The test compares the folder with a headless watcher's.
import json
import os
import re
import sys
from pathlib import Path

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, later, result, start, wait_for, window_shot  # noqa: E402

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402

LAYOUTS = json.loads(os.environ["WAFERSCAN_GUI_PARITY"])
state = {}
result["rows"] = {}


def next_layout():
    if not LAYOUTS:
        finish()
        return
    scenario, folder, states = LAYOUTS.pop(0)
    from waferscan.cad.layout_files import open_layout
    from waferscan.gui.mcs_script import open_mcs_panel

    Gui.activateWorkbench("WaferScanWorkbench")
    doc = open_layout(scenario)
    panel = open_mcs_panel(doc, folder)
    panel.start(events=False, poll_ms=100)
    state.update(doc=doc, panel=panel, folder=Path(folder), states=list(states),
                 name=Path(scenario).stem)
    later(next_state)


def last_seq(commands):
    """The seq the last command of commands.txt is answered under (a torn line's tail too)."""
    return re.findall(r"([0-9]+)[ \t]+[A-Za-z]+", commands)[-1]


def next_state():
    folder = state["folder"]
    if not state["states"]:
        panel = state["panel"]
        result["rows"][state["name"]] = panel.log_rows()
        window_shot(f"gui-mcs-parity-{state['name']}.png")
        panel.reject()
        App.closeDocument(state["doc"].Name)
        later(next_layout)
        return
    parameters, commands = state["states"].pop(0)
    (folder / "parameters.txt").write_text(parameters, encoding="utf-8")
    (folder / "commands.txt").write_text(commands, encoding="utf-8")
    answered = f"seq = {last_seq(commands)}\n"
    results = folder / "results.txt"
    wait_for(f"{answered.strip()} in {results}",
             lambda: results.exists() and answered in results.read_text(encoding="utf-8"),
             lambda: later(next_state, 300), timeout_s=120)


start(next_layout)
