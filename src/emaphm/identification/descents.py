"""Least-squares descents from given starts: the runner-ups' polish (`polish.polish_runner_ups`,
by `lm_polish_many`) and the multistart search's descents (`multistart`, by `descend_from`).

Each descent is the bounded Levenberg–Marquardt of `lm` on eq. 3's residual vector with the
polishes' Jacobian step and budget (`limits.LS_STEP`, `limits.LS_MAX_NFEV`), its Jacobian updated
by secants between difference ones (`limits.LS_BROYDEN`, `limits.LS_MIN_SECANT`); several run in
lockstep, one batch of monitor runs per round (`lm.levenberg_marquardt_many`).

The secants (issue 36, tenth session): a descent from the Table 1 case's runner-ups took 140–150
monitor runs (11–17 difference Jacobians of 8 rows and 24–30 trial points), with them 80–95 (6–8
Jacobians), and went as far or further; on 240 paired random twin runs the final %err moved by
−0.02 ± 0.03 with no wrong basin (BENCHMARKS.md, issue 36).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from . import limits
from .lm import levenberg_marquardt_many
from .metrics import wrap_phase
from .optimizers import Objective, OptimizerRun, Residuals
from .problem import recentre_phase, search_to_faults

__all__ = ["candidates", "descend_from", "diverged_fill", "lm_polish", "lm_polish_many"]


def diverged_fill(r0: NDArray[np.float64]) -> float:
    """What a residual that is not finite becomes in a descent started where the residual is `r0`:
    10³ × its largest (inf if `r0` itself is not finite), so that a trial point that diverges is
    rejected and the descent goes on."""
    return 1e3 * max(float(np.max(np.abs(r0))), 1e-12) if np.all(np.isfinite(r0)) else np.inf


def lm_polish(residuals: Residuals, start: OptimizerRun) -> OptimizerRun:
    """`least_squares_polish`'s job by bounded Levenberg–Marquardt on the 8 × 8 normal equations
    (`lm.levenberg_marquardt`), from one start.

    The same residuals, Jacobian step and budget (`limits.LS_STEP`, `limits.LS_MAX_NFEV`); it
    keeps the start if it does not improve on it. Marquardt's scaling and secant Jacobians
    (`limits.LS_BROYDEN`), where `least_squares_polish` (the search's last polish, the last stage)
    damps isotropically and takes a difference Jacobian at every accepted point.
    """
    return lm_polish_many(residuals, [start])[0]


def lm_polish_many(
    residuals: Residuals,
    starts: list[OptimizerRun],
    on_round: Callable[[int, int], None] | None = None,
    *,
    step: float | None = None,
    max_nfev: int | None = None,
    broyden: bool | None = None,
    scaling: str = "marquardt",
) -> list[OptimizerRun]:
    """`lm_polish` of each start, the descents in lockstep (`lm.levenberg_marquardt_many`: one
    batch of monitor runs per round, each descent on the path it takes alone): the same points,
    values and counts as one by one. A start whose residual is not finite is kept as it is.
    `on_round(stopped, total)` follows the rounds. `step`, `max_nfev` and `broyden` default to
    `limits.LS_STEP`, `limits.LS_MAX_NFEV` and `limits.LS_BROYDEN`; `scaling` is the damping's
    (`lm`; `polish.least_squares_polish` asks for "identity" without secants)."""
    if not starts:
        return []
    X0 = np.array([np.clip(np.asarray(s.x, dtype=np.float64), 0.0, 1.0) for s in starts])
    R0 = np.asarray(residuals(X0), dtype=np.float64)
    ok = [j for j in range(len(starts)) if np.all(np.isfinite(R0[j]))]
    evaluations = np.ones(len(starts), dtype=int)  # each start's own residual
    ends: dict[int, tuple[NDArray[np.float64], float]] = {}
    if ok:
        fill = np.array([diverged_fill(R0[j]) for j in ok])
        try:
            results = levenberg_marquardt_many(
                lambda X: np.asarray(residuals(X), dtype=np.float64), X0[ok], R0[ok],
                step=limits.LS_STEP if step is None else step,
                max_nfev=limits.LS_MAX_NFEV if max_nfev is None else max_nfev, fill=fill, on_round=on_round,
                broyden=limits.LS_BROYDEN if broyden is None else broyden, min_secant=limits.LS_MIN_SECANT,
                scaling=scaling,
            )  # fmt: skip
        except (ValueError, np.linalg.LinAlgError):
            results = []
        for j, res in zip(ok, results, strict=False):
            evaluations[j] += res.njev * X0.shape[1] + res.nfev + res.spared
            ends[j] = (res.x, res.f)
    out = []
    for j, start in enumerate(starts):
        n = start.evaluations + int(evaluations[j])
        x, f = ends.get(j, (None, np.inf))
        if x is None or not f < start.f:
            out.append(OptimizerRun(start.x, start.f, n, start.history))
        else:
            out.append(OptimizerRun(x, f, n, [*start.history, f]))
    return out


def descend_from(
    run: OptimizerRun,
    residuals: Residuals,
    evaluate: Objective,
    count: int,
    distance: float,
    on_round: Callable[[int, int], None] | None = None,
) -> tuple[OptimizerRun, int]:
    """Least-squares descents (`lm_polish_many`) from the run's best point and its best distinct
    population members (`candidates`: up to `count` points, each more than `distance` from
    every one taken before in some fault), each from the representative of k7 inside the box
    (`recentre_phase`). The end points are evaluated once more by `evaluate` (the same numbers as
    Σ r² to 1e-12; a row that diverges there is last).

    Returns the best end point as a run (its population: all end points and their values; its
    evaluations: the run's, the descents' and the end points'; its history: the run's and the best
    end point's value) and which start gave it (0: the run's best point).
    """
    starts = [recentre_phase(OptimizerRun(c.x, c.f, 0, [])) for c in candidates(run, count, distance)]
    ends = lm_polish_many(residuals, starts, on_round=on_round)
    P = np.array([end.x for end in ends])
    F = np.asarray(evaluate(P), dtype=np.float64)
    F = np.where(np.isfinite(F), F, np.inf)
    k = int(np.argmin(F))
    evaluations = run.evaluations + sum(end.evaluations for end in ends) + len(P)
    return OptimizerRun(P[k], float(F[k]), evaluations, [*run.history, float(F[k])], P, F), k


def candidates(run: OptimizerRun, count: int | None = None, distance: float | None = None) -> list[OptimizerRun]:
    """The run's best point and up to `count` − 1 members of its final population (default
    `limits.POLISH_CANDIDATES`), best first, each more than `distance` (default
    `limits.RUNNER_UP_DISTANCE`) from every one taken before in some fault (max norm over k1..k8
    in fault space, k7's difference on the circle); only the best point without a population.

    The GA's final population is still spread (70-95 of 96 members that far on the benchmark
    cases): a basin next to the one the best point fell in is often held by a member. Polishing the
    best such runner-up too turned the one wrong basin of the 40 x 2 benchmark runs (case 17 seed
    2: 1.25 x the best fitness known, 4.25 %err) into the best basin (1.46 %err).
    """
    count = limits.POLISH_CANDIDATES if count is None else count
    distance = limits.RUNNER_UP_DISTANCE if distance is None else distance
    chosen = [run]
    if run.population is None or run.population_f is None or not len(run.population) or count < 2:
        return chosen
    K = search_to_faults(run.population)
    taken = [search_to_faults(run.x[None, :])[0]]
    f = np.where(np.isfinite(run.population_f), run.population_f, np.inf)
    for j in np.argsort(f, kind="stable"):
        if len(chosen) >= count or not np.isfinite(f[j]):
            break
        d = np.abs(K[j] - np.asarray(taken))
        d[:, 6] = np.abs(wrap_phase(d[:, 6]))
        if np.all(d.max(axis=1) > distance):
            chosen.append(OptimizerRun(run.population[j].copy(), float(f[j]), 0, []))
            taken.append(K[j])
    return chosen
