"""The README's and the documentation's examples, run as tests (Sybil).

Every fenced block of README.md and docs/**/*.md is an example, by its language:

- ``console``: each line that starts with ``$ `` is a command, run with bash (``pipefail``); a
  command ending in a backslash goes on on the next line. The lines after it, up to the next
  command, are what it must print (standard output and error together, as a terminal shows
  them), ``...`` standing for any text and trailing spaces ignored. A command must exit 0,
  unless its output ends with a line ``[exit N]``.
- ``python``: run in one namespace per page (``>>>`` blocks as doctests).
- ``toml`` and ``ini`` with a title (```` ```toml title="my.toml" ````): a file the page tells
  its reader to write; it is written, so the commands after it use it, and a ``.toml`` one must
  be valid TOML. Without a title a ``toml`` block must still be valid TOML.
- ``text`` and ``json`` blocks are shown output or syntax, not run. Any other language (``sh``
  among them) fails: a command is shown as ``console`` so that it is tested.

A block that cannot run here (``make test`` itself, the GUI, a long benchmark) is preceded by
``<!-- skip: next "the reason" -->``. A hidden set-up is an ``<!-- invisible-code: python -->``
comment.

Each page runs in a folder of its own: ``resources`` there is the repository's, ``.venv/bin``
is the bin folder of the Python running the tests (``/opt/waferscan-venv/bin`` in the FreeCAD
1.0 root) and comes first on PATH, and FreeCAD's user folder is a fresh one holding the addon's
link to this checkout.
"""

from __future__ import annotations

import difflib
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import pytest
from sybil import Sybil
from sybil.integration.pytest import SybilFile
from sybil.parsers.markdown import PythonCodeBlockParser, SkipParser
from sybil.parsers.markdown.lexers import FencedCodeBlockLexer

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
BIN = Path(sys.executable).parent  # not resolved: the venv's bin folder, not /usr/bin
COMMAND_TIMEOUT = 300  # s; a command here takes a few seconds

EXIT_LINE = re.compile(r"^\[exit (\d+)\]$")
TITLE = re.compile(r'title="([^"]+)"')
FILE_LANGUAGES = {"toml", "ini"}
SHOWN_LANGUAGES = {"text", "json"}


def documents():
    """The pages whose examples are tested: the README and every page of the site."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


# --- Matching shown output ------------------------------------------------------------------

def _normalise(text):
    lines = [line.rstrip() for line in text.replace("\r\n", "\n").split("\n")]
    while lines and not lines[-1]:
        lines.pop()
    return "\n".join(lines)


def output_matches(want, got):
    """``got`` matches ``want`` where each ``...`` of ``want`` stands for any text (possibly
    empty, possibly several lines), as doctest's ELLIPSIS reads it."""
    want, got = _normalise(want), _normalise(got)
    pieces = want.split("...")
    if len(pieces) == 1:
        return want == got
    first, *middle, last = pieces
    if not got.startswith(first) or not got.endswith(last):
        return False
    start, end = len(first), len(got) - len(last)
    if start > end:
        return False
    for piece in middle:
        found = got.find(piece, start, end)
        if found < 0:
            return False
        start = found + len(piece)
    return True


# --- Console blocks ---------------------------------------------------------------------------

def console_steps(source):
    """(command, shown output, expected exit status) for each ``$ `` command of a block."""
    steps, lines, i = [], source.split("\n"), 0
    while i < len(lines):
        line = lines[i]
        if not line.startswith("$ "):
            if line.strip():
                raise ValueError(f"text before the block's first command: {line!r}")
            i += 1
            continue
        command = line[2:]
        while command.endswith("\\") and i + 1 < len(lines):
            i += 1
            command += "\n" + lines[i]  # bash reads backslash-newline as a continuation
        i += 1
        shown = []
        while i < len(lines) and not lines[i].startswith("$ "):
            shown.append(lines[i])
            i += 1
        while shown and not shown[-1].strip():
            shown.pop()
        status = 0
        if shown and EXIT_LINE.match(shown[-1].strip()):
            status = int(EXIT_LINE.match(shown[-1].strip()).group(1))
            shown.pop()
        steps.append((command, "\n".join(shown), status))
    if not steps:
        raise ValueError("a console block without a command ($ ...)")
    return steps


def run_command(command, page):
    """Run one shown command as a reader would, in the page's folder; (status, output). The
    command runs in a process group of its own, ended whole if it outlives its time."""
    process = subprocess.Popen(["bash", "-o", "pipefail", "-c", command], cwd=page.folder,
                               env=page.env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, start_new_session=True)
    try:
        output, _ = process.communicate(timeout=COMMAND_TIMEOUT)
    except BaseException:  # the timeout, or Ctrl-C
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise
    return process.returncode, output.decode("utf-8", errors="replace")


def evaluate_console(example):
    page = example.namespace["page"]
    for command, want, status in console_steps(example.parsed):
        code, got = run_command(command, page)
        problems = []
        if code != status:
            problems.append(f"exit status {code}, expected {status}")
        if not output_matches(want, got):
            diff = difflib.unified_diff(_normalise(want).split("\n"),
                                        _normalise(got).split("\n"), "shown", "printed",
                                        lineterm="")
            problems.append("output differs:\n" + "\n".join(diff))
        if problems:
            return f"$ {command}\n" + "\n".join(problems) + f"\n--- printed ---\n{got}"
    return None


