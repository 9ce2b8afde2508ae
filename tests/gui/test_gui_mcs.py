"""The MCS link task panel in a real FreeCAD GUI, driven through the files as an MCS drives it:
parameters edited with validation, commands.txt followed on file-system events and by polling,
and results.txt and the history written exactly as the headless watcher writes them; each scan
answered shown as Run scan shows one (results table, slot code, the arm animated in the view
only) and, on request, stored in the document."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("mcs_probe.py")
ARTIFACTS = REPO / "test-artifacts"

# The states the probe puts the folder in, in order: (parameters.txt, commands.txt).
STATES = [
    ("# from the MCS\nz_step = 0.01\nmode = slow\n", "1 SCF\n2 SCS\n"),
    ("start_z = 600\n", "1 SCF\n2 SCS\n3 FROB\n4 SCF\n"),
    ("z_step = 0.02\n", "1 SCF\n2 SCS\n3 FROB\n4 SCF\n5 SCF\n6 STOP\n"),
]


@pytest.fixture(scope="module")
def folders(run_gui_probe, tmp_path_factory):
    gui = tmp_path_factory.mktemp("gui-mcs")
    probe = run_gui_probe(PROBE, WAFERSCAN_GUI_MCS=str(gui), WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))
    headless = tmp_path_factory.mktemp("headless-mcs")
    for parameters, commands in STATES:
        (headless / "parameters.txt").write_text(parameters, encoding="utf-8")
        (headless / "commands.txt").write_text(commands, encoding="utf-8")
        subprocess.run([sys.executable, "-m", "waferscan.cli", "watch", str(headless), "--once"],
                       check=True, cwd=REPO, capture_output=True, timeout=300)
    return probe, gui, headless


def _comparable(text, folder):
    """The file without what must differ between two runs: the time and the folder's path."""
    text = text.replace(str(folder), "FOLDER")
    return re.sub(r"^timestamp = .*$", "timestamp = -", text, flags=re.MULTILINE)


def test_results_and_history_are_the_headless_watchers(folders):
    _, gui, headless = folders
    def same(relative):
        ours = (gui / relative).read_text(encoding="utf-8")
        theirs = (headless / relative).read_text(encoding="utf-8")
        assert _comparable(ours, gui) == _comparable(theirs, headless), relative
        return ours

    assert "message = stopped the scan of seq 5" in same("results.txt")
    names = sorted(os.listdir(headless / "history"))
    assert names == [f"results-{seq:08d}.txt" for seq in range(1, 7)]
    assert sorted(os.listdir(gui / "history")) == names
    answers = [same(Path("history") / name) for name in names]
    assert "code = 1101221001220001010000010" in answers[0]


def test_the_log_shows_each_command_once_with_its_status(folders):
    probe, gui, _ = folders
    rows = [row[1:4] for row in probe["rows"]]
    assert rows == [["1", "SCF", "ok"], ["2", "SCS", "ok"], ["3", "FROB", "error"],
                    ["4", "SCF", "error"], ["5", "SCF", "error"], ["6", "STOP", "ok"]]
    assert probe["rows"][0][4] == probe["rows"][1][4] == "1101221001220001010000010"
    assert "below start_z" in probe["rows"][3][4]
    assert probe["rows"][4][4] == "stopped by seq 6"
    assert probe["rows_events"][0][1:4] == ["1", "SCF", "ok"]
    assert probe["rows_after_stop"] == 6  # seq 7 waits: nobody watches
    assert "7 SCF" in (gui / "commands.txt").read_text() and "seq = 6" in \
        (gui / "results.txt").read_text()


def test_the_slow_scan_used_the_saved_parameters(folders):
    _, gui, _ = folders
    first = (gui / "history" / "results-00000002.txt").read_text(encoding="utf-8")
    assert "command = SCS" in first and "z_step = 0.01" in first and "mode = slow" in first


