"""Least-squares descents from given starts: the runner-ups' polish (`polish.polish_runner_ups`)
and the multistart search's descents (`multistart`).

Each descent is the bounded Levenberg–Marquardt of `lm` on eq. 3's residual vector with the
polishes' Jacobian step and budget (`limits.LS_STEP`, `limits.LS_MAX_NFEV`); several run in
lockstep, one batch of monitor runs per round (`lm.levenberg_marquardt_many`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from . import limits
from .lm import levenberg_marquardt_many
from .optimizers import OptimizerRun, Residuals

__all__ = ["lm_polish", "lm_polish_many"]


def lm_polish(residuals: Residuals, start: OptimizerRun) -> OptimizerRun:
    """`least_squares_polish`'s job by bounded Levenberg–Marquardt on the 8 × 8 normal equations
    (`lm.levenberg_marquardt`): the runner-ups' polish (`polish_runner_ups`).

    The same residuals, Jacobian step and budget (`limits.LS_STEP`, `limits.LS_MAX_NFEV`); it
    keeps the start if it does not improve on it. scipy's trust-region method works on the
    10⁴ × 8 Jacobian itself and pays for it on every call (`lm`'s docstring); the search's last
    polish and the last stage keep it, whose estimates the interval and detection calibrations
    were fitted to (a Levenberg–Marquardt there moved the final %err by +0.08 ± 0.05 on 80 paired
    runs, BENCHMARKS.md, issue 36).
    """
    return lm_polish_many(residuals, [start])[0]


def lm_polish_many(
    residuals: Residuals, starts: list[OptimizerRun], on_round: Callable[[int, int], None] | None = None
) -> list[OptimizerRun]:
    """`lm_polish` of each start, the descents in lockstep (`lm.levenberg_marquardt_many`: one
    batch of monitor runs per round, each descent on the path it takes alone): the same points,
    values and counts as one by one. A start whose residual is not finite is kept as it is.
    `on_round(stopped, total)` follows the rounds."""
    if not starts:
        return []
    X0 = np.array([np.clip(np.asarray(s.x, dtype=np.float64), 0.0, 1.0) for s in starts])
    R0 = np.asarray(residuals(X0), dtype=np.float64)
    ok = [j for j in range(len(starts)) if np.all(np.isfinite(R0[j]))]
    evaluations = np.ones(len(starts), dtype=int)  # each start's own residual
    ends: dict[int, tuple[NDArray[np.float64], float]] = {}
    if ok:
        # a residual that is not finite becomes 10³ × its descent's largest at the start (`CountedResiduals`)
        fill = np.array([1e3 * max(float(np.max(np.abs(R0[j]))), 1e-12) for j in ok])
        try:
            results = levenberg_marquardt_many(
                lambda X: np.asarray(residuals(X), dtype=np.float64), X0[ok], R0[ok], step=limits.LS_STEP,
                max_nfev=limits.LS_MAX_NFEV, fill=fill, on_round=on_round,
            )  # fmt: skip
        except (ValueError, np.linalg.LinAlgError):
            results = []
        for j, res in zip(ok, results, strict=False):
            evaluations[j] += res.njev * X0.shape[1] + res.nfev
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
