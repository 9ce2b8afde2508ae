"""Issue 25: the hostile corpora end with exit status 0 or 2, never 1 (a traceback). Each corpus
is fixed (a seeded generator), run through the command line in this process (``cli.main``; an
exception escaping it is what a console shows as a traceback and exit 1), and its outcomes are
counted: every case is either carried out (0) or refused in one line naming the file (2).

- TOL.toml: every quantity x every key of each distribution x hostile values (huge, tiny,
  non-finite, negative, wrong types), and broken tables, through ``waferscan sweep``;
- scenarios: 300 mutations of the example layouts (a line deleted, duplicated, swapped, a value
  replaced), through ``waferscan scan``;
- parameters.txt: 300 mutations of the paper's, through ``waferscan scan --params``."""

import contextlib
import io
import random
from collections import Counter

import pytest
from scenarios import EXAMPLES, PAPER

from waferscan import cli
from waferscan.core.files.mcs import format_parameters
from waferscan.core.files.scenario import read_scenario

QUANTITIES = ("seat_offset", "thickness", "tilt", "protrusion", "beam_z", "beam_tilt",
              "sensor_response", "bow")
TABLES = {"uniform": ("lo", "hi"), "normal": ("mean", "sigma"), "fixed": ("value",)}
NOMINAL = {"lo": "0.0", "hi": "0.1", "mean": "0.7", "sigma": "0.01", "value": "0.05"}
HOSTILE = ("1e308", "-1e308", "nan", "inf", "-inf", "1e-320", "0", "-1", '"x"', "true",
           "[1, 2]", "1e999")
BROKEN = [
    "", "\x00\xff junk", "[beam_z]\n", '[beam_z]\ndist = "cauchy"\nvalue = 1\n',
    '[nothing]\ndist = "fixed"\nvalue = 1\n', '[beam_z]\ndist = "uniform"\nlo = 1\nhi = 0\n',
    '[beam_z]\ndist = "fixed"\nvalue = 1\n[beam_z]\ndist = "fixed"\nvalue = 2\n',
    '[beam_z]\ndist = "fixed"\nvalue = 0\nextra = 3\n', "[states]\npresent = -1\n",
    "[states]\npresent = 2\n", "[states]\npresent = nan\n", "[states]\nunknown = 1\n",
    "[states]\npresent = 0\nempty = 0\n", "[states]\npresent = 0.5\n", "beam_z = 3\n",
    '[beam_z]\ndist = "normal"\nmean = 0\n', '[beam_z]\ndist = 3\nvalue = 1\n',
]


def run(*args):
    """(exit status, stderr) of ``waferscan ARGS`` in this process; 1 for an exception that
    escapes the command line (a traceback in a console)."""
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = cli.main([str(a) for a in args])
        except SystemExit as exc:
            code = exc.code
        except Exception as exc:  # noqa: BLE001 (what this test counts)
            return 1, f"{type(exc).__name__}: {exc}"
    return code, err.getvalue()


def tally(cases, command, path):
    """Each case written to ``path`` and run; {status: count}, and the cases that gave 1."""
    outcomes, failures = Counter(), []
    tally.accepted = []
    for text in cases:
        path.write_text(text, encoding="utf-8", errors="surrogateescape")
        code, err = run(*command)
        outcomes[code] += 1
        if code == 0:
            tally.accepted.append(text)
        if code not in (0, 2) or (code == 2 and (err.count("\n") != 1 or
                                                 "Traceback" in err)):
            failures.append((text, code, err[-500:]))
    return outcomes, failures


def tol_corpus():
    cases = []
    for quantity in QUANTITIES:
        for dist, keys in TABLES.items():
            for key in keys:
                for value in HOSTILE:
                    lines = [f"[{quantity}]", f'dist = "{dist}"']
                    lines += [f"{k} = {value if k == key else NOMINAL[k]}" for k in keys]
                    cases.append("\n".join(lines) + "\n")
    return cases + BROKEN


def test_the_hostile_tol_corpus_ends_with_exit_0_or_2(tmp_path):
    tol = tmp_path / "TOL.toml"
    cases = tol_corpus()
    outcomes, failures = tally(cases, ["sweep", PAPER, "--tolerances", tol, "-n", "20",
                                       "--workers", "0"], tol)
    assert not failures, failures[:5]
    assert sum(outcomes.values()) == len(cases) == 497 and outcomes[1] == 0, outcomes
    assert outcomes[0] > 0 and outcomes[2] > 0, outcomes
    # Nothing huge, non-finite or of the wrong type is swept (it gave nonsense summaries).
    nonsense = ("1e308", "nan", "inf", "1e999", '"x"', "true", "[1, 2]")
    assert not [t for t in tally.accepted if any(v in t for v in nonsense)]
    print(f"TOL.toml: {len(cases)} cases, {dict(outcomes)}")


def mutated(text, rng, values):
    lines = text.splitlines()
    index = rng.randrange(len(lines))
    how = rng.choice(["delete", "value", "value", "duplicate", "swap"])
    if how == "delete":
        del lines[index]
    elif how == "duplicate":
        lines.insert(index, lines[index])
    elif how == "swap":
        other = rng.randrange(len(lines))
        lines[index], lines[other] = lines[other], lines[index]
    elif "=" in lines[index]:
        lines[index] = f"{lines[index].split('=')[0]}= {rng.choice(values)}"
    return "\n".join(lines) + "\n"


VALUES = ("nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-1", "-0", "1e999",
          '"x"', '"22"', '""', "true", "[]", "[0, 0, 0]", "[1, 2]", "{}", "12345678901234567890",
          "0.5", "-3.5", "1000000", '"LP1"', '"fast"', '"slow"', "\x00", "'", "[[1]]")


def test_the_fuzzed_scenario_corpus_ends_with_exit_0_or_2(tmp_path):
    rng = random.Random(25)
    texts = [(EXAMPLES / name).read_text() for name in ("paper.toml", "slow_jab.toml",
                                                         "calibration_drifted.toml")]
    cases = [mutated(texts[i % 3], rng, VALUES) for i in range(300)]
    scenario = tmp_path / "fuzzed.toml"
    outcomes, failures = tally(cases, ["scan", scenario], scenario)
    assert not failures, failures[:5]
    assert sum(outcomes.values()) == 300 and outcomes[1] == 0, outcomes
    print(f"scenarios: 300 cases, {dict(outcomes)}")


@pytest.mark.parametrize("seed", [25])
def test_the_fuzzed_parameters_corpus_ends_with_exit_0_or_2(tmp_path, seed):
    rng = random.Random(seed)
    text = format_parameters(read_scenario(PAPER))
    values = VALUES + ("fast", "slow", "up", "down", "updown", "LP1", "25", "0.05", "250")
    cases = [mutated(text, rng, values) for _ in range(300)]
    params = tmp_path / "parameters.txt"
    outcomes, failures = tally(cases, ["scan", PAPER, "--params", params], params)
    assert not failures, failures[:5]
    assert sum(outcomes.values()) == 300 and outcomes[1] == 0, outcomes
    print(f"parameters.txt: 300 cases, {dict(outcomes)}")