def test_parameters_are_validated_before_saving(folders):
    probe, gui, _ = folders
    assert probe["panel_shown"]
    assert "z_step = 0.05" in probe["start_text"]  # the layout's own values, no file yet
    line = probe["bad_line"]
    assert probe["bad_check"].startswith(f"{gui / 'parameters.txt'}:{line}: z_step")
    assert probe["bad_marks"] == [line]
    assert probe["bad_save_enabled"] is False and probe["bad_saved"] is False
    assert probe["good_check"].startswith("valid")
    assert probe["good_saved"] is True
    assert probe["parameters_file"] == STATES[0][0]
    # The MCS rewrote parameters.txt while the panel watched: the editor follows the file.
    assert probe["editor_final"] == STATES[-1][0]


def test_watching_states(folders):
    probe, _, _ = folders
    assert probe["started_events"] and "file-system events" in probe["state_events"]
    assert "polling" not in probe["state_events"]
    assert probe["started_polling"] and "polling every 0.1 s" in probe["state_polling"]
    assert "file-system events and polling every 0.5 s" in probe["state_both"]
    assert probe["state_stopped"] == "not watching"
    assert probe["panel_closed"]
    assert probe["watching_second"] is True and probe["watching_after_folder_edit"] is False
    assert "z_step = 0.05" in probe["editor_after_folder_edit"]  # no file there: the layout's
    assert probe["watching_before_scan"] is True and probe["watching_after_scan"] is False
    assert (ARTIFACTS / "gui-mcs-panel.png").stat().st_size > 1000


def _table(answer):
    """results.txt's table rows (slot, slot_z, wafer, in, out, diff, state) as text."""
    lines = answer.split("\n\n", 1)[1].strip().splitlines()[1:]
    return [line.split("\t")[:7] for line in lines]


def test_an_answered_scan_is_shown_as_run_scan_shows_it(folders):
    probe, gui, _ = folders
    shown = probe["shown_events"]
    answer = (gui / "history" / "results-00000002.txt").read_text(encoding="utf-8")
    assert shown["code"] == "1101221001220001010000010"  # seq 2, the slow scan answered last
    rows = _table(answer)
    assert len(shown["table"]) == len(rows) == 25
    assert [row[0] for row in shown["table"]] == [row[0] for row in rows]
    assert [row[-1] for row in shown["table"]] == [row[6] for row in rows]
    animation = shown["animation"]
    # the scan the MCS asked for (SCS at parameters.txt's 0.01 mm), in the 3D view only
    assert animation["mode"] == "slow" and animation["in_view"] is True
    assert animation["frames"] > 1
    assert probe["placements_unmoved"] is True
    # not stored: the document has no results sheet and no new undo step
    assert probe["store_default"] is False
    assert shown["stored"] == [] and "WaferScan results" not in shown["undo"]
    assert (ARTIFACTS / "gui-mcs-scan.png").stat().st_size > 1000


def test_store_results_keeps_the_scan_in_the_document_as_run_scan_does(folders):
    probe, _, _ = folders
    shown = probe["shown_stored"]
    answer = probe["stored_answer"]
    code = re.search(r"^code = (\S+)$", answer, re.MULTILINE).group(1)
    assert shown["stored"] == ["ScanResults"] and shown["sheet_code"] == code == shown["code"]
    assert shown["undo"][0] == "WaferScan results"
    # the sheet holds the rows the results table shows (its numbers as numbers)
    for stored, row in zip(shown["sheet_rows"], shown["table"][:2]):
        assert [stored[0], stored[2].lstrip("'"), stored[6].lstrip("'")] == \
            [row[0], row[2], row[6]]
        assert [float(stored[c]) for c in (1, 3, 4, 5)] == [float(row[c]) for c in (1, 3, 4, 5)]
    assert shown["table"][0][3] == _table(answer)[0][3]  # the answer's IN of slot 1
    # the arm went up with the scan in the view, the document's placements untouched
    assert probe["moving"]["z"] > 400.0 and probe["moving"]["ended"] is False
    assert probe["moving"]["placements_unmoved"] is True
