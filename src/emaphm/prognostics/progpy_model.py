"""The fault-growth laws as a ProgPy model, tracked by ProgPy's unscented Kalman filter (issue 12).

ProgPy (NASA, 1.9) is the framework PHM engineers build prognostics on. This module makes
emaphm's fault trends one of its models, so that a history of diagnoses goes into ProgPy's
estimators, predictors and metrics, and so that ``emaphm rul --estimator ukf`` tracks each fault
with ProgPy's UKF instead of `DegradationTrend`'s regression. ProgPy is an optional extra
(``pip install 'emaphm[progpy]'``), imported here only: ``import emaphm`` never loads it, and
without it this module raises `InputError` naming the extra.

`FaultGrowth` (a ``progpy.PrognosticsModel``, time in flights, no inputs), per fault f with its
law (next-features §B.3):

- **linear** (friction, backlash, eccentricity, gain drift): states ``f`` = d (distance from
  healthy) and ``f_rate`` = r, d(t + Δ) = d + r·Δ;
- **exponential** (coil shorts): states ``f_log`` = ln d and ``f_rate`` = r, ln d(t + Δ) =
  ln d + r·Δ, so d = exp(ln d) stays positive, as the UKF needs (next-features §B.4);

output the level state (``f`` = d, or ``f_log`` = ln d), event ``f_failure`` at d ≥ the fault's
threshold, event state 1 − d/threshold clipped to [0, 1]. The model is linear in its states, and a
step is the law's exact solution, so the step size does not change a prediction. The exponential
law is observed in log space, ln max(d, `EXP_FLOOR`) with the deviation sd/d, as
`DegradationTrend` fits it: observed as d, the filter's sigma points spread ln d by the rate's
uncertainty times the gap between measurements, and exp() of that broke the unscented transform
on measurements 10 flights apart (a review found a posterior d of 3·10⁵ against a measured 0.06).
There is no process noise unless asked for (`rate_walk`).

`track` runs ``progpy.state_estimators.UnscentedKalmanFilter`` over one fault's measurements,
setting the filter's measurement covariance R before every update to that identification's own
variance: ProgPy's UKF otherwise keeps the R given at construction (next-features §B.1).
Measurements at the same flight (several seeds) are pooled by their precisions first, because the
filter's time must increase; flights are whole numbers (ProgPy's filter steps its clock by
additions, which fractional times would round past the next measurement). `predict_rul` draws the posterior state and solves each draw's
crossing in closed form (microseconds); `montecarlo_toe` asks ProgPy's ``MonteCarlo`` predictor
the same question by simulation, with ``t0`` set and never-crossing draws as ``inf``, not
``None`` (the tests hold the two to each other). `toe_profile` and `progpy_metrics`
(`emaphm.prognostics.progpy_metrics`, re-exported here) give ProgPy's α-λ, prognostic horizon
and cumulative relative accuracy of a sequence of predictions.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._progpy import (
    MonteCarlo,
    MultivariateNormalDist,
    PrognosticsModel,
    UnscentedKalmanFilter,
    UnweightedSamples,
)
from .progpy_metrics import progpy_metrics, toe_profile
from .trend import LAWS, MIN_SD, DegradationTrend, RulEstimate, crossings, observed

__all__ = [
    "FaultGrowth",
    "UkfTrend",
    "montecarlo_toe",
    "predict_rul",
    "progpy_metrics",
    "toe_profile",
    "track",
]

RATE_PRIOR_SD = {"linear": 0.1, "exponential": 0.5}
"""Prior sd of a fault's rate [per flight] before its second measurement: a linear fault crossing
its whole range in 10 flights, a short growing 1.65× per flight, is 1 sd: broad at the scale of
wear, narrow enough to keep the exponential law's sigma points finite."""
NEVER = math.inf


