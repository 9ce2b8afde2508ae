"""``waferscan scan LAYOUT.FCStd --store`` keeps the results in the layout headlessly: the same
ScanResults spreadsheet the GUI's Run scan writes (cad.results_sheet), saved atomically."""

import json

from commands import waferscan
from scenarios import PAPER
from scenarios import PAPER_CODE as CODE


def test_scan_store_saves_the_results_into_the_layout(tmp_path):
    import FreeCAD as App

    layout = tmp_path / "paper.FCStd"
    assert waferscan("layout", PAPER, "-o", layout).returncode == 0
    done = waferscan("scan", layout, "--store", "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["code"] == CODE
    assert [p.name for p in tmp_path.iterdir()] == ["paper.FCStd"]  # no temporary left

    # Table 1's rows from the JSON: each run at the lowest slot it speaks for, an empty slot
    # one blank row; the numbers as the sheet shows them (seat Z to 0.01 mm, the rest 0.001 mm).
    expected, listed = [], set()
    for slot in data["slots"]:
        own = [i for i in slot["runs"] if i not in listed]
        listed.update(own)
        runs = [data["runs"][i] for i in own] or [None]
        for run in runs:
            numbers = [None] * 3 if run is None else \
                [round(run[k], 3) for k in ("in", "out", "diff")]
            expected.append([slot["slot"], round(slot["z"], 2), *numbers])

    doc = App.openDocument(str(layout))
    try:
        sheet = doc.getObject("ScanResults")
        assert sheet is not None
        assert sheet.get("code") == CODE
        cells = [[float(text) if text else None for text in
                  (sheet.getContents(f"{column}{row}") for column in "ABDEF")]
                 for row in range(2, 2 + len(expected))]
        code_row = 2 + len(expected) + 1
        assert sheet.get(f"A{code_row}") == "Code"
        assert sheet.get(f"B{code_row + 1}") == data["e87"]
    finally:
        App.closeDocument(doc.Name)
    assert cells == expected
    # The saved layout still scans to the same result.
    again = waferscan("scan", layout, "--json")
    assert json.loads(again.stdout)["runs"] == data["runs"]


def test_store_refuses_a_scenario_in_one_line(tmp_path):
    done = waferscan("scan", PAPER, "--store")
    assert done.returncode == 2
    assert done.stderr.startswith(f"waferscan: error: {PAPER}: --store keeps the results in a "
                                  "layout .FCStd")
    assert "Traceback" not in done.stderr and done.stdout == ""
