"""A fault's trend over flights and the remaining useful life it implies (issue 12; next-features §B).

`DegradationTrend` follows MATLAB's ``linearDegradationModel`` / ``exponentialDegradationModel``
(``update``, ``restart``, ``predictRUL``) with one difference those lack: every measurement comes
with its own variance, the identification's interval (`emaphm.identification.uncertainty`).

- **linear** (friction, backlash, eccentricity, gain drift): k(t) = φ + θ·t + ε_t,
  ε_t ~ N(0, σ_t²);
- **exponential** (coil shorts, self-accelerating): k(t) = exp(φ + θ·t + ε_t), fitted in log k
  with σ_t/k_t as the log-space deviation (a measurement at or near 0 carries little information
  there and is floored at `EXP_FLOOR`).

The posterior of (φ, θ) is Bayesian weighted least squares with a broad Gaussian prior
(`PRIOR_SD`), its covariance inflated by the reduced χ² of the fit when the points scatter more
than their stated variances (a model that is only approximately linear, or intervals that are too
narrow). The time of the threshold crossing is drawn from that posterior in closed form,
t* = (g(k_fail) − φ)/θ with g the identity or the log, so a prediction costs microseconds; a draw
whose trend does not grow towards the threshold never crosses (``inf``), and is counted, never
dropped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

__all__ = ["LAWS", "DegradationTrend", "RulEstimate", "crossings", "observed", "predict_many"]

LAWS = ("linear", "exponential")
PRIOR_SD = 1e3  # [k units, k per flight] a prior that says nothing at the scale of a fault in [0, 1]
EXP_FLOOR = 1e-3  # k below this is taken as this in log space (a fault not yet grown)
MIN_SD = 1e-4  # a measurement's standard deviation is never taken below this [k units]


def observed(
    law: str, k: NDArray[np.float64], sd: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Distances `k` and their deviations `sd` on the law's scale: as they are (linear), or
    ln max(k, `EXP_FLOOR`) with sd/max(k, `EXP_FLOOR`) (exponential; the delta method)."""
    if law == "exponential":
        kk = np.maximum(k, EXP_FLOOR)
        return np.log(kk), sd / kk
    return k, sd