class FaultGrowth(PrognosticsModel):  # type: ignore[misc]
    """Fault-growth model of several faults (see the module docstring).

    Parameters
    ----------
    faults : mapping name -> (law, threshold)
        Each fault's law ("linear" or "exponential") and failure threshold (a distance from
        healthy, > 0), e.g. ``{"friction": ("linear", 0.45), "short_b": ("exponential", 0.2)}``.
    rate_walk : float
        Standard deviation of a random walk of each rate per flight (0: the rate is constant, and
        the filter is Bayesian regression). `track` gives the filter Q = rate_walk²·Δ for a gap of
        Δ flights; in ProgPy's own simulation it is the rate states' process noise, which ProgPy
        applies as dt·N(0, σ) per step: simulate with dt = 1 flight.
    **kwargs
        ProgPy model parameters (``x0``, ...).
    """

    is_vectorized = True

    def __init__(self, faults: Mapping[str, tuple[str, float]], rate_walk: float = 0.0, **kwargs: Any):
        if not faults:
            raise InputError("a fault-growth model needs one fault at least")
        self.laws: dict[str, str] = {}
        self.thresholds: dict[str, float] = {}
        for name, (law, threshold) in faults.items():
            if law not in LAWS:
                raise InputError(f"{name}: unknown law {law!r}; use one of {', '.join(LAWS)}")
            if not (math.isfinite(threshold) and threshold > 0):
                raise InputError(
                    f"{name}: a failure threshold is a distance from healthy > 0, got {threshold!r}"
                )
            self.laws[name], self.thresholds[name] = law, float(threshold)
        if not (math.isfinite(rate_walk) and rate_walk >= 0):
            raise InputError(f"rate_walk is a standard deviation per flight >= 0, got {rate_walk!r}")
        self.rate_walk = float(rate_walk)
        self.inputs: list[str] = []
        self.states = [s for name in self.laws for s in (self.level_state(name), f"{name}_rate")]
        self.outputs = [self.level_state(name) for name in self.laws]
        self.events = [f"{name}_failure" for name in self.laws]
        kwargs.setdefault(
            "process_noise", {s: self.rate_walk if s.endswith("_rate") else 0.0 for s in self.states}
        )
        kwargs.setdefault("measurement_noise", 0.0)
        kwargs.setdefault("x0", {s: 0.0 for s in self.states})
        super().__init__(**kwargs)

    def level_state(self, name: str) -> str:
        """The state holding fault `name`'s level: d (linear law) or ln d (exponential)."""
        return f"{name}_log" if self.laws[name] == "exponential" else name

    def _level(self, x: Any, name: str) -> Any:
        v = x[self.level_state(name)]
        return np.exp(v) if self.laws[name] == "exponential" else v

    def next_state(self, x: Any, u: Any, dt: float) -> Any:
        out = {}
        for name in self.laws:
            s = self.level_state(name)
            out[s] = x[s] + x[f"{name}_rate"] * dt  # d or ln d, exact for the law
            out[f"{name}_rate"] = x[f"{name}_rate"]
        return self.StateContainer(out)

    def output(self, x: Any) -> Any:
        return self.OutputContainer({s: x[s] for s in self.outputs})  # d, or ln d (observed in log space)

    def event_state(self, x: Any) -> dict[str, Any]:
        return {
            f"{name}_failure": np.clip(1.0 - self._level(x, name) / self.thresholds[name], 0.0, 1.0)
            for name in self.laws
        }

    def threshold_met(self, x: Any) -> dict[str, Any]:
        return {f"{name}_failure": self._level(x, name) >= self.thresholds[name] for name in self.laws}


