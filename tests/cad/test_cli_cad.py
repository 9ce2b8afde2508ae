"""The command line through FreeCAD documents: layout, scan of .toml and .FCStd with every engine,
crosscheck, and batch runs in freecadcmd whose exit status is the run's."""

import json
import os

import commands
import pytest
from commands import freecadcmd
from scenarios import PAPER
from scenarios import PAPER_CODE as CODE


def waferscan(*args, check=True):
    done = commands.waferscan(*args)
    if check:
        assert done.returncode == 0, done.stderr
    return done


@pytest.fixture(scope="module")
def paper_layout(tmp_path_factory):
    path = tmp_path_factory.mktemp("layout") / "paper.FCStd"
    done = waferscan("layout", PAPER, "-o", path)
    assert path.is_file() and path.stat().st_size > 1000
    assert str(path) in done.stdout
    return path


def runs(done):
    data = json.loads(done.stdout)
    return data["code"], [(r["in"], r["out"], r["wafers"]) for r in data["runs"]]


def test_scan_of_layout_equals_scan_of_scenario_with_every_engine(paper_layout):
    reference = runs(waferscan("scan", PAPER, "--json"))
    assert reference[0] == CODE
    for engine in ("analytic", "document", "brep", "loop", "vector"):
        assert runs(waferscan("scan", paper_layout, "--json", "--engine", engine)) == reference


def test_crosscheck_confirms_the_demo_to_a_micrometre(paper_layout):
    done = waferscan("crosscheck", paper_layout, "--json")
    data = json.loads(done.stdout)
    assert data["ok"] is True and data["code"] == CODE
    assert 0.0 < data["largest_deviation"] <= 1e-6
    assert len(data["runs"]) == 10 and all(r["blocked_at_edges"] and r["clear_outside"]
                                           for r in data["runs"])
    assert len(data["wafers"]) == 10
    text = waferscan("crosscheck", PAPER).stdout
    assert "confirmed by FreeCAD's B-rep geometry" in text


def test_layout_refuses_a_bad_scenario_and_keeps_an_existing_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(PAPER.read_text().replace("pitch = 10.0", "pitch = -10.0"))
    out = tmp_path / "out.FCStd"
    out.write_bytes(b"previous")
    done = waferscan("layout", bad, "-o", out, check=False)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith(f"waferscan: error: {bad}:")
    assert out.read_bytes() == b"previous"


def test_scan_refuses_an_unreadable_layout(tmp_path):
    broken = tmp_path / "broken.FCStd"
    broken.write_text("not a FreeCAD file")
    done = waferscan("scan", broken, check=False)
    assert done.returncode == 2
    assert done.stderr == f"waferscan: error: {broken}: FreeCAD cannot open it: Invalid project " \
                          f"file: {broken}\n"


def test_scan_refuses_settings_typed_wrong_in_a_saved_layout(paper_layout, tmp_path):
    bad = tmp_path / "bad.FCStd"
    done = freecadcmd(f"import FreeCAD as App; doc = App.openDocument({str(paper_layout)!r}); "
                      f"doc.getObjectsByLabel('ScanSettings')[0].FinalZ = 100.0; "
                      f"doc.saveAs({str(bad)!r})")
    assert bad.is_file(), done.stderr
    done = waferscan("scan", bad, check=False)
    assert done.returncode == 2
    assert done.stderr == f"waferscan: error: {bad}: ScanSettings: final_z (100) is below " \
                          f"start_z (280)\n"


def test_batch_run_in_freecadcmd(paper_layout):
    """The documented batch run (docs/reference/command-line.md): the JSON on stdout is clean,
    the exit status is the run's."""
    done = freecadcmd("import sys, waferscan.cli as c; "
                      f"sys.exit(c.main(['scan', {str(paper_layout)!r}, '--json']))")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["code"] == CODE
    done = freecadcmd("import sys, waferscan.cli as c; "
                      "sys.exit(c.main(['scan', '/nonexistent/layout.FCStd']))")
    assert done.returncode == 2
    assert "waferscan: error: /nonexistent/layout.FCStd: no such file" in done.stderr


def test_commands_run_in_process_close_the_documents_they_open(paper_layout, tmp_path,
                                                               capsys):
    # The console script leaves its documents to the process's end (cad.CLOSE_AFTER_USE);
    # main() called from a program that goes on must not leave them behind.
    import FreeCAD as App

    from waferscan import cad, cli

    assert cad.CLOSE_AFTER_USE is True
    before = set(App.listDocuments())
    assert cli.main(["layout", str(PAPER), "-o", str(tmp_path / "again.FCStd")]) == 0
    assert cli.main(["scan", str(paper_layout)]) == 0
    assert cli.main(["scan", str(PAPER)]) == 0
    assert cli.main(["crosscheck", str(paper_layout)]) == 0
    assert set(App.listDocuments()) == before
    assert CODE in capsys.readouterr().out


def test_the_console_script_leaves_no_cache_folder_behind(paper_layout, tmp_path):
    # It leaves its documents to the process's end, but not FreeCAD's transient folder of
    # each (closing a document removes it; the process's end does not).
    home = tmp_path / "home"
    home.mkdir()
    env = dict(os.environ, FREECAD_USER_HOME=str(home))
    for args in (["scan", paper_layout], ["layout", PAPER, "-o", tmp_path / "x.FCStd"],
                 ["scan", PAPER]):
        done = commands.waferscan(*args, env=env)
        assert done.returncode == 0, done.stderr
    left = list(home.rglob("FreeCAD_Doc_*"))
    assert left == []
