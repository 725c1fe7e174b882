"""A bounded Levenberg–Marquardt least-squares solver: the runner-ups' polish and the multistart's
descents (`descents.lm_polish_many`), the search's last polish and the last stage's
(`polish.least_squares_polish`), the current's scale refits (`current_scale`).

Minimises f(x) = Σ r(x)² over the box [lower, upper]^n, where r is a residual vector of m ≫ n
samples (eq. 3's √w·(I_ref − I_LF), m ≈ 10⁴, n = 8) and its Jacobian J is taken by forward
differences in one batch of n rows. Each iteration works on the n × n normal equations only,

    (JᵀJ + μ·D) δ = −Jᵀr,     D = diag(JᵀJ)       (Marquardt's scaling, invariant to the units of x)

or, with ``scaling="identity"``, D = max(diag(JᵀJ))·I (Levenberg's isotropic damping: a spherical
trust region in x, the least-squares polish's, `polish.least_squares_polish`),

with the damping μ updated from the gain ratio ρ = actual / predicted reduction (Nielsen's rule:
μ·max(1/3, 1 − (2ρ − 1)³) on success, μ·ν, ν·2 on failure). A step is projected into the box; a
variable at a bound whose gradient points out of the box is held there for that step.

With ``broyden`` (the secant version of Madsen, Nielsen & Tingleff, *Methods for non-linear least
squares problems*, 2004, §3.4), each accepted step h updates J by Broyden's rank-one secant

    J ← J + (r(x + h) − r(x) − J h) hᵀ / (hᵀh)

instead of a new finite-difference Jacobian (n monitor runs saved; a rejected step leaves J).
A difference Jacobian is taken at the start, after `BROYDEN_REFRESH` accepted steps on secants,
after two rejected steps in a row, and before the descent would stop on a secant Jacobian (so
that it stops where a difference Jacobian sees no descent). A step shorter than `min_secant` does
not update J: eq. 3 is rough below ~1e-3 (`preconditioned`'s docstring), where a secant measures
the roughness, not the slope.

A spare trial (issue 36, thirteenth session): a lone descent's round is one trial point, one
monitor run, which leaves the second core idle, and more than half its trial points are rejected
(382 of 683 in three Table 1 runs). Where a round would evaluate one trial point alone, the
descent also evaluates the point it asks for next if that one is rejected (the damping μ·ν;
`lm_descent.Descent.spare_trial`), and takes its residual from there when it does ask for exactly that
point. The path is the same point for point; the spare trials that are not taken are counted
(`LmResult.spared`).

Why not `scipy.optimize.least_squares`: its trust-region reflective method works on the m × n
Jacobian itself (an SVD and several m × n products per iteration): measured on a random case
(bench_multifault seed 6061, case 1) 0.54 s of a 0.68 s polish was the solver's own arithmetic,
0.09 s the 111 monitor runs (with one BLAS thread, as inside `identify`, 0.07 s against this
solver's 0.04 s); and importing scipy.optimize alone was 0.56–0.75 s of a diagnosis on machine
E (issue 36), so since its tenth session every polish of `identify` runs here. The normal
equations lose precision only when JᵀJ is ill-conditioned beyond ~1e8, where the damping keeps
the step bounded anyway.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from .lm_descent import BROYDEN_REFRESH, SCALINGS, Descent, LmResult, forward_probes

__all__ = ["BROYDEN_REFRESH", "SCALINGS", "LmResult", "forward_probes", "levenberg_marquardt", "levenberg_marquardt_many"]

Batch = Callable[[NDArray[np.float64]], NDArray[np.float64]]

def levenberg_marquardt_many(
    batch: Batch,
    X0: NDArray[np.float64],
    R0: NDArray[np.float64],
    *,
    step: float,
    max_nfev: int,
    lower: float = 0.0,
    upper: float = 1.0,
    ftol: float = 1e-8,
    xtol: float = 1e-8,
    mu0: float = 1e-3,
    fill: NDArray[np.float64] | None = None,
    on_round: Callable[[int, int], None] | None = None,
    broyden: bool = False,
    min_secant: float = 0.0,
    scaling: str = "marquardt",
    spare_trials: bool = True,
) -> list[LmResult]:
    """`levenberg_marquardt` from each row of X0 (R0: their residuals), in lockstep: every round
    evaluates what each running descent needs next (a Jacobian's n rows or one trial point) in one
    call of `batch`. Rows are independent, so each descent takes the path it takes alone; the
    batch keeps both cores busy where a lone descent's trial points run one at a time.

    `fill` (one value per descent, optional): what a residual that is not finite becomes in that
    descent's rows (a trial point that diverges is then rejected), as a caller of
    `levenberg_marquardt` does in its own `batch`. `on_round(stopped, total)` follows the rounds.
    `broyden`, `min_secant`: secant updates of the Jacobian; `scaling`: the damping's D;
    `spare_trials`: a round of one trial point alone also evaluates the descent's spare trial (the
    module docstring: the same path, in fewer rounds).
    """
    descents = [Descent(x0, r0, step, max_nfev, lower, upper, ftol, xtol, mu0, broyden, min_secant, scaling)
                for x0, r0 in zip(X0, R0, strict=True)]  # fmt: skip

    def filled(j: int, part: NDArray[np.float64]) -> NDArray[np.float64]:
        if fill is None or np.isfinite(part).all():  # nearly always: no copy of the rows
            return part
        return np.where(np.isfinite(part), part, fill[j])

    while True:
        wanted = []
        for j, d in enumerate(descents):
            X = d.rows()
            while X is not None and (R_kept := d.spared_residuals(X)) is not None:
                d.take(R_kept)  # the spare trial point it asked for: already evaluated
                X = d.rows()
            if X is not None:
                wanted.append((j, d, X))
        if not wanted:
            if on_round is not None:
                on_round(len(descents), len(descents))
            return [d.result for d in descents]  # type: ignore[misc]
        rows = [X for _, _, X in wanted]
        spare = None
        if spare_trials and len(wanted) == 1 and len(rows[0]) == 1:  # one trial point alone: a spare beside it
            spare = wanted[0][1].spare_trial()
            if spare is not None:
                rows.append(spare[None, :])
        R = batch(np.concatenate(rows))
        at = 0
        for j, d, X in wanted:
            d.take(filled(j, R[at : at + len(X)]))
            at += len(X)
        if spare is not None:
            j, d, _ = wanted[0]
            d.hold_spare(spare, filled(j, R[at]))
        if on_round is not None:
            on_round(sum(d.result is not None for d in descents), len(descents))


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
    broyden: bool = False,
    min_secant: float = 0.0,
    scaling: str = "marquardt",
    spare_trials: bool = True,
) -> LmResult:
    """Minimise Σ r(x)² from x0 (in the box), r0 = r(x0), by bounded Levenberg–Marquardt.

    `batch` maps rows of points (k × n) to their residual vectors (k × m), finite (the caller
    replaces a diverged run's residual by a large one). Stops when an accepted step lowers f by
    less than `ftol`·f while predicting no more, when a step is below `xtol`·(xtol + |x|), or
    after `max_nfev` trial points. With `broyden`, accepted steps longer than `min_secant` update
    the Jacobian by secants; `scaling` is the damping's D; `spare_trials`: each trial point with
    its spare (the module docstring).
    """
    return levenberg_marquardt_many(
        batch, np.asarray(x0, dtype=np.float64)[None, :], np.asarray(r0, dtype=np.float64)[None, :], step=step,
        max_nfev=max_nfev, lower=lower, upper=upper, ftol=ftol, xtol=xtol, mu0=mu0, broyden=broyden,
        min_secant=min_secant, scaling=scaling, spare_trials=spare_trials,
    )[0]  # fmt: skip