def _pooled(
    flights: ArrayLike, values: ArrayLike, sds: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """One (value, sd) per flight: measurements at one flight pooled by their precisions."""
    t, k, sd = (np.atleast_1d(np.asarray(a, dtype=np.float64)) for a in (flights, values, sds))
    ok = np.isfinite(t) & np.isfinite(k) & np.isfinite(sd) & (sd > 0)
    t, k, sd = t[ok], k[ok], np.maximum(sd[ok], MIN_SD)
    uniq = np.unique(t)
    w = 1.0 / sd**2
    kk = np.array([np.sum(w[t == u] * k[t == u]) / np.sum(w[t == u]) for u in uniq])
    ss = np.array([1.0 / math.sqrt(np.sum(w[t == u])) for u in uniq])
    return uniq, kk, ss


def track(
    name: str,
    law: str,
    threshold: float,
    flights: ArrayLike,
    values: ArrayLike,
    sds: ArrayLike,
    *,
    rate_walk: float = 0.0,
) -> tuple[FaultGrowth, Any]:
    """Track one fault with ProgPy's UKF: the model and the filter after the last measurement.

    `values` are distances from healthy at whole-numbered `flights`, each with its
    identification's standard deviation `sds` (a non-finite or non-positive sd: the measurement is
    left out). The exponential law is observed in log space (see the module docstring). The
    filter starts at the first flight from that measurement and a rate prior of `RATE_PRIOR_SD`;
    R is that identification's variance at every update, Q the rate's walk over the gap."""
    t, k, sd = _pooled(flights, values, sds)
    if len(t) < 2:
        raise InputError(f"{name}: a trend needs measurements at two flights at least")
    if not np.all(t == np.round(t)):
        raise InputError(f"{name}: flights are whole numbers, got {t[t != np.round(t)][0]!r}")
    model = FaultGrowth({name: (law, threshold)}, rate_walk=rate_walk)
    level = model.level_state(name)
    z, r = observed(law, k, sd)
    x0 = MultivariateNormalDist(
        [level, f"{name}_rate"], [z[0], 0.0], np.diag([r[0] ** 2, RATE_PRIOR_SD[law] ** 2])
    )
    floor = 1e-12  # keeps the sigma points' Cholesky defined where the state is not noisy
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ProgPy warns about its own internals
        ukf = UnscentedKalmanFilter(model, x0, t0=float(t[0]), alpha=1.0, beta=0.0, kappa=0.0)
        for t_prev, ti, zi, ri in zip(t[:-1], t[1:], z[1:], r[1:], strict=True):
            ukf.filter.Q = np.diag([floor, max(rate_walk**2 * (ti - t_prev), floor)])  # the walk over the gap
            ukf.filter.R = np.array([[ri**2]])  # this identification's variance (fixed otherwise)
            ukf.estimate(float(ti), {}, {level: float(zi)}, dt=float(ti - t_prev))  # one step per gap
    return model, ukf


class UkfTrend(DegradationTrend):
    """One fault's trend as the UKF sees it, for a figure: `trend`'s measurements, and the filter's
    posterior of (level, rate) at its last flight carried back to the law's (φ, θ) at flight 0, so
    that `DegradationTrend`'s ``value`` and ``band`` (what `emaphm.plots.plot_rul` draws) are the
    UKF's."""

    def __init__(self, trend: DegradationTrend, ukf: Any) -> None:
        super().__init__(trend.law, trend.healthy)
        self.t, self.k, self.sd = list(trend.t), list(trend.k), list(trend.sd)
        self._drift = trend._drift  # the side of healthy the measurements lie on (`side`)
        J = np.array([[1.0, -float(ukf.t)], [0.0, 1.0]])  # φ = level − rate·t_last, θ = rate
        x, P = np.asarray(ukf.filter.x, dtype=np.float64), np.asarray(ukf.filter.P, dtype=np.float64)
        self._posterior = (J @ x, J @ P @ J.T)

    def fit(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The UKF's posterior mean and covariance of (φ, θ)."""
        return self._posterior


def _state_draws(ukf: Any, n: int, seed: int, z: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    x, P = np.asarray(ukf.filter.x, dtype=np.float64), np.asarray(ukf.filter.P, dtype=np.float64)
    if z is None:
        z = np.random.default_rng(seed).standard_normal((n, len(x)))
    w, V = np.linalg.eigh((P + P.T) / 2)
    return np.asarray(x + z @ (V * np.sqrt(np.maximum(w, 0.0))).T, dtype=np.float64)


def predict_rul(
    model: FaultGrowth,
    ukf: Any,
    t_now: float | None = None,
    n: int = 4000,
    seed: int = 0,
    z: NDArray[np.float64] | None = None,
) -> RulEstimate:
    """The RUL in flights from `t_now` (default: the filter's last flight) of `track`'s single
    fault: the posterior drawn `n` times, each draw's crossing solved in closed form (a draw whose
    rate does not grow never crosses: inf); 0 where the draw has already crossed."""
    (name,) = model.laws
    t_last = float(ukf.t)
    t_now = t_last if t_now is None else float(t_now)
    draws = _state_draws(ukf, n, seed, z)
    level, rate = draws[:, 0], draws[:, 1]
    g = math.log(model.thresholds[name]) if model.laws[name] == "exponential" else model.thresholds[name]
    toe = crossings(level - rate * t_last, rate, g, t_now)  # the line through (t_last, level)
    return RulEstimate.from_samples(np.maximum(toe - t_now, 0.0), t_now)


def montecarlo_toe(
    model: FaultGrowth, ukf: Any, *, n: int = 100, seed: int = 0, dt: float = 0.1, horizon: float = 1000.0
) -> dict[str, NDArray[np.float64]]:
    """The time of each event (absolute flight) by ProgPy's ``MonteCarlo`` predictor from the
    filter's posterior, `n` draws: the check of `predict_rul`'s closed form. ``t0`` is the
    filter's time (ProgPy starts at 0 otherwise) and a draw that does not fail within `horizon`
    is ``inf`` (ProgPy's ``None``, which its metrics cannot take)."""
    draws = _state_draws(ukf, n, seed)
    state = UnweightedSamples([dict(zip(model.states, row, strict=True)) for row in draws])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = MonteCarlo(model).predict(
            state, lambda t, x=None: model.InputContainer({}), t0=float(ukf.t), dt=dt, horizon=horizon,
            n_samples=n, event_strategy="all", save_freq=1e99,
        )  # fmt: skip
    return {
        event: np.array([NEVER if s[event] is None else float(s[event]) for s in result.time_of_event])
        for event in model.events
    }
