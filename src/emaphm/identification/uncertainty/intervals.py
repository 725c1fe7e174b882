"""The 90 % intervals of a fault vector and what they say (`Uncertainty`, `intervals`, `verdicts`).

Shared by the Laplace step (`laplace`), the MCMC mode (`mcmc`) and the interval calibration
(`factors`): the Cartesian eccentricity pair u = (k1..k5, e_x, e_y, k8), the intervals with their
flags, their half-widths and coverage, and the verdict per fault.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...faults import FAULT_NAMES, HEALTHY
from ..limits import PHASE_SIGMAS

__all__ = [
    "N_PARAMS", "PHASE", "PHASE_SIGMAS", "Z90", "Z90_ONE", "ZETA", "Uncertainty", "covers", "half_widths",
    "intervals", "to_cartesian", "to_faults", "verdicts",
]  # fmt: skip

Z90 = 1.6448536269514722  # two-sided 90 %: the 95 % normal quantile
Z90_ONE = 1.2815515655446004  # one-sided 90 %
N_PARAMS = len(FAULT_NAMES)
ZETA, PHASE = 5, 6  # indices of k6 (ζ) and k7 (its direction) in the fault vector


def to_cartesian(K: ArrayLike) -> NDArray[np.float64]:
    """Fault rows k → u = (k1..k5, e_x, e_y, k8) with (e_x, e_y) = k6·(cos 2πk7, sin 2πk7)."""
    K = np.array(K, dtype=np.float64, ndmin=2, copy=True)
    rho, phi = K[:, ZETA].copy(), 2.0 * np.pi * K[:, PHASE]
    K[:, ZETA], K[:, PHASE] = rho * np.cos(phi), rho * np.sin(phi)
    return K


def to_faults(U: ArrayLike) -> NDArray[np.float64]:
    """u rows → fault rows k (the inverse of `to_cartesian`; k7 in [0, 1))."""
    U = np.array(U, dtype=np.float64, ndmin=2, copy=True)
    ex, ey = U[:, ZETA].copy(), U[:, PHASE].copy()
    U[:, ZETA] = np.hypot(ex, ey)
    U[:, PHASE] = np.mod(np.arctan2(ey, ex) / (2.0 * np.pi), 1.0)
    return U


@dataclass(frozen=True)
class Uncertainty:
    """Per-fault uncertainty of one estimate (k units; k7 in turns of the circle).

    method : str  how the σ were found: "laplace" or "mcmc"
    std : ndarray  calibrated σ per fault
    ci90_low, ci90_high : ndarray  the 90 % intervals' ends (k7 may wrap: low > high)
    corr : ndarray  8 × 8 correlation matrix
    flags : list of list of str  per fault: at_bound, nonsmooth, phase_undefined, non_identifiable
    raw_std : ndarray  σ before the discrepancy calibration (noise only)
    evaluations : int  LF model evaluations spent on the intervals
    details : dict  the method's diagnostics (τ, steps, wall time, ...)
    cov_u : ndarray or None  covariance of u = (k1..k5, e_x, e_y, k8), noise only
    """

    method: str
    std: NDArray[np.float64]  # calibrated σ per fault (NaN for k7 when its direction is undefined)
    ci90_low: NDArray[np.float64]
    ci90_high: NDArray[np.float64]
    corr: NDArray[np.float64]  # 8 x 8 (NaN in k7's row and column when undefined)
    flags: list[list[str]]
    raw_std: NDArray[np.float64]  # σ before the discrepancy calibration
    evaluations: int
    details: dict[str, Any] = field(default_factory=dict)
    cov_u: NDArray[np.float64] | None = None  # Cov of u = (k1..k5, e_x, e_y, k8), noise only (`sandwich`)

    def half_width(self) -> NDArray[np.float64]:
        """Half the length of each 90 % interval (k7: of its arc)."""
        return half_widths(self.ci90_low, self.ci90_high)

    def to_json(self) -> dict[str, Any]:
        def values(a: NDArray[np.float64]) -> list[Any]:
            return [float(v) if np.isfinite(v) else None for v in np.ravel(a)]

        def clean(x: Any) -> Any:  # JSON has no NaN or inf: null
            if isinstance(x, dict):
                return {k: clean(v) for k, v in x.items()}
            if isinstance(x, (list, tuple)):
                return [clean(v) for v in x]
            if isinstance(x, (float, np.floating)):
                return float(x) if np.isfinite(x) else None
            return x

        return {
            "uq_method": self.method,
            "std": values(self.std),
            "ci90_low": values(self.ci90_low),
            "ci90_high": values(self.ci90_high),
            "corr": [values(row) for row in self.corr],
            "uq_flags": [list(f) for f in self.flags],
            "uq": clean({"raw_std": values(self.raw_std), "evaluations": self.evaluations, **self.details}),
        }


def half_widths(low: ArrayLike, high: ArrayLike) -> NDArray[np.float64]:
    """Half the length of each interval (rows of (m, 8) or one row); k7 (column 6) of its arc on
    the circle, where low > high runs through 0 and [0, 1] is the whole circle (0.5)."""
    lo, hi = (np.asarray(a, dtype=np.float64) for a in (low, high))
    width = hi - lo
    whole = (lo[..., PHASE] == 0.0) & (hi[..., PHASE] == 1.0)
    width[..., PHASE] = np.where(whole, 1.0, np.mod(width[..., PHASE], 1.0))
    return width / 2.0  # type: ignore[no-any-return]


def covers(low: ArrayLike, high: ArrayLike, truth: ArrayLike) -> NDArray[np.bool_]:
    """Whether each true value lies in its interval; k7 (column 6) on the circle, where
    low > high is an arc through 0. Works row-wise on (m, 8) arrays."""
    lo, hi, t = (np.asarray(a, dtype=np.float64) for a in (low, high, truth))
    inside = (lo - 1e-12 <= t) & (t <= hi + 1e-12)
    lo7, hi7, t7 = lo[..., PHASE], hi[..., PHASE], np.mod(t[..., PHASE], 1.0)
    wrapped = lo7 > hi7
    inside[..., PHASE] = np.where(wrapped, (t7 >= lo7) | (t7 <= hi7), (lo7 <= t7) & (t7 <= hi7))
    return inside  # type: ignore[no-any-return]


def intervals(
    k_hat: ArrayLike, std: ArrayLike, *, with_flags: bool = True
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], list[list[str]]]:
    """90 % intervals from calibrated σ (rows of (m, 8) or one row): (std, low, high, flags).

    Two-sided k̂ ± 1.645σ inside [0, 1]; one-sided (k̂ + 1.282σ above 0, or k̂ − 1.282σ below 1) where the
    two-sided one crosses a bound (``at_bound``). k7: an arc, or the whole circle [0, 1] with
    ``phase_undefined`` while ζ̂ < 2σ(ζ) (its σ is then NaN).
    """
    k = np.array(k_hat, dtype=np.float64, ndmin=2)
    s = np.array(std, dtype=np.float64, ndmin=2, copy=True)
    lo, hi = k - Z90 * s, k + Z90 * s
    below, above = lo < 0.0, hi > 1.0
    lo = np.where(below, 0.0, np.where(above, k - Z90_ONE * s, lo))
    hi = np.where(above, 1.0, np.where(below, k + Z90_ONE * s, hi))
    lo, hi = np.clip(lo, 0.0, 1.0), np.clip(hi, 0.0, 1.0)
    undefined = ~(k[:, ZETA] >= PHASE_SIGMAS * s[:, ZETA]) | ~np.isfinite(s[:, PHASE]) | (k[:, ZETA] <= 0.0)
    whole = undefined | (Z90 * s[:, PHASE] >= 0.5)
    with np.errstate(invalid="ignore"):  # a σ that is not finite: the whole circle, chosen below
        lo[:, PHASE] = np.where(whole, 0.0, np.mod(k[:, PHASE] - Z90 * s[:, PHASE], 1.0))
        hi[:, PHASE] = np.where(whole, 1.0, np.mod(k[:, PHASE] + Z90 * s[:, PHASE], 1.0))
    s[:, PHASE] = np.where(undefined, np.nan, s[:, PHASE])
    flags: list[list[str]] = []
    for row in range(k.shape[0] if with_flags else 0):
        f: list[list[str]] = [[] for _ in range(N_PARAMS)]
        for j in range(N_PARAMS):
            if j != PHASE and (below[row, j] or above[row, j]):
                f[j].append("at_bound")
        if undefined[row]:
            f[PHASE].append("phase_undefined")
        flags.append(f)  # type: ignore[arg-type]
    if np.ndim(k_hat) == 1:
        return s[0], lo[0], hi[0], flags[0]  # type: ignore[return-value]
    return s, lo, hi, flags  # type: ignore[return-value]


def verdicts(
    estimate: ArrayLike, low: ArrayLike, high: ArrayLike, thresholds: dict[str, float]
) -> dict[str, str]:
    """Per detectable fault: "present" when its 90 % interval excludes the healthy value by more than
    the threshold, "absent" when the estimate is within the threshold of healthy, else "cannot tell"
    (the estimate departs, but the interval reaches back to within the threshold of healthy).

    Parameters
    ----------
    estimate : array_like of 8 floats in [0, 1]
        The identified fault vector k1..k8.
    low, high : array_like of 8 floats
        The ends of the 90 % intervals (`Uncertainty.ci90_low`, `Uncertainty.ci90_high`).
    thresholds : dict of str to float
        The detection threshold of each fault, in fault units above healthy (`detect`).
    """
    k, lo, hi = (np.asarray(a, dtype=np.float64) for a in (estimate, low, high))
    out: dict[str, str] = {}
    for j, name in enumerate(FAULT_NAMES):
        if name not in thresholds:
            continue
        h, thr = HEALTHY[j], thresholds[name]
        excluded = max(lo[j] - h, h - hi[j])
        if excluded > thr:
            out[name] = "present"
        elif abs(k[j] - h) <= thr:
            out[name] = "absent"
        else:
            out[name] = "cannot tell"
    return out
