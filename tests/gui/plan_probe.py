# Run by FreeCAD's GUI (tests/gui/test_gui_plan.py): the slot-code dialog of a slow scan with
# jabs and sweeps (resources/examples/slow_jab.toml) shows each probed pocket from above. The
# probe opens its "Pockets from above" tab, chooses slots, and reads back what was drawn: the
# canvas's list of drawn items, the pixel of plan points (as the canvas maps them) and their
# colours in the rendered image; then saves a picture of the dialog.
import os
import sys

sys.path.insert(0, os.environ["WAFERSCAN_GUI_PROBES"])
import FreeCADGui as Gui  # noqa: E402
from probe_steps import artifact, finish, result, start  # noqa: E402


def begin():
    from waferscan.core.files.scenario import read_scenario
    from waferscan.core.scan.layout_scan import scan_layout
    from waferscan.gui.plan_view import BEAM_STYLES, STRIKE
    from waferscan.gui.results_view import SlotCodeDialog

    Gui.activateWorkbench("WaferScanWorkbench")
    scanned = scan_layout(read_scenario(os.environ["WAFERSCAN_GUI_SCENARIO"]))
    dialog = SlotCodeDialog(scanned)
    dialog.resize(900, 900)
    dialog.show()
    view = dialog.plan_view
    result["beam_colours"] = {role: list(style[0]) for role, style in BEAM_STYLES.items()}
    result["strike_colour"] = list(STRIKE)
    result["duration_label"] = dialog.duration_label.text()
    result["durations"] = scanned.durations
    result["tabs"] = [dialog.views.tabText(i) for i in range(dialog.views.count())]
    dialog.views.setCurrentWidget(view)
    Gui.updateGui()
    result["chooser"] = [view.chooser.itemText(i) for i in range(view.chooser.count())]
    result["first_shown"] = view.canvas.plan.slot
    points = {int(k): v for k, v in
              __import__("json").loads(os.environ["WAFERSCAN_GUI_POINTS"]).items()}
    result["slots"] = {}
    for slot in (8, 3, 5):
        view.show_slot(slot)
        view.canvas.repaint()
        Gui.updateGui()
        image = view.canvas.grab().toImage()
        # The image may hold more pixels than the widget (a device pixel ratio other than 1).
        ratio = image.width() / view.canvas.width()
        seen = {}
        for name, (u, v) in points.get(slot, {}).items():
            x, y = view.canvas.to_pixel(u, v)
            colour = QtGui.QColor(image.pixel(int(x * ratio), int(y * ratio)))
            seen[name] = {"pixel": [x, y], "rgb": [colour.red(), colour.green(), colour.blue()]}
        result["slots"][slot] = {"drawn": [list(d) for d in view.canvas.drawn],
                                 "chosen": view.chooser.currentText(),
                                 "scale": view.canvas.scale(), "points": seen}
    view.show_slot(8)
    Gui.updateGui()
    dialog.grab().save(artifact("gui-pocket-plan.png"))
    # The same dialog at the size it opens at: the legend wraps instead of being clipped.
    small = SlotCodeDialog(scanned)
    small.show()
    small.views.setCurrentWidget(small.plan_view)
    small.plan_view.show_slot(8)
    Gui.updateGui()
    canvas = small.plan_view.canvas
    canvas.repaint()
    metrics = QtGui.QFontMetricsF(canvas._small_font())
    result["default_canvas"] = [canvas.width(), canvas.height()]
    result["default_legend"] = {"box": list(canvas.legend_box),
                                "one_line_width": metrics.horizontalAdvance(canvas.legend()),
                                "line_height": metrics.lineSpacing(),
                                "drawn": [d for d in canvas.drawn if d[0] == "legend"],
                                "title": list(canvas._title_rect().getRect()),
                                "title_width": metrics.horizontalAdvance(canvas.plan.title)}
    small.grab().save(artifact("gui-pocket-plan-default-size.png"))
    small.close()
    finish()


from PySide import QtGui  # noqa: E402

start(begin)