# --- Files the reader is told to write ---------------------------------------------------------

def evaluate_file(example):
    language, title = example.parsed[0], example.parsed[1]
    text = example.parsed[2]
    if language == "toml":
        try:
            tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            return f"not valid TOML: {exc}"
    example.namespace["shown_files"][title or f"<{language} block>"] = text
    if title:
        path = example.namespace["page"].folder / title
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return None


def refuse(example):
    return (f"a ```{example.parsed} block is not tested: show commands as ```console "
            f"(skip them with a reason if they cannot run), output as ```text")


class FencedBlockParser:
    """Every fenced block but Python's (PythonCodeBlockParser has those): console blocks run,
    files written, shown output left alone, anything else refused."""

    def __init__(self):
        self.lexer = FencedCodeBlockLexer(language=r".+", mapping={"language": "info",
                                                                   "source": "source"})

    def __call__(self, document):
        for region in self.lexer(document):
            info = region.lexemes["info"].strip()
            language = info.split()[0]
            if info == "python" or language in SHOWN_LANGUAGES:
                continue  # PythonCodeBlockParser's, or shown only
            if language == "console":
                region.parsed = str(region.lexemes["source"])
                region.evaluator = evaluate_console
            elif language in FILE_LANGUAGES:
                title = TITLE.search(info)
                region.parsed = (language, title.group(1) if title else None,
                                 str(region.lexemes["source"]))
                region.evaluator = evaluate_file
            else:
                region.parsed = language
                region.evaluator = refuse
            yield region


# --- One folder per page ---------------------------------------------------------------------

class Page:
    """A page's folder and environment, and the processes its hidden set-up started."""

    def __init__(self):
        self.folder = Path(tempfile.mkdtemp(prefix="waferscan-docs-"))
        (self.folder / "resources").symlink_to(ROOT / "resources")
        if sys.prefix != sys.base_prefix:  # the venv itself: its python finds pyvenv.cfg
            (self.folder / ".venv").symlink_to(sys.prefix)
        else:
            (self.folder / ".venv").mkdir()
            (self.folder / ".venv" / "bin").symlink_to(BIN)
        home = self.folder / ".freecad-home"
        (home / "Mod").mkdir(parents=True)
        (home / "Mod" / "WaferScan").symlink_to(ROOT)
        self.env = dict(os.environ,
                        PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}",
                        FREECAD_USER_HOME=str(home),
                        # freecadcmd finds the venv's packages (pinocchio) through the addon
                        WAFERSCAN_VENV=os.environ.get("WAFERSCAN_VENV") or sys.prefix,
                        PYTHONUNBUFFERED="1",  # the order a terminal shows
                        PYTHONIOENCODING="utf-8")
        self.env.pop("PYTHONPATH", None)
        self.processes = []
        self.cwd = os.getcwd()

    def start(self, command, **kwargs):
        """Start a background process for the page (a Dask scheduler...); it ends with it."""
        process = subprocess.Popen(command, cwd=self.folder, env=self.env,
                                   start_new_session=True, **kwargs)
        self.processes.append(process)
        return process

    def stop(self):
        """End the processes ``start`` started, each with its process group."""
        for process in self.processes:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in self.processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()
        self.processes = []

    def close(self):
        self.stop()
        os.chdir(self.cwd)
        shutil.rmtree(self.folder, ignore_errors=True)


def setup(namespace):
    page = Page()
    namespace["page"] = page
    namespace["shown_files"] = {}
    namespace["REPO"] = ROOT
    namespace["scenario_with"] = scenario_with
    os.chdir(page.folder)  # the Python examples' relative paths, as the console's


def teardown(namespace):
    namespace["page"].close()


SYBIL = Sybil(
    parsers=[SkipParser(), PythonCodeBlockParser(), FencedBlockParser()],
    setup=setup,
    teardown=teardown,
)


class Examples(pytest.File):
    """The pages' examples, collected from here (this folder's conftest.py) because the pages
    themselves lie outside the tests' folders."""

    def collect(self):
        for path in documents():
            yield SybilFile.from_parent(self, path=path, sybils=[SYBIL])


def pytest_collect_file(file_path, parent):
    if file_path == Path(__file__):
        return Examples.from_parent(parent, path=file_path)
    return None


# --- Scenario fragments -----------------------------------------------------------------------

def scenario_with(fragment, base="resources/examples/paper.toml"):
    """The ``Layout`` of a scenario (by default the paper's) with a page's TOML fragment added:
    each key of the fragment goes into the scenario's first table of the same header, so a
    fragment that shows a few keys of [sensor], [scan] and [[carrier]] is read as a whole
    scenario by WaferScan's own reader."""
    from waferscan.core.files.scenario import parse_scenario

    lines = (ROOT / base).read_text(encoding="utf-8").split("\n")
    header, added = None, {}
    for line in fragment.split("\n"):
        if line.strip().startswith("["):
            header = line.split("#")[0].strip()
        elif line.split("#")[0].strip():
            if header is None:
                raise ValueError(f"a key outside any table: {line!r}")
            added.setdefault(header, []).append(line)
    for header, keys in added.items():
        at = next(i for i, line in enumerate(lines) if line.split("#")[0].strip() == header)
        lines[at + 1:at + 1] = keys
    return parse_scenario("\n".join(lines), f"{base} with the page's fragment",
                          folder=(ROOT / base).parent)
