"""The polishes' CMA-ES on arrays (`identification.cmaes.cmaes_minimize`) against pymoo's CMAES
run by `minimize_batch`: the same point, value, evaluations, history and progress to the bit."""

from __future__ import annotations

import numpy as np
import pytest

from emaphm.identification.cmaes import cmaes, cmaes_minimize
from emaphm.identification.optimizers import BatchProblem, Stagnation, minimize_batch


def _valley(X):
    """A narrow rotated valley with its floor inside the box."""
    X = np.atleast_2d(X)
    d = X - np.linspace(0.3, 0.6, X.shape[1])
    return np.sum(d**2, axis=1) + 300.0 * (d[:, 0] - d[:, 1]) ** 2


def _holes(X):
    """The valley with an infinite region and NaN in another: both rank last."""
    f = _valley(X)
    f = np.where(np.atleast_2d(X)[:, 0] > 0.45, np.inf, f)
    return np.where(np.atleast_2d(X)[:, 1] < 0.2, np.nan, f)


def _flat(X):
    """Ties everywhere: the early stop and pymoo's optimum on equal values."""
    return np.floor(2.0 * np.sum(np.atleast_2d(X), axis=1))


def _tiny(X):
    """A bowl whose minimum is found to cma's own tolerance: cma stops itself (its final mean)."""
    return 1e-9 * np.sum((np.atleast_2d(X) - 0.5) ** 2, axis=1)


def _both(objective, n_var, x0, sigma, pop, gens, seed, stagnation, lo=0.0, hi=1.0):
    out = []
    for run in ("pymoo", "arrays"):
        problem = BatchProblem(objective, np.full(n_var, lo), np.full(n_var, hi))
        calls: list = []
        on = lambda g, n, b, calls=calls: calls.append((g, n, b))  # noqa: E731
        if run == "pymoo":
            x, f, history = minimize_batch(problem, cmaes(x0, sigma, pop, gens), gens, seed=seed,
                                           stagnation=stagnation, on_generation=on)  # fmt: skip
        else:
            x, f, history = cmaes_minimize(problem, x0, sigma, pop, gens, seed=seed, stagnation=stagnation,
                                           on_generation=on)  # fmt: skip
        out.append((x, f, problem.evaluations, history, calls))
    return out


@pytest.mark.parametrize(
    "objective, n_var, x0, sigma, pop, gens, seed, patience, bounds",
    [
        (_valley, 8, np.full(8, 0.5), 0.05, 16, 30, 1, 6, (0.0, 1.0)),
        (_valley, 8, np.full(8, 0.5), 0.3, 16, 30, 7, 100, (0.0, 1.0)),  # no early stop: the budget
        (_valley, 4, np.zeros(4), 0.005, 16, 20, 3, 6, (-100.0, 100.0)),  # the preconditioned polish's y box
        (_holes, 6, np.full(6, 0.4), 0.2, 12, 25, 5, 8, (0.0, 1.0)),
        (_flat, 5, np.full(5, 0.3), 0.1, 8, 25, 2, 4, (0.0, 1.0)),
        (_tiny, 3, np.full(3, 0.2), 0.3, 10, 400, 4, 1000, (0.0, 1.0)),
        (_valley, 8, np.ones(8), 0.05, 32, 10, 9, 15, (0.0, 1.0)),  # x0 on the bound (the round polish clips it there)
    ],
)
def test_the_cma_es_on_arrays_is_pymoos_to_the_bit(objective, n_var, x0, sigma, pop, gens, seed, patience, bounds):
    (xa, fa, ea, ha, ca), (xb, fb, eb, hb, cb) = _both(objective, n_var, x0, sigma, pop, gens, seed,
                                                       Stagnation(patience=patience), *bounds)  # fmt: skip
    np.testing.assert_array_equal(xb, xa)
    assert fb == fa and eb == ea and hb == ha and cb == ca
    assert 1 < len(ha) <= gens


def test_cma_stopping_itself_ends_with_its_mean_as_pymoo_does():
    # `_tiny` reaches cma's tolfun long before the budget: pymoo evaluates cma's final mean alone
    (_, _, ea, ha, _), (_, _, eb, hb, _) = _both(_tiny, 3, np.full(3, 0.2), 0.3, 10, 400, 4, Stagnation(patience=1000))
    assert len(ha) < 400 and (ea - 1) % 10 == 1  # x0, whole generations, then the mean alone
    assert (eb, hb) == (ea, ha)


@pytest.mark.parametrize("seed", [0, 2**32, 2**40 + 3])
def test_seeds_cma_cannot_take_give_the_same_run_twice(seed):
    # cma seeds itself from the clock for 0, and numpy refuses 2**32 and above: `cma_seed` maps them
    from emaphm.identification.cmaes import cma_seed

    runs = []
    for _ in range(2):
        problem = BatchProblem(_valley, np.zeros(4), np.ones(4))
        runs.append(cmaes_minimize(problem, np.full(4, 0.5), 0.2, 8, 12, seed=seed, stagnation=Stagnation(patience=100)))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    assert runs[0][1:] == runs[1][1:]
    assert 0 < cma_seed(seed) < 2**32 and cma_seed(7) == 7 and cma_seed(2**32 - 1) == 2**32 - 1
