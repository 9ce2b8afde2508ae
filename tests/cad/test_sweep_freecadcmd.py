"""``waferscan sweep`` in the documented ``freecadcmd -c`` form: Dask's local workers start
(with the venv's Python, not freecadcmd) and the summary is the library's for the same seed,
although FreeCAD's Python runs Debian's numpy 1.24 and the venv numpy 2.x."""

import json
import os

from commands import freecadcmd
from scenarios import EXAMPLES, PAPER

from waferscan.core.files.scenario import read_scenario
from waferscan.core import sweep
from waferscan.core.sweep.distributions import read_tolerances

TOLERANCES = EXAMPLES / "fab_tolerances.toml"


def test_sweep_under_freecadcmd_with_two_workers_gives_the_librarys_summary(tmp_path):
    args = ["sweep", str(PAPER), "--tolerances", str(TOLERANCES), "-n", "900", "--seed", "3",
            "--workers", "2", "--json"]
    script = f"import waferscan.cli as c, sys; sys.exit(c.main({args!r}))"
    # A FreeCAD home of its own: the FreeCAD 1.0 suite may run beside this one on the checkout.
    env = dict(os.environ, FREECAD_USER_HOME=os.environ.get("FREECAD_USER_HOME",
                                                            str(tmp_path / "fchome")))
    done = freecadcmd(script, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    summary = json.loads(done.stdout[done.stdout.index("{"):])
    expected = sweep.run_sweep(read_scenario(PAPER), read_tolerances(TOLERANCES), 900, seed=3)
    assert summary == json.loads(json.dumps(expected))


def test_a_layout_fcstd_sweeps_as_its_scenario_does(tmp_path, capsys):
    """INPUT as a FreeCAD layout: its wafers, read back from the document, are placed in the
    same states and give the scenario's summary, seed for seed."""
    from waferscan import cli

    layout = tmp_path / "paper.FCStd"
    assert cli.main(["layout", str(PAPER), "-o", str(layout)]) == 0
    capsys.readouterr()
    outputs = []
    for source in (layout, PAPER):
        assert cli.main(["sweep", str(source), "--tolerances", str(TOLERANCES), "-n", "700",
                         "--seed", "9", "--workers", "0", "--json"]) == 0
        outputs.append(json.loads(capsys.readouterr().out))
    assert outputs[0] == outputs[1]
    assert outputs[0]["confusion"]["cross"]["cross"] > 0
