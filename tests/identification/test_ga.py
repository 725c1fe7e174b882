"""The search's GA on arrays (`identification.ga`) against pymoo's GA itself: the same run to the bit."""

from __future__ import annotations

import numpy as np
import pytest

from emaphm.identification import ga, search
from emaphm.identification.optimizers import BatchProblem, Stagnation, run_pymoo


def _bowl(X):
    """A rotated bowl with a minimum inside the box at (0.3, 0.6, ...)."""
    X = np.atleast_2d(X)
    d = X - np.linspace(0.3, 0.6, X.shape[1])
    return np.sum(d**2, axis=1) + 0.5 * (d[:, 0] - d[:, 1]) ** 2


def _plateau(X):
    """Ties everywhere (a coarse staircase) and an infinite region: tournaments draw their coins."""
    X = np.atleast_2d(X)
    f = np.floor(4.0 * np.sum(X, axis=1)) / 4.0
    return np.where(X[:, 0] > 0.8, np.inf, f)


def _pymoo(objective, n_var, pop_size, generations, seed, stagnation, initial=None, offspring=None):
    problem = BatchProblem(objective, np.zeros(n_var), np.ones(n_var))
    rng = np.random.default_rng(seed)
    algorithm = search._pymoo_algorithm("ga", pop_size, generations, n_var, rng, initial, offspring)
    calls = []
    x, f, history, res = run_pymoo(problem, algorithm, stagnation.termination(generations), generations, seed,
                                   lambda g, n, b: calls.append((g, n, b)))  # fmt: skip
    return x, f, problem.evaluations, history, np.clip(res.pop.get("X"), 0, 1), res.pop.get("F")[:, 0], calls


def _arrays(objective, n_var, pop_size, generations, seed, stagnation, initial=None, offspring=None):
    problem = BatchProblem(objective, np.zeros(n_var), np.ones(n_var))
    calls = []
    run = ga.genetic_algorithm(problem, pop_size, generations, seed, stagnation,
                               lambda g, n, b: calls.append((g, n, b)), initial, offspring)  # fmt: skip
    return run.x, run.f, run.evaluations, run.history, run.population, run.population_f, calls


CASES = [
    # objective, n_var, pop, generations, seed, stagnation, start, offspring
    ("bowl", 8, 96, 15, 1, Stagnation(), "table", 48),  # the search's start-table GA
    ("bowl", 8, 96, 40, 7, Stagnation(), None, None),  # the uniform start (the second search)
    ("bowl", 8, 16, 60, 3, Stagnation(patience=5, rtol=0.2), None, None),  # stops on stagnation
    ("bowl", 3, 9, 12, 11, Stagnation(), None, 5),  # a population that is not a multiple of 3
    ("plateau", 8, 24, 20, 5, Stagnation(), None, 12),  # ties and +inf values
    ("plateau", 4, 12, 10, 2, Stagnation(patience=3), "duplicates", None),  # a start with duplicates
]


@pytest.mark.parametrize("case", range(len(CASES)))
def test_the_ga_on_arrays_is_pymoos_ga_to_the_bit(case):
    name, n_var, pop, gens, seed, stagnation, start, offspring = CASES[case]
    objective = {"bowl": _bowl, "plateau": _plateau}[name]
    initial = None
    if start == "table":
        initial = np.random.default_rng(seed + 100).random((pop, n_var))
    elif start == "duplicates":
        initial = np.random.default_rng(seed).random((pop, n_var))
        initial[5] = initial[2]
        initial[7] = initial[2]
    want = _pymoo(objective, n_var, pop, gens, seed, stagnation, initial, offspring)
    got = _arrays(objective, n_var, pop, gens, seed, stagnation, initial, offspring)
    np.testing.assert_array_equal(got[0], want[0])  # the best point
    assert got[1] == want[1] and got[2] == want[2]  # its value, the evaluations
    assert got[3] == want[3] and got[6] == want[6]  # the history, the progress calls
    np.testing.assert_array_equal(got[4], want[4])  # the final population, in order
    np.testing.assert_array_equal(got[5], want[5])


def test_the_early_stops_are_pymoos():
    # the stagnation rule ends both runs at the same generation, before the budget
    for case in (2, 5):
        name, n_var, pop, gens, seed, stagnation, _, offspring = CASES[case]
        objective = {"bowl": _bowl, "plateau": _plateau}[name]
        got = _arrays(objective, n_var, pop, gens, seed, stagnation, None, offspring)
        assert 1 < len(got[3]) < gens


def test_a_mating_with_nothing_new_to_give_stops_as_pymoos(monkeypatch):
    # where no new point can be made (every child a duplicate), pymoo keeps its population for one
    # more generation and stops: both matings made to give nothing from their third generation on
    from pymoo.core.mating import Mating
    from pymoo.core.population import Population

    def after(n, real, empty):
        calls = []

        def mate(*args, **kwargs):
            calls.append(1)
            return empty() if len(calls) >= n else real(*args, **kwargs)

        return mate

    monkeypatch.setattr(Mating, "do", after(3, Mating.do, Population.create))
    want = _pymoo(_bowl, 3, 12, 20, 4, Stagnation(), None, None)
    monkeypatch.setattr(ga, "mating", after(3, ga.mating, lambda: np.empty((0, 3))))
    got = _arrays(_bowl, 3, 12, 20, 4, Stagnation(), None, None)
    assert len(got[3]) == len(want[3]) == 4  # the first population, two generations, the stop
    np.testing.assert_array_equal(got[0], want[0])
    assert got[1:4] == want[1:4] and got[6] == want[6]
    np.testing.assert_array_equal(got[4], want[4])


def test_the_search_runs_the_ga_on_arrays(monkeypatch):
    # run_optimizer("ga") goes through the array GA, not pymoo's algorithm loop
    calls = []
    real = ga.genetic_algorithm

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(search, "genetic_algorithm", spy)
    run = search.run_optimizer("ga", _bowl, pop_size=8, generations=3, seed=1)
    assert calls == [1] and run.evaluations == 24 and len(run.history) == 3
