"""A scan's results kept in its FreeCAD document: the paper's Table 1 as a Spreadsheet named
``ScanResults``, with the slot code and E87 string under it, so they survive save and reload.
Written the same by the GUI's Run scan and by ``waferscan scan LAYOUT.FCStd --store``; no GUI
needed."""

from __future__ import annotations

COLUMNS = ("Slot", "Slot Z [mm]", "Wafer", "IN [mm]", "OUT [mm]", "Diff [mm]", "State")
# SPEC §13: a slow scan's jab and sweep per slot, shown when its pockets were probed.
POCKET_COLUMNS = ("Front [mm]", "Sweep first [°]", "Sweep last [°]")
SHEET = "ScanResults"


def columns(result):
    """The table's columns for this result: COLUMNS, and POCKET_COLUMNS after a jab or sweep."""
    return COLUMNS + (POCKET_COLUMNS if result.pockets else ())


def _mm(value):
    return "" if value is None else f"{value:.3f}"


def _pocket_cells(result, slot):
    probe = next((p for p in result.pockets if p.slot == slot), None)
    sweep = (None, None) if probe is None or probe.sweep is None else probe.sweep
    return [_mm(None if probe is None else probe.front),
            *("" if a is None else f"{a:+.3f}" for a in sweep)]


def table_cells(result):
    """The table's rows as text cells, with each row's state code."""
    codes = {s.slot: s.state for s in result.slot_map.slots}
    rows = []
    for slot, seat, wafers, z_in, z_out, diff, state in result.table_rows():
        rows.append(([str(slot), f"{seat:.2f}", ", ".join(wafers) or "-", _mm(z_in), _mm(z_out),
                      _mm(diff), state] + (_pocket_cells(result, slot) if result.pockets else []),
                     codes[slot]))
    return rows


def store_in_document(doc, result):
    """Keep the results in the document as a Spreadsheet, so they survive save and reload."""
    sheet = doc.getObject(SHEET) or doc.addObject("Spreadsheet::Sheet", SHEET)
    sheet.clearAll()
    for column, title in enumerate(columns(result)):
        sheet.set(f"{chr(65 + column)}1", title)
    rows = table_cells(result)
    for row, (cells, _) in enumerate(rows, start=2):
        for column, text in enumerate(cells):
            if text:
                sheet.set(f"{chr(65 + column)}{row}", f"'{text}" if column in (2, 6) else text)
    last = len(rows) + 3
    sheet.set(f"A{last}", "Code")
    sheet.set(f"B{last}", f"'{result.code}")
    sheet.setAlias(f"B{last}", "code")
    sheet.set(f"A{last + 1}", "E87")
    sheet.set(f"B{last + 1}", f"'{result.e87}")
    doc.recompute()
    return sheet
