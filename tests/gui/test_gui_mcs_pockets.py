"""Issue 27 item 11: a slow scan with jabs and sweeps that the MCS asks for through the GUI's MCS
link is shown as Run scan shows it: after the Z steps the arm jabs and sweeps pocket by pocket in
the document (the same animation, gui/pocket_animation.py). A command the MCS sends while the
pockets still play ends them first, so the scan it asks for reads the arm in its start pose."""

import dataclasses
import re
from pathlib import Path

import pytest

from waferscan.core.files.scenario import read_scenario
from waferscan.core.scan import slow_scan
from waferscan.core.scan.layout_scan import scan_layout

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "resources" / "examples" / "slow_jab.toml"
PROBE = Path(__file__).resolve().with_name("mcs_pockets_probe.py")
ARTIFACTS = REPO / "test-artifacts"
LAYOUT = read_scenario(EXAMPLE)


@pytest.fixture(scope="module")
def gui(run_gui_probe, tmp_path_factory):
    folder = tmp_path_factory.mktemp("mcs-pockets")
    (ARTIFACTS / "gui-mcs-jab.png").unlink(missing_ok=True)
    probe = run_gui_probe(PROBE, WAFERSCAN_GUI_SCENARIO=str(EXAMPLE),
                          WAFERSCAN_GUI_MCS=str(folder), WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))
    return probe, folder


def _code(answer):
    return re.search(r"^code = (\S+)$", answer, re.MULTILINE).group(1)


def test_the_mcs_slow_scan_animates_its_pockets(gui):
    probe, folder = gui
    slow = scan_layout(LAYOUT)
    answer = (folder / "history" / "results-00000001.txt").read_text(encoding="utf-8")
    # SPEC §13 amended, §15: slow_jab.toml's sweeps stop short of the wafers, so no motion is a
    # contact and the MCS is answered ok, with the code (the stopped sweeps judge no position:
    # slot 3 reads 1 where the core's whole ±40° finds its shift, 5).
    assert re.search(r"^status = ok$", answer, re.MULTILINE), answer
    assert not re.search(r"^collision = ", answer, re.MULTILINE), answer
    assert _code(answer) == "1111221601220001010000010"
    assert slow.code == "1151221601220001010000010"
    assert probe["rows"][0][1:4] == ["1", "SCS", "ok"]
    played = probe["pockets_of"]
    assert played["doc"] and played["code"] == _code(answer) and played["panel_kept"]
    assert played["slots"] == [p.slot for p in slow.pockets]


def test_the_jab_moves_the_robot_in_the_document_where_the_closed_form_puts_the_beam(gui):
    probe, _ = gui
    jab = probe["jab"]
    slot, phase, z, advance, turn = jab["frame"]
    assert (slot, phase, advance, turn) == (8, "jab", pytest.approx(20.0), 0.0)
    emitter, beam = slow_scan.beam_at(LAYOUT, z, advance, turn)
    assert jab["emitter"] == pytest.approx(list(emitter), abs=1e-6)
    assert jab["direction"] == pytest.approx(list(beam.direction), abs=1e-9)
    assert abs(jab["fork"][1] - probe["fork_start"][1]) == pytest.approx(20.0, abs=1e-6)
    assert jab["blocked"] is True  # slot 8's wafer protrudes 5 mm: the jab's end meets it
    assert (ARTIFACTS / "gui-mcs-jab.png").stat().st_size > 10_000


def test_a_command_sent_while_the_pockets_play_ends_them_and_reads_the_start_pose(gui):
    probe, folder = gui
    assert probe["rows_after"][1][1:4] == ["2", "SCF", "ok"]
    assert probe["pockets_ended_before"] is True
    assert probe["restored_after"] is True  # every placement as before the scans
    fast = dataclasses.replace(LAYOUT, scan=dataclasses.replace(LAYOUT.scan, mode="fast"))
    answer = (folder / "history" / "results-00000002.txt").read_text(encoding="utf-8")
    # the beam 10 mm in front of the seated wafers (not jabbed 20 mm into slot 8's pocket)
    assert _code(answer) == scan_layout(fast).code == "0000000600000000000000000"
