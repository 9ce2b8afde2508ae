"""Issue 27, item 4: the GUI's MCS link and `waferscan watch` write results.txt and the history
byte for byte alike (the timestamp aside) for every command and every failure, side by side on
the same layouts and the same folder states: SCF, SCS, CAL that works and CAL that fails (no top
wafer, no bottom wafer), parameters out of range and malformed, an unknown command, a STOP, a
torn line. The GUI answered a failed CAL "cannot scan the document: CalibrationError: …"."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from scenarios import PAPER, drifted_paper

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("mcs_parity_probe.py")
ARTIFACTS = REPO / "test-artifacts"
LOAD = "1100100001000010000100011"
TAUGHT = "first_slot_z = 293.94\nslot_pitch = 10.0\n"
# (parameters.txt, commands.txt) in turn; commands.txt grows as an MCS appends to it.
STATES = [
    (TAUGHT, "1 CAL\n2 SCF\n"),
    ("start_z = 600\n", "1 CAL\n2 SCF\n3 CAL\n4 SCS\n5 FROB\n"),
    ("z_step = -0.01\nslot_pitch = ten\n", "1 CAL\n2 SCF\n3 CAL\n4 SCS\n5 FROB\n6 CAL\n7 SCF\n"),
    ("", "1 CAL\n2 SCF\n3 CAL\n4 SCS\n5 FROB\n6 CAL\n7 SCF\n8 SCF\n9 STOP\n10 SC11 CAL\n"),
]


@pytest.fixture(scope="module")
def folders(run_gui_probe, tmp_path_factory):
    base = tmp_path_factory.mktemp("mcs-parity")
    layouts = {"paper": PAPER}
    for name, load in (("drifted", LOAD), ("no_bottom", "0" + LOAD[1:])):
        layouts[name] = base / f"{name}.toml"
        layouts[name].write_text(drifted_paper(load), encoding="utf-8")
    pairs = {}
    for name, scenario in layouts.items():
        gui, headless = base / f"gui-{name}", base / f"headless-{name}"
        gui.mkdir()
        headless.mkdir()
        pairs[name] = (gui, headless)
        for parameters, commands in STATES:
            (headless / "parameters.txt").write_text(parameters, encoding="utf-8")
            (headless / "commands.txt").write_text(commands, encoding="utf-8")
            subprocess.run([sys.executable, "-m", "waferscan.cli", "watch", str(headless),
                            "--layout", str(scenario), "--once"],
                           check=True, cwd=REPO, capture_output=True, timeout=300)
    spec = [[str(layouts[name]), str(gui), STATES] for name, (gui, _) in pairs.items()]
    probe = run_gui_probe(PROBE, WAFERSCAN_GUI_PARITY=json.dumps(spec),
                          WAFERSCAN_GUI_ARTIFACTS=str(ARTIFACTS))
    return probe, pairs


def _comparable(text, folder):
    """The file without what must differ between two runs: the time and the folder's path."""
    text = text.replace(str(folder), "FOLDER")
    return re.sub(r"^timestamp = .*$", "timestamp = -", text, flags=re.MULTILINE)


def _message(text):
    return re.search(r"^message =[ ]?(.*)$", text, flags=re.MULTILINE).group(1)


@pytest.mark.parametrize("name", ["paper", "drifted", "no_bottom"])
def test_every_answer_is_the_headless_watchers(folders, name):
    _, pairs = folders
    gui, headless = pairs[name]
    names = sorted(os.listdir(headless / "history"))
    assert names == [f"results-{seq:08d}.txt" for seq in range(1, 12)]
    assert sorted(os.listdir(gui / "history")) == names
    for relative in ["results.txt"] + [f"history/{n}" for n in names]:
        ours = (gui / relative).read_text(encoding="utf-8")
        theirs = (headless / relative).read_text(encoding="utf-8")
        assert _comparable(ours, gui) == _comparable(theirs, headless), relative


def test_the_answers_cover_each_failure(folders):
    probe, pairs = folders
    for name, (gui, _) in pairs.items():
        answers = [(gui / "history" / f"results-{seq:08d}.txt").read_text(encoding="utf-8")
                   for seq in range(1, 12)]
        heads = [re.findall(r"^(command|status) = (.*)$", a, flags=re.MULTILINE)
                 for a in answers]
        commands = [dict(h)["command"] for h in heads]
        assert commands == ["CAL", "SCF", "CAL", "SCS", "FROB", "CAL", "SCF", "SCF", "STOP",
                            "?", "CAL"], name
        messages = [_message(a).replace(str(gui), "FOLDER") for a in answers]
        assert messages[2] == messages[3] == \
            "FOLDER/parameters.txt:1: start_z: final_z (550) is below start_z (600)"
        assert messages[4] == "unknown command 'FROB' (known: SCF, SCS, STOP, CAL, LOAD)"
        assert messages[5] == messages[6] == \
            "FOLDER/parameters.txt:1: z_step: must not be negative, got ' -0.01'"
        assert messages[7:9] == ["stopped by seq 9", "stopped the scan of seq 8"]
        assert messages[9].startswith("torn line '10 SC'")
        # CAL: calibrated on the drifted carrier, each failure in its own words elsewhere.
        cal = {"paper": "no-top-wafer: no wafer in the top slot (slot 25)",
               "no_bottom": "no-bottom-wafer: no wafer in the bottom slot (slot 1)",
               "drifted": "calibrated from the reference wafers in slots 1 and 25"}[name]
        assert messages[0].startswith(cal) and messages[10].startswith(cal), name
        # Every answer has its row in the panel's log: seq, command and status as answered.
        assert [row[1:4] for row in probe["rows"][name]] == \
            [[str(seq), command, dict(h)["status"]]
             for seq, command, h in zip(range(1, 12), commands, heads)], name
