"""The paper's experiment in the FreeCAD GUI: build it with the workbench's command, run the
animated scan to the end, and compare the results table and the slot-code dialog with the
headless scan."""

from pathlib import Path

from waferscan.cad.document_scan import scan_document
from waferscan.cad.layout_files import opened_layout
from waferscan.cli import paper_scenario

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("scan_probe.py")
ARTIFACTS = REPO / "test-artifacts"


def test_animated_scan_shows_the_headless_results(run_gui_probe):
    ARTIFACTS.mkdir(exist_ok=True)
    gui = run_gui_probe(PROBE, WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))
    with opened_layout(paper_scenario()) as doc:
        headless = scan_document(doc, "analytic")
    assert gui["dialog_code"] == gui["sheet_code"] == headless.code
    assert len(gui["rows"]) == 25
    expected = [[str(slot), f"{seat:.2f}", ", ".join(wafers) or "-",
                 "" if z_in is None else f"{z_in:.3f}", "" if z_out is None else f"{z_out:.3f}",
                 "" if diff is None else f"{diff:.3f}", state]
                for slot, seat, wafers, z_in, z_out, diff, state in headless.table_rows()]
    assert gui["rows"] == expected
    assert gui["frames"] >= 5401 // 50  # the animation stepped through the whole scan
    for name in ("gui-results-table.png", "gui-slot-code.png", "gui-after-scan.png",
                 "gui-during-scan.png"):
        assert (ARTIFACTS / name).stat().st_size > 1000