def crossings(
    phi: NDArray[np.float64], theta: NDArray[np.float64], g: float, t_now: float | None = None
) -> NDArray[np.float64]:
    """The flights at which lines φ + θ·t (draws, on the law's scale) reach `g`: inf where θ <= 0;
    with `t_now`, a draw already past `g` then has crossed by `t_now`, whichever way its slope
    points (a falling trend above the threshold has failed, it does not "never" fail)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t_star = np.where(theta > 0, (g - phi) / theta, np.inf)
    if t_now is not None:
        t_star = np.where(phi + theta * t_now >= g, np.minimum(t_star, t_now), t_star)
    return np.asarray(t_star, dtype=np.float64)


@dataclass(frozen=True)
class RulEstimate:
    """The remaining useful life of one fault (or of the first of several) in flights.

    median, p05, p95 : flights from `t_now` to the crossing (inf where more than half, 5 %, 95 %
    of the draws never cross); `samples` the draws; `never` the fraction of draws that never cross.
    """

    median: float
    p05: float
    p95: float
    t_now: float
    samples: NDArray[np.float64] = field(repr=False)
    never: float = 0.0

    def prob_before(self, flights: float) -> float:
        """Probability that the crossing comes within `flights` of `t_now`."""
        return float(np.mean(self.samples <= flights))

    @classmethod
    def from_samples(cls, samples: NDArray[np.float64], t_now: float) -> RulEstimate:
        s = np.asarray(samples, dtype=np.float64)
        # np.quantile(s, q, method="inverted_cdf") is the (ceil(q n) - 1)-th smallest: one partition
        kth = [max(math.ceil(q * s.size) - 1, 0) for q in (0.05, 0.5, 0.95)]
        p05, median, p95 = (float(v) for v in np.partition(s, kth)[kth])
        return cls(median, p05, p95, t_now, s, float(np.mean(~np.isfinite(s))))

    def to_json(self) -> dict[str, Any]:
        def num(v: float) -> float | None:
            return round(v, 3) if math.isfinite(v) else None  # JSON has no inf: null means "beyond"

        return {"rul_median": num(self.median), "rul_p05": num(self.p05), "rul_p95": num(self.p95),
                "never_fraction": round(self.never, 4)}  # fmt: skip


class DegradationTrend:
    """A fault's measured values over flights and their fitted law (see the module docstring).

    Parameters
    ----------
    law : {"linear", "exponential"}
    healthy : float
        The fault's healthy value (0, or 0.5 for the gain drift k8): the trend is of the distance
        from it, |k − healthy|; `side` says on which side of it the measurements lie.
    """

    def __init__(self, law: str = "linear", healthy: float = 0.0) -> None:
        if law not in LAWS:
            raise InputError(f"unknown law {law!r}; use one of {', '.join(LAWS)}")
        self.law, self.healthy = law, float(healthy)
        self.t: list[float] = []
        self.k: list[float] = []
        self.sd: list[float] = []
        self._drift = 0.0  # sum of the measurements' k − healthy, for `side`
        self._fitted: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None

    # -- data -----------------------------------------------------------------------------------

    def update(self, t: ArrayLike, k: ArrayLike, sd: ArrayLike) -> DegradationTrend:
        """Add measurements: flights `t`, values `k` and their standard deviations `sd` (the
        identification's; non-finite or non-positive: the measurement is skipped)."""
        self._fitted = None
        tt, kk, ss = (np.atleast_1d(np.asarray(a, dtype=np.float64)) for a in (t, k, sd))
        if not tt.shape == kk.shape == ss.shape:
            raise ValueError(f"t, k and sd differ in length: {tt.shape}, {kk.shape}, {ss.shape}")
        ok = np.isfinite(tt) & np.isfinite(kk) & np.isfinite(ss) & (ss > 0)
        self.t.extend(tt[ok].tolist())
        self.k.extend(np.abs(kk[ok] - self.healthy).tolist())
        self.sd.extend(np.maximum(ss[ok], MIN_SD).tolist())
        self._drift += float(np.sum(kk[ok] - self.healthy))
        return self

    def restart(self) -> DegradationTrend:
        """Forget every measurement."""
        self.t, self.k, self.sd = [], [], []
        self._drift = 0.0
        self._fitted = None
        return self

    @property
    def side(self) -> float:
        """+1 when the measurements lie above the healthy value on the whole, −1 below (the gain
        drift k8 drifts either way; the other faults only grow): where a distance d lies in fault
        units, healthy + side·d."""
        return -1.0 if self._drift < 0 else 1.0

    def __len__(self) -> int:
        return len(self.t)

    # -- the fit --------------------------------------------------------------------------------

    def _transformed(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        t, k, sd = (np.asarray(a, dtype=np.float64) for a in (self.t, self.k, self.sd))
        return (t, *observed(self.law, k, sd))

    def fit(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Posterior mean and covariance of (φ, θ), t in flights; `InputError` with < 2 flights."""
        if self._fitted is None:  # cleared by `update` and `restart`
            self._fitted = self._fit()
        return self._fitted

    def _fit(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        if len(set(self.t)) < 2:
            raise InputError("a trend needs measurements at two flights at least")
        t, y, sd = self._transformed()
        X = np.column_stack([np.ones_like(t), t])
        W = 1.0 / sd**2
        A = X.T @ (X * W[:, None]) + np.eye(2) / PRIOR_SD**2
        cov = np.linalg.inv(A)
        mean = cov @ (X.T @ (W * y))
        dof = len(t) - 2
        if dof > 0:  # points that scatter more than their variances say widen the posterior
            chi2 = float(np.sum(W * (y - X @ mean) ** 2)) / dof
            cov = cov * max(1.0, chi2)
        return np.asarray(mean, dtype=np.float64), np.asarray(cov, dtype=np.float64)

    def value(self, t: ArrayLike) -> NDArray[np.float64]:
        """The fitted trend at flights `t` (distance from healthy)."""
        mean, _ = self.fit()
        y = mean[0] + mean[1] * np.asarray(t, dtype=np.float64)
        return np.exp(y) if self.law == "exponential" else y

    def band(self, t: ArrayLike, z: float = 1.645) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The trend's 90 % band (of the law's mean) at flights `t`."""
        mean, cov = self.fit()
        tt = np.asarray(t, dtype=np.float64)
        y = mean[0] + mean[1] * tt
        sd = np.sqrt(cov[0, 0] + 2 * tt * cov[0, 1] + tt**2 * cov[1, 1])
        lo, hi = y - z * sd, y + z * sd
        return (np.exp(lo), np.exp(hi)) if self.law == "exponential" else (lo, hi)

    # -- the prediction -------------------------------------------------------------------------

    def crossing_samples(
        self,
        threshold: float,
        n: int = 4000,
        seed: int = 0,
        t_now: float | None = None,
        z: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """Draws of the flight at which the trend reaches `threshold` (distance from healthy); with
        `t_now`, a draw already past the threshold then has crossed by `t_now`, whichever way its
        slope points (a falling trend above the threshold has failed, it does not "never" fail)."""
        if not threshold > 0:
            raise InputError(
                f"a failure threshold must lie beyond the healthy value, got a distance {threshold!r}"
            )
        mean, cov = self.fit()
        if z is None:  # (n, 2) standard normal draws; given, to correlate this trend with others
            z = np.random.default_rng(seed).standard_normal((n, 2))
        draws = mean + z @ np.linalg.cholesky(cov).T
        g = math.log(threshold) if self.law == "exponential" else threshold
        return crossings(draws[:, 0], draws[:, 1], g, t_now)

    def predict_rul(
        self,
        threshold: float,
        t_now: float | None = None,
        n: int = 4000,
        seed: int = 0,
        z: NDArray[np.float64] | None = None,
    ) -> RulEstimate:
        """The RUL in flights from `t_now` (default: the last measurement) to the crossing of
        `threshold` (a distance from healthy); 0 where the draw has already crossed. `z`: the
        posterior's (n, 2) standard normal draws, when they are to be correlated with another
        fault's (`emaphm.prognostics.rul`)."""
        t_now = max(self.t) if t_now is None else float(t_now)
        rul = np.maximum(self.crossing_samples(threshold, n, seed, t_now, z) - t_now, 0.0)
        return RulEstimate.from_samples(rul, t_now)


def predict_many(
    trends: list[DegradationTrend], thresholds: list[float], t_now: float, z: NDArray[np.float64]
) -> list[RulEstimate]:
    """`DegradationTrend.predict_rul` of several trends at once, trend i with the standard normal
    draws ``z[i]`` (shape (trends, n, 2)): the same numbers, each step one array operation over all
    of them (a fleet predicts thousands)."""
    if any(not th > 0 for th in thresholds):
        raise InputError(f"a failure threshold must lie beyond the healthy value, got distances {thresholds}")
    fits = [trend.fit() for trend in trends]
    mean = np.array([m for m, _ in fits])
    chol = np.linalg.cholesky(np.array([c for _, c in fits]))
    z0, z1 = z[..., 0], z[..., 1]  # mean + z @ chol.T, trend by trend (einsum is 10x slower here)
    phi = mean[:, 0, None] + (z0 * chol[:, 0, 0, None] + z1 * chol[:, 0, 1, None])
    theta = mean[:, 1, None] + (z0 * chol[:, 1, 0, None] + z1 * chol[:, 1, 1, None])
    g = np.array(
        [math.log(th) if tr.law == "exponential" else th for tr, th in zip(trends, thresholds, strict=True)]
    )
    rul = np.maximum(crossings(phi, theta, g[:, None], t_now) - t_now, 0.0)
    n = rul.shape[1]
    kth = [max(math.ceil(q * n) - 1, 0) for q in (0.05, 0.5, 0.95)]
    p05, median, p95 = np.partition(rul, kth, axis=1)[:, kth].T
    never = np.mean(~np.isfinite(rul), axis=1)
    return [
        RulEstimate(float(median[i]), float(p05[i]), float(p95[i]), t_now, rul[i], float(never[i]))
        for i in range(len(trends))
    ]
