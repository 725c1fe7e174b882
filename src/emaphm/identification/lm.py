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
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["BROYDEN_REFRESH", "SCALINGS", "LmResult", "forward_probes", "levenberg_marquardt", "levenberg_marquardt_many"]

Batch = Callable[[NDArray[np.float64]], NDArray[np.float64]]

# D of the normal equations (the module docstring)
SCALINGS = ("marquardt", "identity")
# with ``broyden``: a difference Jacobian after this many accepted steps on secant updates
BROYDEN_REFRESH = 4


@dataclass(frozen=True)
class LmResult:
    """The end point `x`, its f = Σ r², the trial points evaluated (`nfev`, Jacobians not
    counted), the Jacobians taken (`njev`) and why it stopped (`status`)."""

    x: NDArray[np.float64]
    f: float
    nfev: int
    njev: int
    status: str


def forward_probes(
    x: NDArray[np.float64], step: float, upper: float = 1.0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The n rows of a forward-difference Jacobian at x (row i: x with x_i + h_i) and the steps h:
    `step`, backward (−`step`) where the forward one would pass `upper`. The polishes' Jacobians
    (this solver's, `polish.least_squares_polish`'s, `preconditioned`'s) all take these rows;
    J = ((R − r(x)) / h[:, None])ᵀ from their residuals R.

    x : the point (n,); step : the difference's step; upper : the box's upper bound.
    """
    n = len(x)
    h = np.where(x + step <= upper, step, -step)
    X = np.repeat(np.asarray(x, dtype=np.float64)[None, :], n, axis=0)
    X[np.arange(n), np.arange(n)] += h
    return X, h


def _sum_sq(r: NDArray[np.float64]) -> float:
    """Σ r², summed as `Context.evaluate` sums eq. 3 (numpy's pairwise sum), independent of BLAS."""
    return float(np.sum(r * r))


class _Descent:
    """One Levenberg–Marquardt descent as a sequence of requests: `rows` gives the points whose
    residuals it needs next (a Jacobian's n rows, or one trial point; None once it has stopped),
    `take` consumes their residuals. `levenberg_marquardt_many` serves several in one batch."""

    def __init__(self, x0: NDArray[np.float64], r0: NDArray[np.float64], step: float, max_nfev: int,
                 lower: float, upper: float, ftol: float, xtol: float, mu0: float, broyden: bool = False,
                 min_secant: float = 0.0, scaling: str = "marquardt") -> None:  # fmt: skip
        if scaling not in SCALINGS:
            raise ValueError(f"unknown scaling {scaling!r}; use one of {SCALINGS}")
        self.scaling = scaling
        self.x = np.clip(np.asarray(x0, dtype=np.float64), lower, upper)
        self.r = np.asarray(r0, dtype=np.float64)
        self.f = _sum_sq(self.r)
        self.step, self.max_nfev, self.lower, self.upper = step, max_nfev, lower, upper
        self.ftol, self.xtol = ftol, xtol
        self.mu, self.nu, self.nfev, self.njev = mu0, 2.0, 0, 0
        self.broyden, self.min_secant = broyden, min_secant
        # accepted steps since the last difference Jacobian; rejected steps in a row
        self.secant_steps = self.rejected = 0
        self.result: LmResult | None = None
        self.h: NDArray[np.float64] | None = None  # the Jacobian's steps while one is requested
        self.x_new: NDArray[np.float64] | None = None  # the trial point while one is requested
        self.J: NDArray[np.float64] | None = None  # Jᵀ (n × m), kept with ``broyden``
        self.A = self.g = self.d = self.free = None
        if not self.nfev < self.max_nfev:
            self._stop("budget")

    def _stop(self, status: str) -> None:
        if self.broyden and self.secant_steps and status in ("ftol", "xtol") and self.nfev < self.max_nfev:
            self.A = None  # on a secant Jacobian: look again with a difference one before stopping
            return
        self.result = LmResult(self.x, self.f, self.nfev, self.njev, status)

    def _normal_equations(self, Jt: NDArray[np.float64]) -> None:
        """JᵀJ, Jᵀr, the variables held at a bound and the damping's D from Jᵀ (n × m) at x."""
        # einsum, not BLAS: the same sums in the same order whatever BLAS's threads (a 1e-16
        # difference flips an accept/reject near the end and moves the path: review of issue 36)
        self.A, self.g = np.einsum("ik,jk->ij", Jt, Jt), np.einsum("ik,k->i", Jt, self.r)
        held = ((self.x <= self.lower) & (self.g > 0.0)) | ((self.x >= self.upper) & (self.g < 0.0))
        self.free = ~held
        d = np.diag(self.A).copy()
        if self.scaling == "identity":
            d[:] = max(float(d.max()), 1e-300)
        self.d = np.maximum(d, 1e-12 * max(float(d.max()), 1e-300))

    def _secant(self, s: NDArray[np.float64], r_new: NDArray[np.float64]) -> None:
        """Broyden's rank-one update of Jᵀ along the trial step s (module docstring)."""
        ss = float(s @ s)
        if self.J is None or not ss > self.min_secant**2:
            return
        miss = r_new - self.r - np.einsum("ik,i->k", self.J, s)
        self.J += s[:, None] * (miss / ss)[None, :]

    def rows(self) -> NDArray[np.float64] | None:
        """The points to evaluate next (k × n), None when stopped."""
        if self.result is not None:
            return None
        if self.A is None:  # a Jacobian at x: forward differences (backward at the upper bound)
            X, self.h = forward_probes(self.x, self.step, self.upper)
            return X
        if self.nfev >= self.max_nfev:
            self._stop("budget")
            return None
        delta = np.zeros_like(self.x)
        Af = self.A[np.ix_(self.free, self.free)] + self.mu * np.diag(self.d[self.free])
        try:
            delta[self.free] = np.linalg.solve(Af, -self.g[self.free])
        except np.linalg.LinAlgError:
            self._stop("singular")
            return None
        self.x_new = np.clip(self.x + delta, self.lower, self.upper)
        if np.linalg.norm(self.x_new - self.x) <= self.xtol * (self.xtol + np.linalg.norm(self.x)):
            self._stop("xtol")
            return self.rows()  # a difference Jacobian first, if the stop was on a secant one
        return self.x_new[None, :]

    def take(self, R: NDArray[np.float64]) -> None:
        """The residuals of the points `rows` gave."""
        if self.A is None:
            Jt = (R - self.r) / self.h[:, None]  # type: ignore[index]
            self.njev += 1
            self.secant_steps = self.rejected = 0
            self.J = Jt if self.broyden else None
            self._normal_equations(Jt)
            return
        r_new = R[0]
        self.nfev += 1
        f_new = _sum_sq(r_new)
        s = self.x_new - self.x  # type: ignore[operator]
        predicted = -(2.0 * float(s @ self.g) + float(s @ self.A @ s))
        actual = self.f - f_new
        if actual > 0.0 and predicted > 0.0:
            if self.broyden:
                self._secant(s, r_new)
            rho = actual / predicted
            self.mu *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
            self.nu = 2.0
            self.x, self.r, self.f = self.x_new, r_new, f_new
            self.secant_steps += 1
            self.rejected = 0
            if self.broyden and self.secant_steps < BROYDEN_REFRESH:
                self._normal_equations(self.J)  # type: ignore[arg-type]
            else:
                self.A = None  # the next request is a Jacobian at the new point
            if actual < self.ftol * (self.f + actual) and predicted < self.ftol * (self.f + actual):
                self._stop("ftol")
            elif not self.nfev < self.max_nfev:
                self._stop("budget")
            return
        self.mu *= self.nu
        self.nu *= 2.0
        if self.broyden and self.secant_steps:
            self.rejected += 1
            if self.rejected >= 2:
                self.A = None  # two rejections in a row on a secant Jacobian: a difference one


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
) -> list[LmResult]:
    """`levenberg_marquardt` from each row of X0 (R0: their residuals), in lockstep: every round
    evaluates what each running descent needs next (a Jacobian's n rows or one trial point) in one
    call of `batch`. Rows are independent, so each descent takes the path it takes alone; the
    batch keeps both cores busy where a lone descent's trial points run one at a time.

    `fill` (one value per descent, optional): what a residual that is not finite becomes in that
    descent's rows (a trial point that diverges is then rejected), as a caller of
    `levenberg_marquardt` does in its own `batch`. `on_round(stopped, total)` follows the rounds.
    `broyden`, `min_secant`: secant updates of the Jacobian; `scaling`: the damping's D (the
    module docstring).
    """
    descents = [_Descent(x0, r0, step, max_nfev, lower, upper, ftol, xtol, mu0, broyden, min_secant, scaling)
                for x0, r0 in zip(X0, R0, strict=True)]  # fmt: skip
    while True:
        wanted = [(j, d, d.rows()) for j, d in enumerate(descents)]
        wanted = [(j, d, X) for j, d, X in wanted if X is not None]
        if not wanted:
            if on_round is not None:
                on_round(len(descents), len(descents))
            return [d.result for d in descents]  # type: ignore[misc]
        R = batch(np.concatenate([X for _, _, X in wanted]))
        at = 0
        for j, d, X in wanted:
            part = R[at : at + len(X)]
            d.take(part if fill is None else np.where(np.isfinite(part), part, fill[j]))
            at += len(X)
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
) -> LmResult:
    """Minimise Σ r(x)² from x0 (in the box), r0 = r(x0), by bounded Levenberg–Marquardt.

    `batch` maps rows of points (k × n) to their residual vectors (k × m), finite (the caller
    replaces a diverged run's residual by a large one). Stops when an accepted step lowers f by
    less than `ftol`·f while predicting no more, when a step is below `xtol`·(xtol + |x|), or
    after `max_nfev` trial points. With `broyden`, accepted steps longer than `min_secant` update
    the Jacobian by secants; `scaling` is the damping's D (the module docstring).
    """
    return levenberg_marquardt_many(
        batch, np.asarray(x0, dtype=np.float64)[None, :], np.asarray(r0, dtype=np.float64)[None, :], step=step,
        max_nfev=max_nfev, lower=lower, upper=upper, ftol=ftol, xtol=xtol, mu0=mu0, broyden=broyden,
        min_secant=min_secant, scaling=scaling,
    )[0]  # fmt: skip
