"""Stage 2 and the search's last step: the local polishes of the search's best point.

`polish_stage` refines the best point and its best distinct runner-up from the final population
with a small CMA-ES each (`polish`, `polish_two`, `runner_up`) and keeps the better; after the
final checks (`checks`), `least_squares_stage` ends the search with scipy's bounded least squares
on eq. 3's residual vector (`least_squares_polish`), its Jacobian one batch per iteration. Both
run only with the settings' ``polish``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from . import limits
from .cmaes import cmaes
from .context import Context
from .metrics import wrap_phase
from .optimizers import (
    BatchProblem,
    Objective,
    OnGeneration,
    OptimizerRun,
    Residuals,
    Stagnation,
    minimize_batch,
)
from .problem import recentre_phase, search_to_faults
from .state import Record, State

__all__ = ["least_squares_polish", "least_squares_stage", "polish", "polish_stage", "polish_two", "runner_up"]


def polish(
    evaluate: Objective,
    start: OptimizerRun,
    *,
    n_var: int = 8,
    seed: int = 0,
    sigma: float = 0.05,
    stagnation: Stagnation | None = None,
    on_generation: OnGeneration | None = None,
    budget: tuple[int, int] | None = None,
) -> OptimizerRun:
    """Refine a run's best point with a small CMA-ES around it (step `sigma` in the unit box).

    `budget` (population, generations) defaults to `limits.POLISH_BUDGET`; stops early by
    `stagnation` (default `Stagnation(patience=limits.POLISH_PATIENCE)`). Keeps the start point if
    the polish finds nothing better; the history continues the start's.
    """
    pop_size, generations = limits.POLISH_BUDGET if budget is None else budget
    stop = stagnation if stagnation is not None else Stagnation(patience=limits.POLISH_PATIENCE)
    problem = BatchProblem(evaluate, np.zeros(n_var), np.ones(n_var))
    x, f, history = minimize_batch(
        problem, cmaes(np.clip(start.x, 0.0, 1.0), sigma, pop_size, generations), generations,
        seed=seed, stagnation=stop, on_generation=on_generation,
    )  # fmt: skip
    if not f < start.f:
        x, f = start.x, start.f
    return OptimizerRun(x, f, start.evaluations + problem.evaluations, [*start.history, *history])


def least_squares_polish(
    residuals: Residuals,
    start: OptimizerRun,
    *,
    step: float | None = None,
    max_nfev: int | None = None,
) -> OptimizerRun:
    """Refine a point by nonlinear least squares on its residual vector (scipy's trust-region
    reflective `least_squares` within the unit box), the objective being Σ r².

    Where the fitness is a long curved valley in several faults at once, the CMA-ES polish stops
    before its end: measured on a random case (bench_multifault, seed 2027, case 15 seed 2) a run
    ended with the eccentricity at 0.020 against 0.047, at 1.23x the best fitness other seeds
    found, with the fitness falling all along the straight line to their point; this polish went
    there in 84 evaluations. The Jacobian is taken by forward differences of `step` in one batch
    of n rows from the residual of the point itself, which scipy has just evaluated (backward at
    the upper bound; `step` and `max_nfev` default to `limits.LS_STEP` and `limits.LS_MAX_NFEV`).
    Keeps the start if the polish does not improve
    on it, or fails. A residual that is not finite is replaced by a large one: a trial point that
    diverges is rejected; a Jacobian probe that diverges spoils its column, and the step it
    proposes then rarely fits better, so the start is kept. The history continues the start's.
    """
    from scipy.optimize import least_squares

    step = limits.LS_STEP if step is None else step
    max_nfev = limits.LS_MAX_NFEV if max_nfev is None else max_nfev

    x0 = np.clip(np.asarray(start.x, dtype=np.float64), 0.0, 1.0)
    n = len(x0)
    evaluations = 0

    def batch(X: NDArray[np.float64]) -> NDArray[np.float64]:
        nonlocal evaluations
        evaluations += len(X)
        return np.asarray(residuals(X), dtype=np.float64)

    r0 = batch(x0[None, :])[0]
    if not np.all(np.isfinite(r0)):
        return OptimizerRun(start.x, start.f, start.evaluations + evaluations, start.history)
    big = 1e3 * max(float(np.max(np.abs(r0))), 1e-12)

    def finite(R: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.where(np.isfinite(R), R, big)

    # the point scipy evaluated last and its residual: it evaluates its start once more, and takes
    # the Jacobian at the point it has just evaluated and accepted
    last_x, last_r = x0, r0

    def at(x: NDArray[np.float64]) -> NDArray[np.float64]:
        nonlocal last_x, last_r
        if not np.array_equal(x, last_x):
            last_x, last_r = np.array(x, dtype=np.float64), batch(x[None, :])[0]
        return last_r

    def fun(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return finite(at(x))

    def jac(x: NDArray[np.float64]) -> NDArray[np.float64]:
        h = np.where(x + step <= 1.0, step, -step)
        base = finite(at(x))
        X = np.repeat(x[None, :], n, axis=0)
        X[np.arange(n), np.arange(n)] += h
        R = finite(batch(X))
        return ((R - base) / h[:, None]).T  # type: ignore[no-any-return]

    try:
        res = least_squares(
            fun, x0, jac=jac, bounds=(np.zeros(n), np.ones(n)), method="trf", x_scale=np.full(n, 0.05),
            max_nfev=max_nfev,
        )  # fmt: skip
    except (ValueError, np.linalg.LinAlgError):
        return OptimizerRun(start.x, start.f, start.evaluations + evaluations, start.history)
    f = 2.0 * float(res.cost)
    if not f < start.f:
        return OptimizerRun(start.x, start.f, start.evaluations + evaluations, start.history)
    return OptimizerRun(
        np.asarray(res.x, dtype=np.float64), f, start.evaluations + evaluations, [*start.history, f]
    )


def runner_up(run: OptimizerRun, distance: float | None = None) -> OptimizerRun | None:
    """The best member of the run's final population that lies more than `distance` (default
    `limits.RUNNER_UP_DISTANCE`) from its best point in some fault (max norm over k1..k8 in fault
    space, k7's difference on the circle), as a run to polish; None without a population or when
    every member is that close.

    The GA's final population is still spread (70-95 of 96 members that far on the benchmark
    cases): a basin next to the one the best point fell in is often held by a member. Polishing it
    too turned the one wrong basin of the 40 x 2 benchmark runs (case 17 seed 2: 1.25 x the best
    fitness known, 4.25 %err) into the best basin (1.46 %err).
    """
    distance = limits.RUNNER_UP_DISTANCE if distance is None else distance
    if run.population is None or run.population_f is None or not len(run.population):
        return None
    K = search_to_faults(run.population)
    best = search_to_faults(run.x[None, :])[0]
    d = np.abs(K - best)
    d[:, 6] = np.abs(wrap_phase(d[:, 6]))
    f = np.where(np.isfinite(run.population_f), run.population_f, np.inf)
    far = np.flatnonzero((d.max(axis=1) > distance) & np.isfinite(f))
    if not len(far):
        return None
    j = int(far[np.argmin(f[far])])
    return OptimizerRun(run.population[j].copy(), float(f[j]), 0, [])


def polish_two(
    evaluate: Objective,
    run: OptimizerRun,
    *,
    seed: int = 0,
    on_generation: OnGeneration | None = None,
) -> tuple[OptimizerRun, bool]:
    """Polish the search's best point and its best distinct runner-up (`runner_up`); keep the better.

    Both start from the representative of k7 inside the box (`recentre_phase`: a polish cannot
    move a point at a bound). Returns the run (its history the search's and the first polish's,
    its evaluations all three) and whether the runner-up's polish gave it.
    """
    first = polish(evaluate, recentre_phase(run), seed=seed, on_generation=on_generation)
    second = runner_up(run)
    if second is None:
        return first, False
    other = polish(evaluate, recentre_phase(second), seed=seed + 1)
    won = other.f < first.f
    kept = other if won else first
    return OptimizerRun(kept.x, kept.f, first.evaluations + other.evaluations, first.history), won


def polish_stage(state: State | None, context: Context) -> tuple[State, Record]:
    """Stage 2: the CMA-ES polish of the search's best point and of its runner-up (`polish_two`)."""
    assert state is not None  # the search ran
    if not context.settings.polish:
        return state, {"stage": "polish", "ran": False}
    run, won = polish_two(context.evaluate, state.run, seed=context.seed, on_generation=context.on_generation)
    # runner_up: whether the polish of the population's best distinct runner-up gave the point
    return state.with_run(run), {"stage": "polish", "ran": True, "runner_up": won, "fitness": run.f}


def least_squares_stage(state: State | None, context: Context) -> tuple[State, Record]:
    """The search's last polish: least squares on eq. (3)'s residual vector (`least_squares_polish`),
    r = √w·(I_ref − I_LF) over the compared samples, from the representative of k7 inside the box.
    The run's value is then the search's own (`Context.evaluate`); its record gives the fitness
    ratio it gained (1.0: the previous point kept)."""
    assert state is not None
    if not context.settings.polish:
        return state, {"stage": "least_squares", "ran": False}
    run = state.run
    polished = least_squares_polish(context.residuals(), recentre_phase(run))
    gain, kept = 1.0, OptimizerRun(run.x, run.f, polished.evaluations, run.history)
    if polished.f < run.f:
        f = float(context.evaluate(polished.x[None, :])[0])
        kept = OptimizerRun(run.x, run.f, polished.evaluations + 1, run.history)
        if f < run.f:  # the same numbers to 1e-12; guards against a row that diverges here
            # the history stays the search's and the CMA-ES polish's: one value per generation
            gain, kept = f / run.f, OptimizerRun(polished.x, f, polished.evaluations + 1, run.history)
    return state.with_run(kept), {"stage": "least_squares", "ran": True, "gain": gain, "fitness": kept.f}
