# WaferScan: `make demo` and `make test` on a fresh Debian bookworm machine.
# `make setup` (run by both) installs what is missing and is quick when nothing is.

SHELL := /bin/bash
VENV := .venv

.PHONY: setup demo test test-freecad1 docs ci-fresh clean

setup:
	./scripts/setup.sh

demo: setup
	$(VENV)/bin/waferscan demo --out build/demo

# No pytest cache: CI runs this beside test-freecad1 on the same checkout.
test: setup
	$(VENV)/bin/python -m pytest tests -q -p no:cacheprovider

# The same tests on FreeCAD 1.0: in a Debian trixie root (built once, cached in
# /var/cache/waferscan; needs root), with a venv of its own there. See docs/freecad-1.0.md.
test-freecad1:
	./scripts/freecad1-run.sh sh -c 'scripts/setup.sh && "$$WAFERSCAN_VENV/bin/python" -m pytest tests -q -p no:cacheprovider'

# The documentation site, built offline and strictly (a broken link or a page missing from the
# navigation fails it) into build/site; `make test` builds it too (tests/docs).
docs: setup
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir build/site

# The rehearsal of a new machine: .ci/run from a fresh clone of this checkout's HEAD, inside a
# throwaway Debian bookworm root (minbase, cached in /var/cache/waferscan). Needs root.
# See docs/contributing.md.
ci-fresh:
	./scripts/ci-fresh.sh

# Removes what the build made here; the Mod link and system packages stay.
clean:
	rm -rf $(VENV) build test-artifacts .pytest_cache *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
