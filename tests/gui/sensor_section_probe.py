# Run by FreeCAD's GUI (tests/gui/test_gui_sensor_section.py): the scan panel's "Sensor and slow
# scan" section as a user uses it. Scan the paper's layout; open the section; type a bad
# threshold (refused: nothing written) then a 2 mm spot and apply; Replay (a new scan with it);
# then set the layout to slow mode, type a 5 mm jab in the panel, apply and Replay again.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import (  # noqa: E402
    finish, open_section, replay, result, scan_paper_layout, start, task_panel, wait_for,
    window_shot)

import FreeCAD as App  # noqa: E402
import FreeCADGui as Gui  # noqa: E402


def settings():
    return next(o for o in App.ActiveDocument.Objects if "SpotDiameter" in o.PropertiesList)


def begin():
    first = scan_paper_layout()
    first.speed.setValue(1.0)
    result["first_code"] = first.animation.result.code
    result["collapsed_visible"] = first.sensor.body.isVisible()
    result["shown_values"] = {p: f.text() for p, f in first.sensor.fields.items()}
    result["shown_latch"] = first.sensor.latch.currentText()
    wait_for("the first scan's end", lambda: first.animation.ended, edit_spot)


def edit_spot():
    section = task_panel().sensor
    result["expanded_visible"] = open_section(section)
    undo_before = App.ActiveDocument.UndoCount
    # Refused by the reader: OFF above ON.
    section.fields["SpotDiameter"].setText("2 mm")
    section.fields["ThresholdOff"].setText("0.9")
    result["bad_applied"] = section.apply()
    result["bad_message"] = section.message.text()
    result["after_bad"] = [settings().SpotDiameter.Value, settings().ThresholdOff,
                           App.ActiveDocument.UndoCount - undo_before]
    section.fields["ThresholdOff"].setText(result["shown_values"]["ThresholdOff"])
    result["good_applied"] = section.apply()
    result["good_message"] = section.message.text()
    result["after_good"] = [settings().SpotDiameter.Value, settings().ThresholdOff,
                            App.ActiveDocument.UndoCount - undo_before,
                            App.ActiveDocument.UndoNames[0]]
    window_shot("gui-scan-panel-sensor.png")
    replay("the replay with the spot", after_spot)


def after_spot():
    spotted = task_panel().animation.result
    result["spot_code"] = spotted.code
    result["spot_params"] = [spotted.layout.spot.diameter if spotted.layout.spot else None]
    result["spot_runs"] = [[r.z_in, r.z_out] for r in spotted.runs]
    result["wafers"] = {w.name: [w.center[2], w.thickness] for w in spotted.layout.wafers}
    settings().Mode = "slow"  # the mode is the Data tab's (not in the section)
    App.ActiveDocument.recompute()
    section = task_panel().sensor
    section.fields["Jab"].setText("5 mm")
    section.fields["SpotDiameter"].setText("0 mm")
    result["jab_applied"] = section.apply()
    replay("the replay with the jab", after_jab, until_ended=False)


def after_jab():
    jabbed = task_panel().animation.result
    result["jab_scan"] = [jabbed.layout.scan.mode, jabbed.layout.scan.jab]
    result["pockets"] = [[p.slot, p.front] for p in jabbed.pockets]
    result["jab_code"] = jabbed.code
    task_panel().animation.stop()
    # SPEC §10's other settings in the section: sampled latching without a read period is
    # refused, with one (and a slit, an acceleration) written and read by the scan's reader.
    from waferscan.cad.reader import read_layout
    section = task_panel().sensor
    section.latch.setCurrentIndex(section.latch.findText("sampled"))
    result["sampled_bare"] = [section.apply(), section.message.text()]
    for name, text in (("SamplePeriodMs", "0.002"), ("Acceleration", "1500"),
                       ("SpotWidth", "2 mm"), ("SpotHeight", "0.5 mm")):
        section.fields[name].setText(text)
    result["sampled_applied"] = section.apply()
    read = read_layout(App.ActiveDocument)
    result["sampled_read"] = [read.scan.latch, read.scan.sample_period, read.scan.acceleration,
                              read.spot.width, read.spot.height, read.spot.diameter]
    Gui.Control.closeDialog()
    finish()


start(begin)
