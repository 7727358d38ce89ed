"""Test-session settings shared by every test module.

Hypothesis profiles (issue 33, item 6): in CI (environment variable ``CI`` set to ``true``/``1``,
:func:`tests.real_corpus.in_ci`) the ``ci`` profile is loaded: examples are derived from each
test's name (``derandomize=True``), so a run can fail only where every run fails, and no example
database is kept (``database=None``), so a failure drawn once is not replayed into later runs. On a
developer's machine hypothesis keeps its defaults (random draws, a local database), which is
where new counter-examples are found; ``HYPOTHESIS_PROFILE=ci`` selects the CI profile there too.
A test's own ``@settings`` still sets the fields it names (``max_examples``, ``deadline``).

Figures: every test's open matplotlib figures are closed after it (:func:`close_figures`), so
that the figures the plotting tests draw do not pile up over a session (past 20, pyplot warns
"More than 20 figures have been opened" in whichever test opens the 21st, e.g. in
``tests/test_risk.py`` after ``test_cli``, ``test_figures_cli``, ``test_record_figure`` and
``test_report_plot`` had left 20 open).
"""

from __future__ import annotations

import os
import sys

import pytest
from hypothesis import settings

from tests.real_corpus import in_ci

settings.register_profile("ci", derandomize=True, database=None, print_blob=True)
settings.register_profile("dev")

settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if in_ci() else "dev"))


@pytest.fixture(autouse=True)
def close_figures():
    """Close the matplotlib figures a test left open (pyplot is looked up, not imported, so that
    a test process that never draws does not load it)."""
    yield
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close("all")
