"""The multistart search (`identification.multistart`): its sample, its choice between basins, its
counts, and its place in an identification."""

import numpy as np
import pytest

from emaphm import InputError, MonitorEma
from emaphm.identification.identifier import FaultIdentifier
from emaphm.identification.multistart import latin_hypercube, multistart
from emaphm.identification.search import run_optimizer

# two basins in 8-D: the global minimum at B (f = 0) inside a ball of radius 0.7, a wide shallow
# one at A (f = 0.05 at its bottom) outside it; a descent ends in whichever it starts in
A = np.full(8, 0.3)
B = np.array([0.8, 0.7, 0.75, 0.85, 0.8, 0.7, 0.45, 0.8])


def _two_basins(X):
    """Residual vectors (9 per row): inside the ball about B, x − B and 0; elsewhere x − A and √0.05."""
    near_b = np.sum((X - B) ** 2, axis=1) < 0.7**2
    R = np.empty((len(X), 9))
    R[:, :8] = np.where(near_b[:, None], X - B, X - A)
    R[:, 8] = np.where(near_b, 0.0, np.sqrt(0.05))
    return R


def f_two_basins(X):
    return np.sum(_two_basins(np.atleast_2d(X)) ** 2, axis=1)


def test_a_latin_hypercube_has_one_point_in_each_cell_of_every_axis():
    X = latin_hypercube(50, 8, np.random.default_rng(1))
    assert X.shape == (50, 8) and np.all((X >= 0.0) & (X < 1.0))
    for j in range(8):
        assert sorted(np.floor(X[:, j] * 50).astype(int)) == list(range(50))
    assert not np.array_equal(X, latin_hypercube(50, 8, np.random.default_rng(2)))


def test_the_sample_chooses_the_basin_a_descent_cannot():
    calls = []

    def counted(X):
        calls.append(len(X))
        return _two_basins(X)

    run = multistart(f_two_basins, counted, sample=64, descents=4, seed=1)
    assert run.f < 1e-12 and np.allclose(run.x, B, atol=1e-6)  # the narrow global basin
    # the descents' end points are the population, their values the objective's own
    assert run.population.shape == (4, 8)
    np.testing.assert_array_equal(run.population_f, f_two_basins(run.population))
    assert np.sum(run.population_f > 0.04) >= 1  # some descents ended in the wide basin
    # evaluations: the sample, every residual row, the end points once more
    assert run.evaluations == 64 + sum(calls) + 4
    assert run.history == [pytest.approx(np.min(f_two_basins(latin_hypercube(64, 8, np.random.default_rng(1))))),
                           run.f]  # fmt: skip
    again = multistart(f_two_basins, _two_basins, sample=64, descents=4, seed=1)
    np.testing.assert_array_equal(again.x, run.x)
    assert again.evaluations == run.evaluations


def test_one_descent_from_the_best_point_misses_it():
    # the test above can fail: from the same sample a single descent ends in the wide basin
    assert multistart(f_two_basins, _two_basins, sample=64, descents=1, seed=1).f == pytest.approx(0.05)


def test_progress_counts_the_descents_that_stopped_and_needs_residuals():
    seen = []
    run_optimizer("multistart", f_two_basins, residuals=_two_basins, pop_size=32, generations=3, seed=1,
                  on_generation=lambda done, total, best: seen.append((done, total)))  # fmt: skip
    assert seen and seen[-1] == (3, 3) and all(t == 3 for _, t in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)
    with pytest.raises(InputError, match="residuals"):
        run_optimizer("multistart", f_two_basins, pop_size=32, generations=3)


def test_an_identification_by_multistart_skips_the_polish_stage():
    res = MonitorEma().simulate([0.3, 0.2, 0, 0.2, 0, 0, 0, 0.5], noise=True, seed=2, duration=0.2)
    ident = FaultIdentifier(seed=1, optimizer="multistart", pop_size=32, generations=3, last_stage="none")
    ident.fit(res.t, res.i_q)
    search, polish = ident.record("search"), ident.record("polish")
    assert search["optimizer"] == "multistart" and not polish["ran"] and "least squares" in polish["reason"]
    assert np.isfinite(ident.fitness_) and ident.run_.evaluations > 32
