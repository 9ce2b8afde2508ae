# Run by FreeCAD's GUI (tests/gui/test_gui_half_thickness.py): the preferences' thickness
# tolerance as issue 27 item 13 wants it: "half the nominal wafer thickness" a box of its own
# (stored as the HalfThickness parameter), the length kept while it is ticked; a tolerance stored
# by an earlier version (ThicknessTolerance alone, -1 for half the thickness) read as it was.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
from probe_steps import finish, result, start  # noqa: E402

import FreeCAD as App  # noqa: E402


def stored(group):
    return [group.GetBool("HalfThickness") if "HalfThickness" in group.GetBools() else None,
            group.GetFloat("ThicknessTolerance") if "ThicknessTolerance" in group.GetFloats()
            else None]


def page_state(preferences):
    page = preferences.PreferencesPage()
    page.loadSettings()
    return page, [page.half_thickness.isChecked(), page.thickness.isEnabled(),
                  page.thickness.value_mm(), preferences.mapping_tolerances().thickness_tolerance]


def begin():
    from waferscan.gui import preferences
    group = App.ParamGet(preferences.PARAMETERS)
    # nothing stored: half the thickness
    _, result["nothing"] = page_state(preferences)
    # as an earlier version stored "half the thickness", then a length
    group.SetFloat("ThicknessTolerance", -1.0)
    page, result["old_half"] = page_state(preferences)
    page.saveSettings()  # accepted untouched: nothing stored
    result["old_half_untouched"] = stored(group)
    group.SetFloat("ThicknessTolerance", 0.3)
    _, result["old_length"] = page_state(preferences)
    # today: tick the box (the length is kept), untick it again
    page, _ = page_state(preferences)
    page.half_thickness.setChecked(True)
    page.saveSettings()
    result["ticked_stored"] = stored(group)
    page, result["ticked"] = page_state(preferences)
    page.half_thickness.setChecked(False)
    page.saveSettings()
    result["unticked_stored"] = stored(group)
    _, result["unticked"] = page_state(preferences)
    # from an earlier version's -1, untick and type a length
    group.RemBool("HalfThickness")
    group.SetFloat("ThicknessTolerance", -1.0)
    page, _ = page_state(preferences)
    page.half_thickness.setChecked(False)
    page.thickness.setText("0.01 in")
    page.saveSettings()
    result["from_old_stored"] = stored(group)
    _, result["from_old"] = page_state(preferences)
    try:
        preferences.set_values(thickness_tolerance=-1.0)
        result["negative"] = "stored"
    except ValueError as exc:
        result["negative"] = str(exc)
    finish()


start(begin)
