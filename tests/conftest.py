"""Shared fixtures: simulations are cached per session so the suite runs each case once.

Plain helpers live in `tests/helpers.py`; `IDEAL`, `RAMP`, `faults` and `frictionless` are
re-exported here only for files that still import them from `tests.conftest`.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import emaphm
from emaphm import EmaParams
from tests.helpers import IDEAL, RAMP, faults, frictionless

__all__ = ["IDEAL", "RAMP", "faults", "frictionless"]  # re-exported (see the docstring)


@cache
def _sim(k: tuple[float, ...], command: object, ideal: bool, params: EmaParams | None) -> emaphm.SimResult:
    p = params if params is not None else (IDEAL if ideal else EmaParams())
    return emaphm.simulate(np.array(k), noise=False, params=p, command=command)  # type: ignore[arg-type]


@pytest.fixture(scope="session")
def sim():
    """sim(k, command=None, ideal=True, params=None) -> SimResult, noise off, cached per session."""

    def run(k, command=None, ideal=True, params=None):  # type: ignore[no-untyped-def]
        return _sim(tuple(float(v) for v in k), command, ideal, params)

    return run


@pytest.fixture
def small_polish(monkeypatch):
    """The round CMA-ES polish at 16 x 50 instead of the shipped 32 x 50 (`limits.POLISH_BUDGET`:
    the final checks' polish, and the best point's under ``POLISH_ROUTE = "round"``): same
    accuracy on the test cases (measured; see the tests that use it)."""
    from emaphm.identification import limits

    budget = (16, 50)
    monkeypatch.setattr(limits, "POLISH_BUDGET", budget)
    return budget


def pytest_sessionfinish(session, exitstatus):
    """A session in which no test passed is a failure, also when everything was skipped (CI)."""
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is None or session.config.option.collectonly:
        return
    if exitstatus == 0 and not reporter.stats.get("passed"):
        session.exitstatus = 5  # pytest's "no tests ran"
