"""A bounded Levenberg–Marquardt least-squares solver: the runner-ups' polish (`polish.lm_polish`).

Minimises f(x) = Σ r(x)² over the box [lower, upper]^n, where r is a residual vector of m ≫ n
samples (eq. 3's √w·(I_ref − I_LF), m ≈ 10⁴, n = 8) and its Jacobian J is taken by forward
differences in one batch of n rows. Each iteration works on the n × n normal equations only,

    (JᵀJ + μ·D) δ = −Jᵀr,     D = diag(JᵀJ)       (Marquardt's scaling, invariant to the units of x)

with the damping μ updated from the gain ratio ρ = actual / predicted reduction (Nielsen's rule:
μ·max(1/3, 1 − (2ρ − 1)³) on success, μ·ν, ν·2 on failure). A step is projected into the box; a
variable at a bound whose gradient points out of the box is held there for that step.

Why not `scipy.optimize.least_squares`: its trust-region reflective method works on the m × n
Jacobian itself (an SVD and several m × n products per iteration): measured on a random case
(bench_multifault seed 6061, case 1) 0.54 s of a 0.68 s polish was the solver's own arithmetic,
0.09 s the 111 monitor runs (with one BLAS thread, as inside `identify`, 0.07 s against this
solver's 0.04 s). The normal equations lose precision only when JᵀJ is ill-conditioned beyond
~1e8, where the damping keeps the step bounded anyway.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["LmResult", "levenberg_marquardt"]

Batch = Callable[[NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True)
class LmResult:
    """The end point `x`, its f = Σ r², the trial points evaluated (`nfev`, Jacobians not
    counted), the Jacobians taken (`njev`) and why it stopped (`status`)."""

    x: NDArray[np.float64]
    f: float
    nfev: int
    njev: int
    status: str


def _sum_sq(r: NDArray[np.float64]) -> float:
    """Σ r², summed as `Context.evaluate` sums eq. 3 (numpy's pairwise sum), independent of BLAS."""
    return float(np.sum(r * r))


def _jacobian(batch: Batch, x: NDArray[np.float64], r: NDArray[np.float64], step: float,
              upper: float) -> NDArray[np.float64]:  # fmt: skip
    """Jᵀ (n × m, rows contiguous) by forward differences of `step` in one batch of n rows
    (backward at the upper bound)."""
    n = len(x)
    h = np.where(x + step <= upper, step, -step)
    X = np.repeat(x[None, :], n, axis=0)
    X[np.arange(n), np.arange(n)] += h
    return (batch(X) - r) / h[:, None]  # type: ignore[no-any-return]


def levenberg_marquardt(
    batch: Batch,
    x0: NDArray[np.float64],
    r0: NDArray[np.float64],
    *,
    step: float,
    max_nfev: int,
    lower: float = 0.0,
    upper: float = 1.0,
    ftol: float = 1e-8,
    xtol: float = 1e-8,
    mu0: float = 1e-3,
) -> LmResult:
    """Minimise Σ r(x)² from x0 (in the box), r0 = r(x0), by bounded Levenberg–Marquardt.

    `batch` maps rows of points (k × n) to their residual vectors (k × m), finite (the caller
    replaces a diverged run's residual by a large one). Stops when an accepted step lowers f by
    less than `ftol`·f while predicting no more, when a step is below `xtol`·(xtol + |x|), or
    after `max_nfev` trial points.
    """
    x = np.clip(np.asarray(x0, dtype=np.float64), lower, upper)
    r = np.asarray(r0, dtype=np.float64)
    f = _sum_sq(r)
    mu, nu, nfev, njev = mu0, 2.0, 0, 0
    while nfev < max_nfev:
        Jt = _jacobian(batch, x, r, step, upper)
        njev += 1
        # einsum, not BLAS: the same sums in the same order whatever BLAS's threads (a 1e-16
        # difference flips an accept/reject near the end and moves the path: review of issue 36)
        A, g = np.einsum("ik,jk->ij", Jt, Jt), np.einsum("ik,k->i", Jt, r)
        held = ((x <= lower) & (g > 0.0)) | ((x >= upper) & (g < 0.0))
        free = ~held
        d = np.diag(A).copy()
        d = np.maximum(d, 1e-12 * max(float(d.max()), 1e-300))
        while True:
            if nfev >= max_nfev:
                return LmResult(x, f, nfev, njev, "budget")
            delta = np.zeros_like(x)
            Af = A[np.ix_(free, free)] + mu * np.diag(d[free])
            try:
                delta[free] = np.linalg.solve(Af, -g[free])
            except np.linalg.LinAlgError:
                return LmResult(x, f, nfev, njev, "singular")
            x_new = np.clip(x + delta, lower, upper)
            s = x_new - x
            if np.linalg.norm(s) <= xtol * (xtol + np.linalg.norm(x)):
                return LmResult(x, f, nfev, njev, "xtol")
            r_new = batch(x_new[None, :])[0]
            nfev += 1
            f_new = _sum_sq(r_new)
            predicted = -(2.0 * float(s @ g) + float(s @ A @ s))
            actual = f - f_new
            if actual > 0.0 and predicted > 0.0:
                rho = actual / predicted
                mu *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                nu = 2.0
                x, r, f = x_new, r_new, f_new
                break
            mu *= nu
            nu *= 2.0
        if actual < ftol * (f + actual) and predicted < ftol * (f + actual):
            return LmResult(x, f, nfev, njev, "ftol")
    return LmResult(x, f, nfev, njev, "budget")
