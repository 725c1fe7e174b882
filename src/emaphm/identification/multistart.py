"""Stage 1 by least squares from many starts (the search "multistart", issue 36).

A Latin-hypercube sample of the box [0, 1]^8 (`latin_hypercube`, from the run's seed) is evaluated
in one batch of eq. 3; from its best points that are distinct in some fault (`descents.candidates`,
`limits.MULTISTART_DISTANCE` apart) bounded Levenberg–Marquardt descents run in lockstep
(`descents.descend_from`), one batch of monitor runs per round; the best end point is the
search's. The run's population is the descents' end points, already polished, which the polish
stage then leaves as they are.

Why, and why not the default (BENCHMARKS.md, issue 36): eq. 3 over a 10⁴-sample residual is
smooth enough that a descent from a coarse start usually reaches the basin the GA finds. On 200
random twin runs (seeds 7, 6061, 2611) the median and p90 %err were the GA pipeline's within their
scatter at a third of its monitor runs (Table 1: 1 900 against 6 124); but a descent cannot choose
between basins, only the sample can, and a uniform sample does not always start one in the right
basin: 2 of the 80 runs of seed 6061 ended at 1.6× and 2.7× the GA's fitness, and one case of the
interval set at 34 %err. Larger samples (up to 2 048 points) and more descents moved which cases
failed, not whether. An option for fast screening, not the default search.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from . import limits
from .descents import descend_from
from .optimizers import Objective, OnGeneration, OptimizerRun, Residuals

__all__ = ["latin_hypercube", "multistart"]


def latin_hypercube(n: int, n_var: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """n points of [0, 1]^n_var with one point in each n-th of every axis (a Latin hypercube),
    placed uniformly within its cell."""
    cells = np.argsort(rng.random((n_var, n)), axis=1).T  # a random permutation of 0..n-1 per axis
    return (cells + rng.random((n, n_var))) / n  # type: ignore[no-any-return]


def multistart(
    evaluate: Objective,
    residuals: Residuals,
    *,
    n_var: int = 8,
    sample: int | None = None,
    descents: int | None = None,
    seed: int = 0,
    on_generation: OnGeneration | None = None,
) -> OptimizerRun:
    """The best of `descents` least-squares descents (default `limits.DEFAULT_BUDGETS["multistart"]`)
    from the best distinct points of a Latin-hypercube sample of `sample` points.

    `evaluate` gives eq. 3 of rows of the box, `residuals` its residual vectors (Σ r² = eq. 3); the
    descents' Jacobian step and budget are the polishes' (`limits.LS_STEP`, `limits.LS_MAX_NFEV`).
    The end points are evaluated once more by `evaluate`, whose values rank them (the same numbers
    to 1e-12; a row that diverges there is last). `on_generation(done, descents, best)` reports
    the descents that have stopped.
    """
    default_sample, default_descents = limits.DEFAULT_BUDGETS["multistart"]
    sample = default_sample if sample is None else sample
    descents = default_descents if descents is None else descents
    rng = np.random.default_rng(seed)
    X = latin_hypercube(sample, n_var, rng)
    f = _finite(evaluate(X))
    b = int(np.argmin(f))
    first = OptimizerRun(X[b], float(f[b]), sample, [float(f[b])], X, f)

    def report(done: int, total: int) -> None:
        if on_generation is not None:
            on_generation(done, total, first.f)

    return descend_from(first, residuals, evaluate, descents, limits.MULTISTART_DISTANCE, on_round=report)[0]


def _finite(f: NDArray[np.float64]) -> NDArray[np.float64]:
    f = np.asarray(f, dtype=np.float64)
    return np.where(np.isfinite(f), f, np.inf)
