"""Stage 2 and the search's last step: the local polishes of the search's best point.

`polish_stage` refines the best point (`limits.POLISH_ROUTE`: "preconditioned", least squares
then a CMA-ES in the Gauss–Newton Hessian's round coordinates, `preconditioned`; or "round", the
small CMA-ES of `polish`) and its distinct runner-ups from the final population by least squares
on eq. 3's residual vector (`candidates`, `polish_runner_ups`: bounded Levenberg–Marquardt
descents in lockstep, `descents`), and keeps the best; after the final checks (`checks`),
`least_squares_stage` ends the search with a bounded least squares on the same residuals
(`least_squares_polish`: Levenberg–Marquardt with isotropic damping), its Jacobian one batch per
iteration. Both run only with the settings' ``polish``; after the multistart search (whose
points are least-squares end points) the first does nothing.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from . import limits
from .cmaes import cmaes_minimize
from .context import Context
from .descents import candidates, diverged_fill, lm_polish_many
from .optimizers import (
    BatchProblem,
    Objective,
    OnGeneration,
    OptimizerRun,
    Residuals,
    Stagnation,
)
from .preconditioned import preconditioned_polish
from .problem import recentre_phase
from .state import Record, State

__all__ = [
    "CountedResiduals",
    "least_squares_polish",
    "least_squares_stage",
    "polish",
    "polish_runner_ups",
    "polish_stage",
]


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
    x, f, history = cmaes_minimize(
        problem, np.clip(start.x, 0.0, 1.0), sigma, pop_size, generations,
        seed=seed, stagnation=stop, on_generation=on_generation,
    )  # fmt: skip
    if not f < start.f:
        x, f = start.x, start.f
    return OptimizerRun(x, f, start.evaluations + problem.evaluations, [*start.history, *history])


class CountedResiduals:
    """A polish's residuals (`batch`: rows of the box → residual vectors), their evaluations
    counted, the start's residual `r0`, and `finite`: a residual that is not finite replaced by a
    large one (10³ × the start's largest), so that a trial point that diverges is rejected. Also
    the current's scale refits (`current_scale`)."""

    def __init__(self, residuals: Residuals, x0: NDArray[np.float64]) -> None:
        self.residuals, self.evaluations = residuals, 0
        self.r0 = self.batch(x0[None, :])[0]
        self.big = diverged_fill(self.r0)

    def batch(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        self.evaluations += len(X)
        return np.asarray(self.residuals(X), dtype=np.float64)

    def finite(self, R: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.where(np.isfinite(R), R, self.big)

    def kept(self, start: OptimizerRun, x: NDArray[np.float64] | None = None, f: float = np.inf) -> OptimizerRun:
        """The polished point (x, f) if it improves on the start, else the start; evaluations counted."""
        if x is None or not f < start.f:
            return OptimizerRun(start.x, start.f, start.evaluations + self.evaluations, start.history)
        return OptimizerRun(x, f, start.evaluations + self.evaluations, [*start.history, f])


def least_squares_polish(
    residuals: Residuals,
    start: OptimizerRun,
    *,
    step: float | None = None,
    max_nfev: int | None = None,
) -> OptimizerRun:
    """Refine a point by nonlinear least squares on its residual vector within the unit box, the
    objective being Σ r²: a bounded Levenberg–Marquardt with Levenberg's isotropic damping
    (`descents.lm_polish_many`, ``scaling="identity"``: a spherical trust region, as scipy's
    trust-region reflective `least_squares` with an isotropic ``x_scale``, which this polish ran
    until issue 36's tenth session), a difference Jacobian at every accepted point.

    Where the fitness is a long curved valley in several faults at once, the CMA-ES polish stops
    before its end: measured on a random case (bench_multifault, seed 2027, case 15 seed 2) a run
    ended with the eccentricity at 0.020 against 0.047, at 1.23x the best fitness other seeds
    found, with the fitness falling all along the straight line to their point; this polish went
    there in 84 evaluations. The Jacobian is taken by forward differences of `step` in one batch
    of n rows (backward at the upper bound; `step` and `max_nfev`, the trial points, default to
    `limits.LS_STEP` and `limits.LS_MAX_NFEV`). Keeps the start if the polish does not improve
    on it, or fails. A residual that is not finite is replaced by a large one: a trial point that
    diverges is rejected; a Jacobian probe that diverges spoils its column, and the step it
    proposes then rarely fits better, so the start is kept. The history continues the start's.
    Why not scipy's any more: importing scipy.optimize was 0.56–0.75 s of every diagnosis on
    machine E (BENCHMARKS.md, issue 36, tenth session).
    """
    return lm_polish_many(residuals, [start], step=step, max_nfev=max_nfev, broyden=False, scaling="identity")[0]


def polish_runner_ups(residuals: Residuals, evaluate: Objective, search: OptimizerRun, kept: OptimizerRun,
                      count: int | None = None) -> tuple[OptimizerRun, int]:  # fmt: skip
    """The least-squares polish (`descents.lm_polish_many`: in lockstep) of the search's distinct
    runner-ups (`candidates` but its best point), each from the representative of k7 inside the
    box (`recentre_phase`: a polish cannot move a point at a bound), against `kept`, the polished
    best point: the best of them, its value the search's own (`evaluate`, one evaluation), and
    which runner-up gave it (0: `kept` stands). Evaluations: `kept`'s and all of theirs."""
    evaluations, best, won = kept.evaluations, None, 0
    starts = [recentre_phase(OptimizerRun(start.x, start.f, 0, [])) for start in candidates(search, count)[1:]]
    for i, polished in enumerate(lm_polish_many(residuals, starts), start=1):
        evaluations += polished.evaluations
        if polished.f < kept.f and (best is None or polished.f < best.f):
            best, won = polished, i
    if best is None:
        return OptimizerRun(kept.x, kept.f, evaluations, kept.history), 0
    f = float(evaluate(best.x[None, :])[0])  # the same number to 1e-12; guards a row that diverges here
    if not f < kept.f:
        return OptimizerRun(kept.x, kept.f, evaluations + 1, kept.history), 0
    return OptimizerRun(best.x, f, evaluations + 1, kept.history), won


def polish_stage(state: State | None, context: Context) -> tuple[State, Record]:
    """Stage 2: the polish of the search's best point (`limits.POLISH_ROUTE`: `preconditioned`'s
    by default, else the round CMA-ES of `polish`), then the least-squares polish of its distinct
    runner-ups (`polish_runner_ups`); the best kept. Not after the multistart search, whose points
    are least-squares end points (`multistart`).

    Until issue 36 the best runner-up got a CMA-ES polish of its own (up to 1569 evaluations);
    least squares from up to four of them costs 80–100 LF runs each. Least squares does not
    replace the best point's CMA-ES: where the valley is narrower than its finite-difference step
    it stops short (the interval calibration's case 94, seed 4101: 4.2 x the fitness a CMA-ES then
    reached from its point), and a pipeline started with it moved estimates the calibrations rest
    on (BENCHMARKS.md, issue 36).
    """
    assert state is not None  # the search ran
    if not context.settings.polish:
        return state, {"stage": "polish", "ran": False}
    if context.settings.optimizer == "multistart":
        # its points are least-squares end points already; a CMA-ES from the best moved the %err
        # by +0.02 ± 0.02 on 77 paired random runs (BENCHMARKS.md, issue 36)
        return state, {"stage": "polish", "ran": False, "reason": "the multistart search ends in least squares"}
    search, residuals = state.run, context.residuals()
    start = recentre_phase(search)
    if limits.POLISH_ROUTE == "preconditioned":
        best = preconditioned_polish(context.evaluate, residuals, start, seed=context.seed,
                                     on_generation=context.on_generation)  # fmt: skip
    else:
        best = polish(context.evaluate, start, seed=context.seed, on_generation=context.on_generation)
    run, won = polish_runner_ups(residuals, context.evaluate, search, best)
    # runner_up: whether a runner-up's polish gave the point (`candidate`: which, 0 the best point)
    return state.with_run(run), {"stage": "polish", "ran": True, "runner_up": won > 0, "candidate": won, "fitness": run.f}


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
