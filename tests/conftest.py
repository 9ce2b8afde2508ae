"""Shared test set-up: the tests folder on sys.path (for the random-layout generator) and the
repository root. Hypothesis runs derandomised, so that every run (CI's too) tries the same
cases and can be repeated; HYPOTHESIS_PROFILE=explore draws new ones, to look for bugs."""

import os
import sys
from pathlib import Path

from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("explore", print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
