# Run by FreeCAD's GUI (tests/gui/test_gui_frames_choice.py): "Set up carrier and sensor…" on the
# paper's layout with a second object tagged as a carrier and ScanSettings naming none: the
# command asks which carrier, as Run scan asks. Cancel: no panel, the reason said. The second
# carrier chosen: the panel is on it (its name in the panel, its slots derived), and OK writes
# the chosen carrier's slots, in the recorded line and in the document; the paper's carrier is
# left as it was.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    answer_next_question, console_calls, finish, message_texts, result, start, task_panel,
    window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402

SLOT_PROPERTIES = ("SlotCount", "Pitch", "SlotOrigin")


def slots(obj):
    return {name: str(getattr(obj, name)) for name in SLOT_PROPERTIES if hasattr(obj, name)}


def begin():
    import Part

    from waferscan.gui.commands import tag_selection

    Gui.activateWorkbench("WaferScanWorkbench")
    Gui.runCommand("WaferScan_NewPaperLayout")
    doc = App.ActiveDocument
    paper = next(o for o in doc.Objects if getattr(o, "WaferScanRole", "") == "Carrier")
    # A second carrier: a plain box beside the FOUP, tagged as a carrier.
    spare = doc.addObject("Part::Feature", "Spare")
    spare.Label = "SpareCassette"
    spare.Shape = Part.makeBox(320, 320, 300, App.Vector(600, 0, 0))
    doc.recompute()
    tag_selection("carrier", [spare])
    message_texts()
    settings = next(o for o in doc.Objects if "Carrier" in o.PropertiesList
                    and "ThicknessMin" in o.PropertiesList)
    settings.Carrier = ""  # none chosen
    doc.recompute()
    result["labels"] = [paper.Label, spare.Label]
    result["paper_before"] = slots(paper)
    result["spare_before"] = slots(spare)
    questions = result.setdefault("questions", [])
    # Cancel: nothing opens, the user is told why.
    answer_next_question("Cancel", questions)
    Gui.runCommand("WaferScan_SetFrames")
    Gui.updateGui()
    result["cancel_panel"] = bool(Gui.Control.activeDialog())
    result["cancel_messages"] = message_texts()
    # The spare chosen.
    answer_next_question("SpareCassette", questions)
    Gui.runCommand("WaferScan_SetFrames")
    Gui.updateGui()
    panel = task_panel()
    result["panel_open"] = bool(Gui.Control.activeDialog())
    result["panel_carrier"] = panel.carrier.Name if panel.carrier is not None else None
    result["panel_box"] = [b.title() for b in panel.form.findChildren(
        __import__("PySide").QtGui.QGroupBox)]
    result["derived"] = panel.derived.text()
    window_shot("gui-frames-choice.png")
    panel.slot_count.setValue(7)
    panel.pitch.setText("12 mm")
    accepted = panel.accept()
    Gui.updateGui()
    result["accepted"] = accepted
    result["messages"] = message_texts()
    result["lines"] = [c for c in console_calls() if ".set_frames(" in c]
    result["paper_after"] = slots(paper)
    result["spare_after"] = slots(spare)
    result["spare_name"] = spare.Name
    result["undo"] = list(doc.UndoNames)[:1]
    finish()


start(begin)
