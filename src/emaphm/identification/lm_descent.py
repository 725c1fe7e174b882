"""One bounded Levenberg–Marquardt descent as a sequence of requests (`Descent`), and what the
solver's callers share: its result (`LmResult`), the forward-difference probes of a Jacobian
(`forward_probes`), the dampings (`SCALINGS`) and the secants' refresh (`BROYDEN_REFRESH`).

`lm.levenberg_marquardt_many` serves the requests of several descents in one batch of monitor
runs per round; the method, the secants and the spare trial point are described there (`lm`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

__all__ = ["BROYDEN_REFRESH", "SCALINGS", "Descent", "LmResult", "forward_probes", "gram"]

# D of the normal equations (`lm`'s docstring)
SCALINGS = ("marquardt", "identity")
# with ``broyden``: a difference Jacobian after this many accepted steps on secant updates
BROYDEN_REFRESH = 4


@dataclass(frozen=True)
class LmResult:
    """The end point `x`, its f = Σ r², the trial points taken (`nfev`, Jacobians not
    counted), the Jacobians taken (`njev`), why it stopped (`status`) and the spare trial points
    evaluated and never taken (`spared`; `lm`'s docstring): its monitor runs are
    njev·n + nfev + spared."""

    x: NDArray[np.float64]
    f: float
    nfev: int
    njev: int
    status: str
    spared: int = 0


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


def gram(Jt: NDArray[np.float64]) -> NDArray[np.float64]:
    """JᵀJ from Jᵀ (n × m): ``np.einsum("ik,jk->ij", Jt, Jt)`` to the bit, in a little over half
    its time (0.27 -> 0.18 ms for 8 × 10 001, 129 a diagnosis: issue 36).

    einsum's product is symmetric to the bit (entry (j, i) is the same dot product as (i, j)), and
    its row i is ``np.einsum("k,jk->j", Jt[i], Jt)``: the same inner loop per entry. So each row
    is taken from column i on, and mirrored. Always against at least two rows of Jᵀ: against one,
    einsum runs a plain dot product, whose sum differs in the last bit
    (`tests/identification/test_lm.py` checks the equality on random shapes and views).
    """
    n = Jt.shape[0]
    if n < 2:
        return np.einsum("ik,jk->ij", Jt, Jt)  # type: ignore[no-any-return]
    A = np.empty((n, n))
    for i in range(n):
        lo = min(i, n - 2)
        row = np.einsum("k,jk->j", Jt[i], Jt[lo:])[i - lo :]
        A[i, i:] = row
        A[i:, i] = row
    return A


def _sum_sq(r: NDArray[np.float64]) -> float:
    """Σ r², summed as `Context.evaluate` sums eq. 3 (numpy's pairwise sum), independent of BLAS."""
    return float(np.sum(r * r))


class Descent:
    """One Levenberg–Marquardt descent as a sequence of requests: `rows` gives the points whose
    residuals it needs next (a Jacobian's n rows, or one trial point; None once it has stopped),
    `take` consumes their residuals. `lm.levenberg_marquardt_many` serves several in one batch."""

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
        # a spare trial point evaluated beside the last one and its residual (`spare_trial`); how
        # many were evaluated and never taken
        self.spare: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self.spared = 0
        if not self.nfev < self.max_nfev:
            self._stop("budget")

    def _stop(self, status: str) -> None:
        if self.broyden and self.secant_steps and status in ("ftol", "xtol") and self.nfev < self.max_nfev:
            self.A = None  # on a secant Jacobian: look again with a difference one before stopping
            return
        if self.spare is not None:  # evaluated and never asked for
            self.spare, self.spared = None, self.spared + 1
        self.result = LmResult(self.x, self.f, self.nfev, self.njev, status, self.spared)

    def _normal_equations(self, Jt: NDArray[np.float64]) -> None:
        """JᵀJ, Jᵀr, the variables held at a bound and the damping's D from Jᵀ (n × m) at x."""
        # einsum, not BLAS: the same sums in the same order whatever BLAS's threads (a 1e-16
        # difference flips an accept/reject near the end and moves the path: review of issue 36)
        self.A, self.g = gram(Jt), np.einsum("ik,k->i", Jt, self.r)
        held = ((self.x <= self.lower) & (self.g > 0.0)) | ((self.x >= self.upper) & (self.g < 0.0))
        self.free = ~held
        d = np.diag(self.A).copy()
        if self.scaling == "identity":
            d[:] = max(float(d.max()), 1e-300)
        self.d = np.maximum(d, 1e-12 * max(float(d.max()), 1e-300))

    def _secant(self, s: NDArray[np.float64], r_new: NDArray[np.float64]) -> None:
        """Broyden's rank-one update of Jᵀ along the trial step s (`lm`'s docstring)."""
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
        x_new = self._trial(self.mu)
        if x_new is None:
            self._stop("singular")
            return None
        self.x_new = x_new
        if self._too_short(x_new):
            self._stop("xtol")
            return self.rows()  # a difference Jacobian first, if the stop was on a secant one
        return self.x_new[None, :]

    def _trial(self, mu: float) -> NDArray[np.float64] | None:
        """The trial point of the damped normal equations at x with damping `mu` (None: singular)."""
        delta = np.zeros_like(self.x)
        Af = self.A[np.ix_(self.free, self.free)] + mu * np.diag(self.d[self.free])  # type: ignore[index]
        try:
            delta[self.free] = np.linalg.solve(Af, -self.g[self.free])  # type: ignore[index]
        except np.linalg.LinAlgError:
            return None
        return np.clip(self.x + delta, self.lower, self.upper)  # type: ignore[no-any-return]

    def _too_short(self, x_new: NDArray[np.float64]) -> bool:
        return bool(np.linalg.norm(x_new - self.x) <= self.xtol * (self.xtol + np.linalg.norm(self.x)))

    def spare_trial(self) -> NDArray[np.float64] | None:
        """The trial point this descent asks for next if the one `rows` gave is rejected: the same
        normal equations with the damping μ·ν that `take` then sets. None where a rejection leads
        elsewhere: to the budget's end, to a difference Jacobian (a second rejection in a row on a
        secant one), or to a stop (a singular system, a step below `xtol`)."""
        if self.result is not None or self.A is None or self.x_new is None:
            return None
        if not self.nfev + 1 < self.max_nfev:
            return None
        if self.broyden and self.secant_steps and self.rejected + 1 >= 2:
            return None
        x_spare = self._trial(self.mu * self.nu)
        if x_spare is None or self._too_short(x_spare):
            return None
        return x_spare

    def hold_spare(self, x_spare: NDArray[np.float64], r_spare: NDArray[np.float64]) -> None:
        """Keep a spare trial point's residual for `spared_residuals`; where the trial beside it
        ended the descent, the spare is only counted (`LmResult.spared`)."""
        if self.result is not None:
            self.spared += 1
            self.result = replace(self.result, spared=self.spared)
            return
        self.spare = (x_spare, r_spare)

    def spared_residuals(self, X: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The residuals of the points `rows` gave, where they are exactly the spare trial point
        kept (then taken from there, not evaluated again); None otherwise. A spare is offered once."""
        if self.spare is None:
            return None
        (x_spare, r_spare), self.spare = self.spare, None
        if len(X) == 1 and self.A is not None and np.array_equal(X[0], x_spare):
            return r_spare[None, :]
        self.spared += 1
        return None

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
