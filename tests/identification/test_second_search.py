"""The second search a poor fit starts (issue 8, item 3: no wrong basins)."""

from __future__ import annotations

import numpy as np
import pytest

import emaphm
from emaphm.commands import Chirp
from emaphm.identification import identify as identify_module
from emaphm.identification import optimizers
from emaphm.identification.identify import (
    FIT_NRMSE_LIMIT,
    SECOND_SEARCH_NRMSE,
    FaultIdentifier,
    _Search,
    identify,
    second_seed,
)
from emaphm.identification.optimizers import OptimizerRun
from emaphm.models import MonitorEma

FAULTS = [0.3, 0, 0, 0.3, 0, 0, 0, 0.5]
TRIGGER = SECOND_SEARCH_NRMSE["default"]


@pytest.fixture(scope="module")
def trace():
    return emaphm.simulate(FAULTS, seed=5)


def canned(by_seed):
    """A stand-in for `FaultIdentifier._search`: the search from each seed as given (x, f, fit NRMSE)."""

    def search(self, evaluate, seed):
        x, f, fit = by_seed[seed]
        run = OptimizerRun(np.full(8, x), f, 100, [f])
        return _Search(run, fit, None, False, None, f"move {seed}", None, 1.0)

    return search


@pytest.mark.parametrize(
    ("first_fit", "second_f", "taken"),
    [
        (2 * TRIGGER, 0.5, True),  # a poor fit, a better basin found: taken
        (2 * TRIGGER, 2.0, False),  # a poor fit, nothing better: the first kept
    ],
)
def test_a_poor_fit_searches_again_and_keeps_the_better(trace, monkeypatch, first_fit, second_f, taken):
    other = second_seed(7)
    monkeypatch.setattr(
        FaultIdentifier, "_search", canned({7: (0.1, 1.0, first_fit), other: (0.4, second_f, 0.01)})
    )
    ident = FaultIdentifier(seed=7).fit(trace.t, trace.i_q, Chirp())
    record = ident.second_search_
    assert record is not None and record["taken"] is taken and record["seed"] == other
    assert record["first_fit_nrmse"] == first_fit and record["fitness_ratio"] == pytest.approx(second_f)
    assert ident.fitness_ == min(1.0, second_f) and ident.run_.evaluations == 200  # both searches counted
    assert ident.fit_nrmse_ == (0.01 if taken else first_fit)
    assert ident.short_move_ == f"move {other if taken else 7}"  # the kept search's record
    assert ident.faults_[0] == pytest.approx(0.4 if taken else 0.1)


@pytest.mark.parametrize(
    ("fit", "settings"),
    [
        (0.9 * TRIGGER, {}),  # the monitor's usual fit: one search
        (1.1 * FIT_NRMSE_LIMIT, {}),  # no fit at all (units, signs): a recording problem, not a basin
        (2 * TRIGGER, {"second_search": False}),
        (2 * TRIGGER, {"local_polish": False}),  # a raw search was asked for
    ],
)
def test_no_second_search_where_it_cannot_help_or_was_not_asked(trace, monkeypatch, fit, settings):
    monkeypatch.setattr(FaultIdentifier, "_search", canned({7: (0.1, 1.0, fit)}))  # any other seed: KeyError
    ident = FaultIdentifier(seed=7, **settings).fit(trace.t, trace.i_q, Chirp())
    assert ident.second_search_ is None and ident.run_.evaluations == 100


def test_each_monitor_has_its_own_trigger(trace, monkeypatch):
    # the paper's monitor fits the twin worse as a rule: a fit between the two triggers searches
    # again with the default monitor only
    between = 0.5 * (SECOND_SEARCH_NRMSE["default"] + SECOND_SEARCH_NRMSE["paper"])
    assert SECOND_SEARCH_NRMSE["default"] < between < SECOND_SEARCH_NRMSE["paper"]
    monkeypatch.setattr(
        FaultIdentifier, "_search", canned({7: (0.1, 1.0, between), second_seed(7): (0.2, 0.9, 0.01)})
    )
    ran = {}
    for name in ("default", "paper"):
        ident = FaultIdentifier(seed=7, monitor=MonitorEma(monitor=name)).fit(trace.t, trace.i_q, Chirp())
        ran[name] = ident.second_search_
    assert ran["paper"] is None and ran["default"]["trigger"] == SECOND_SEARCH_NRMSE["default"]


def test_the_kept_result_is_the_better_of_the_two_searches_run_alone(trace, monkeypatch):
    # a small search (pop 16 x 3, a tiny polish) fits this actuator to 2.2 % at every seed tried:
    # a trigger below that must start the second search
    monkeypatch.setattr(optimizers, "POLISH_BUDGET", (8, 2))
    monkeypatch.setitem(identify_module.SECOND_SEARCH_NRMSE, "default", 0.02)
    budget = {"pop_size": 16, "generations": 3}
    res = identify(reference=trace, seed=3, uncertainty="none", **budget)
    record = res.settings["second_search_run"]
    assert res.settings["second_search"] is True and record is not None
    first_seed = res.settings["optimizer_seed"]
    alone = [
        FaultIdentifier(seed=s, second_search=False, **budget).fit(trace.t, trace.i_q, Chirp())
        for s in (first_seed, second_seed(first_seed))
    ]
    assert alone[0].fit_nrmse_ > 0.02
    assert alone[0].fit_nrmse_ == pytest.approx(record["first_fit_nrmse"], abs=1e-6)
    best = min(alone, key=lambda a: a.fitness_)
    # the same numbers to rounding (identify sets the kernel's threads, which may sum in another order)
    assert res.fitness == pytest.approx(best.fitness_, rel=1e-9) and record["taken"] == (best is alone[1])
    np.testing.assert_allclose(res.estimate, best.faults_, atol=1e-6)
    assert res.evaluations == alone[0].run_.evaluations + alone[1].run_.evaluations
    off = identify(reference=trace, seed=3, uncertainty="none", second_search=False, **budget)
    assert off.settings["second_search_run"] is None and off.fitness == pytest.approx(
        alone[0].fitness_, rel=1e-9
    )
