"""The documentation as a whole: the site builds strictly and offline, the README stays one short
page that starts with the two commands, and every page of the site can be reached from it.
(Each page's examples are run by conftest.py.)"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
MAX_README_LINES = 150
TWO_COMMANDS = [
    "make demo   # installs everything, then runs the paper's experiment headless (output in "
    "build/demo)",
    "make test   # runs all tests (core, FreeCAD headless, FreeCAD GUI under Xvfb)",
]

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
QUIET = dict(os.environ, NO_MKDOCS_2_WARNING="1")  # Material's notice of its successor
FENCE = re.compile(r"^[ \t]*(`{3,}|~{3,})(.*)$")


def fenced_blocks(text):
    """(line number, info string, body) of each fenced code block."""
    blocks, opened, body = [], None, []
    for number, line in enumerate(text.splitlines(), start=1):
        match = FENCE.match(line)
        if opened is None and match:
            opened, body = (number, match.group(1), match.group(2).strip()), []
        elif opened is not None and match and match.group(1).startswith(opened[1]) \
                and not match.group(2).strip():
            blocks.append((opened[0], opened[2], "\n".join(body)))
            opened = None
        elif opened is not None:
            body.append(line)
    return blocks


def prose(text):
    """The text without its fenced code blocks and inline code: where links are."""
    kept, inside = [], False
    for line in text.splitlines():
        if FENCE.match(line):
            inside = not inside
            continue
        if not inside:
            kept.append(re.sub(r"`[^`]*`", "", line))
    return "\n".join(kept)


def relative_links(path):
    """The targets of the page's relative links and images, without their #anchors."""
    targets = []
    for target in LINK.findall(prose(path.read_text(encoding="utf-8"))):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue
        targets.append(target.split("#", 1)[0])
    return targets


def pages():
    return sorted(DOCS.rglob("*.md"))


# --- The site ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """`make docs`' build, strict: a broken link or anchor, or a page left out of the
    navigation, is a warning and fails it."""
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict",
                           "--site-dir", str(out)], cwd=ROOT, capture_output=True, text=True,
                          timeout=600, env=QUIET)
    assert done.returncode == 0, f"mkdocs build --strict failed:\n{done.stdout}\n{done.stderr}"
    return out


def test_the_site_builds_strictly_with_every_page(site):
    for page in pages():
        built = site / page.relative_to(DOCS).with_suffix(".html")
        assert built.is_file(), f"{page} was not built"
    api = (site / "reference" / "python-api.html").read_text(encoding="utf-8")
    assert "scan_layout" in api and "read_scenario" in api  # mkdocstrings rendered the API
    licence = (site / "licence.html").read_text(encoding="utf-8")
    assert "GNU LESSER GENERAL PUBLIC LICENSE" in licence  # the LICENSE file, included


def test_every_picture_is_shown_on_a_page():
    shown = {(page.parent / target).resolve() for page in pages()
             for target in relative_links(page)}
    unused = [p.name for p in sorted(DOCS.rglob("*.png")) if p.resolve() not in shown]
    assert not unused, f"pictures no page shows: {unused}"


def test_the_site_fetches_nothing_from_the_network(site):
    # No web fonts, scripts or styles from elsewhere: the site reads offline.
    for html in site.rglob("*.html"):
        text = html.read_text(encoding="utf-8")
        remote = re.findall(r"<(?:link|script|img)\b[^>]*\b(?:href|src)=\"(https?:[^\"]+)\"",
                            text)
        assert not remote, f"{html.relative_to(site)} loads {remote}"
        assert "fonts.googleapis" not in text and "fonts.gstatic" not in text


def test_the_strict_build_fails_on_a_broken_link(tmp_path):
    """The strictness is real: with this configuration a page with a broken link does not build
    (a one-page copy of the site, to be quick: the missing pages' warnings aside, the broken
    link is named)."""
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\n[missing](no-such-page.md)\n", encoding="utf-8")
    shutil.copy(ROOT / "mkdocs.yml", tmp_path / "mkdocs.yml")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                           str(tmp_path / "site")], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600, env=QUIET)
    assert done.returncode != 0
    assert "contains a link 'no-such-page.md'" in done.stderr, done.stderr


# --- The README ---------------------------------------------------------------------------------

def test_the_readme_fits_in_two_screens():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_README_LINES, f"README.md has {len(lines)} lines"


def test_the_readme_starts_with_the_two_commands():
    text = README.read_text(encoding="utf-8")
    blocks = fenced_blocks(text)
    assert blocks, "README.md has no code block"
    line, _, body = blocks[0]
    assert body.splitlines() == TWO_COMMANDS
    first_section = next(n for n, l in enumerate(text.splitlines(), start=1) if l.startswith("## "))
    assert line < first_section, "the two commands come before the README's first section"


def test_every_relative_link_of_the_readme_resolves():
    targets = relative_links(README)
    assert targets
    missing = [t for t in targets if not (ROOT / t).exists()]
    assert not missing, f"README.md links to missing files: {missing}"


def test_every_page_is_reachable_from_the_readme():
    from_readme = {(ROOT / t).resolve() for t in relative_links(README)}
    index = (DOCS / "index.md").resolve()
    assert index in from_readme, "README.md links to docs/index.md"
    from_index = {(DOCS / t).resolve() for t in relative_links(DOCS / "index.md")}
    unreachable = [str(p.relative_to(ROOT)) for p in pages()
                   if p.resolve() not in from_readme | from_index]
    assert not unreachable, f"not linked from README.md or docs/index.md: {unreachable}"


def test_every_code_block_names_its_language():
    # A block without a language would escape the examples' tests (conftest.py).
    for path in [README, *pages()]:
        for line, info, _ in fenced_blocks(path.read_text(encoding="utf-8")):
            assert info, f"{path.relative_to(ROOT)}:{line}: a code block without a language"
