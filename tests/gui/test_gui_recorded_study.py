"""Issue 27, recorded scripting: the tolerance study's Run is one line a macro replays. It named
the dialog's temporary output folder (``/tmp/waferscan-sweep-…/out``), which is gone when the
macro is replayed in another session; the line now names the folder the user chose, or none
(then the replayed dialog writes to a temporary folder of its own)."""

import ast
import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().with_name("recorded_study_probe.py")
PREFIX = "waferscan.gui.commands.run_tolerance_study("
N = 40


@pytest.fixture(scope="module")
def gui(run_gui_probe):
    return run_gui_probe(PROBE)


def _arguments(line):
    """The keyword arguments of a recorded run_tolerance_study line, as Python values."""
    assert line.startswith(PREFIX) and line.endswith(")"), line
    call = ast.parse(line).body[0].value
    assert not call.args
    return {k.arg: ast.literal_eval(k.value) for k in call.keywords}


def test_left_empty_the_output_folder_is_a_temporary_one_the_line_does_not_name(gui):
    assert gui["out_default"] == ""
    run = gui["temporary"]
    assert run["state"] == "done", run["errors"]
    assert run["placeholder"] == "(a temporary folder)"
    assert run["out_used"] == os.path.join(run["scratch"], "out") and run["summary_written"]
    assert run["n"] == N
    assert run["out_used"] in run["status"]  # the dialog says where it wrote
    [line] = gui["temporary_line"]
    arguments = _arguments(line)
    assert "out" not in arguments and run["scratch"] not in line
    assert arguments["n"] == N and arguments["workers"] == 0
    assert arguments["input_path"].endswith(os.path.join("resources", "examples", "paper.toml"))
    assert arguments["tolerances"].endswith(os.path.join("resources", "examples",
                                                         "fab_tolerances.toml"))


def test_a_chosen_output_folder_is_named_in_the_line(gui):
    run = gui["chosen_run"]
    assert run["state"] == "done", run["errors"]
    assert run["out_used"] == gui["chosen"] and run["summary_written"]
    [line] = gui["chosen_line"]
    assert _arguments(line)["out"] == gui["chosen"]


def test_each_line_replays_in_a_new_dialog(gui):
    temporary, chosen = gui["replays"]
    for replay in (temporary, chosen):
        assert replay["error"] is None and replay["new_dialog"] is True
        assert replay["state"] == "done", replay["errors"]
        assert replay["n"] == N and replay["summary_written"]
    # none named: the replayed dialog's own temporary folder, not the first dialog's
    assert temporary["out_field"] == ""
    assert temporary["out_used"] == os.path.join(temporary["scratch"], "out")
    assert temporary["scratch"] != gui["temporary"]["scratch"]
    # the chosen folder: written there again
    assert chosen["out_field"] == chosen["out_used"] == gui["chosen"]
