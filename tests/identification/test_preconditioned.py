"""The best point's polish in the Gauss–Newton Hessian's round coordinates (`preconditioned`):
the map it searches in, what it reaches on a narrow, rough valley where a round CMA-ES of the same
cost does not, the box, the evaluations it counts and that it never returns a worse point."""

from __future__ import annotations

import numpy as np
import pytest

from emaphm.identification import limits
from emaphm.identification.optimizers import OptimizerRun
from emaphm.identification.polish import polish
from emaphm.identification.preconditioned import preconditioned_polish, whitening

# a narrow valley: eight directions of the box whose curvatures span 10⁶, rotated off the axes
_rng = np.random.default_rng(36)
Q, _ = np.linalg.qr(_rng.normal(size=(8, 8)))
SCALES = np.logspace(0, 3, 8)
X_STAR = np.array([0.31, 0.62, 0.18, 0.44, 0.71, 0.52, 0.38, 0.57])
F_STAR = 1e-3


def valley(X):
    """Residuals (rows of X → 9 samples): a rotated, ill-conditioned linear fit with a floor of
    F_STAR, and a roughness of period 1e-4 (as the monitor's discrete events give eq. 3) that
    spoils fine finite differences but not steps of 1e-2."""
    X = np.atleast_2d(X)
    D = (X - X_STAR) @ Q
    rough = 3e-4 * np.sin(2 * np.pi * X.sum(axis=1) / 1e-4)
    return np.column_stack([D * SCALES, np.sqrt(F_STAR) + rough])


def sum_sq(R):
    return np.sum(R * R, axis=1)


class Counted:
    """The residuals and eq. 3 of `valley`, their monitor runs counted."""

    def __init__(self, fun=valley):
        self.fun, self.runs = fun, 0

    def residuals(self, X):
        self.runs += len(np.atleast_2d(X))
        return self.fun(X)

    def evaluate(self, X):
        return sum_sq(self.residuals(X))


def test_whitening_makes_the_gauss_newton_model_round():
    J = _rng.normal(size=(50, 8)) * np.logspace(-2, 2, 8)
    f0, scale = 0.3, 0.5
    M = whitening(J, f0, scale, (1e-12, 1e12))
    # each unit step of y raises the model's f by scale·f0/n, and the axes do not interact
    np.testing.assert_allclose(M.T @ (J.T @ J) @ M, np.eye(8) * scale * f0 / 8, rtol=1e-8, atol=1e-9)
    # clipped: no axis steps beyond the bounds; a direction the residuals do not see gets the largest
    J[:, 3] = 0.0
    M = whitening(J, f0, scale, (1e-4, 0.1))
    steps = np.linalg.norm(M, axis=0)
    assert np.all(steps >= 1e-4 - 1e-15) and np.all(steps <= 0.1 + 1e-15)
    blind = np.argmax(np.abs(M[3]))
    assert steps[blind] == pytest.approx(0.1)


def test_it_reaches_a_narrow_rough_valley_where_a_round_cma_es_of_the_same_cost_does_not():
    x0 = np.clip(X_STAR + 0.02 * Q[:, 0] + 0.01 * Q[:, 7], 0, 1)
    c = Counted()
    start = OptimizerRun(x0, float(c.evaluate(x0[None])[0]), 100, [1.0])
    c.runs = 0
    run = preconditioned_polish(c.evaluate, c.residuals, start, seed=3)
    assert run.f < 3.0 * F_STAR < 1e-2 * start.f
    assert run.f == pytest.approx(float(c.evaluate(run.x[None])[0]), rel=1e-12)
    pop, gens = limits.PRECONDITIONED["budget"]
    used = c.runs - 1
    assert run.evaluations == start.evaluations + used  # every run counted, no other
    assert used <= 1 + 9 * (1 + limits.LS_MAX_NFEV) + 9 + pop * gens
    assert run.history[0] == 1.0 and len(run.history) >= 2
    # the round CMA-ES of the old polish, given as many runs, stops far above the floor
    round_ = polish(c.evaluate, start, seed=3, budget=(16, max(used // 16, 2)))
    assert round_.f > 10 * run.f


def test_it_stays_in_the_box_and_never_returns_a_worse_point():
    def outside(X):  # the valley's minimum beyond the upper bound of x0
        X = np.atleast_2d(X)
        return np.column_stack([(X - np.r_[1.2, X_STAR[1:]]) * 3.0, np.full(len(X), 0.1)])

    c = Counted(outside)
    x0 = np.r_[0.9, X_STAR[1:]]
    start = OptimizerRun(x0, float(c.evaluate(x0[None])[0]), 0, [])
    run = preconditioned_polish(c.evaluate, c.residuals, start, seed=1)
    assert np.all((run.x >= 0.0) & (run.x <= 1.0)) and run.x[0] == pytest.approx(1.0, abs=1e-3)
    assert run.f < start.f
    # a start already better than anything it can find (a lower value than the objective's) is kept
    kept = preconditioned_polish(c.evaluate, c.residuals, OptimizerRun(x0, -1.0, 7, [2.0]), seed=1)
    assert kept.f == -1.0 and np.array_equal(kept.x, x0) and kept.evaluations > 7


def test_the_same_seed_gives_the_same_point():
    x0 = np.clip(X_STAR + 0.05 * Q[:, 2], 0, 1)
    runs = []
    for seed in (5, 5):
        c = Counted()
        runs.append(preconditioned_polish(c.evaluate, c.residuals, OptimizerRun(x0, float(c.evaluate(x0[None])[0]), 0, []), seed=seed))
    assert np.array_equal(runs[0].x, runs[1].x) and runs[0].f == runs[1].f
    assert runs[0].history == runs[1].history
