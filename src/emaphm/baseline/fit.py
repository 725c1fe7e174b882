"""The baseline fit: the constants of one actuator from recordings of it when healthy (issue 33).

No actuator matches its nameplate, and the monitor reads what the nameplate does not say as faults:
a magnet flux 2 % low reads as shorts in all three phases, a current sensor 5 % high as friction
and shorts. The baseline fits, with the faults held healthy, scale factors c on what moves the
healthy current, about the nameplate and its calibration:

    g      the current sensor's gain: the measured current is g × the actuator's
    c_kt   k_t,eq   the monitor's torque gain (ψ_m)
    c_ke   k_e,eq   its back-EMF gain (ψ_m)
    c_J    J_eq     the inertia at the motor shaft (J_m + J_u/τ²)
    c_FS   F_S0     static friction, healthy
    c_FD   F_D0     dynamic friction, healthy
    c_KP   K_P0     the position loop's gain as it acts

by least squares on eq. (3)'s residuals over every recording (the identification's comparison,
`identification.context`), each log-factor with a Gaussian prior from the nameplate's tolerance
(`PRIOR_TOLERANCE`; a uniform band ±T has σ = T/√3). The data residuals are whitened by their own
RMS at the start and the filter's correlation length (`CORRELATION_SAMPLES`), so that the
intervals (Laplace, about the optimum) weigh the data against the priors as independent samples
would. k_t,eq, J_eq and the friction scale together leave the current unchanged (the torque
balance J·θ'' = k_t·i − F is the same after multiplying all three), so their priors pin that
direction and their intervals say how little the recordings tell apart. The sensor's gain g is
told from k_t,eq by the position loop (k_t,eq moves the loop's dynamics, g does not): where that
is weak its interval says so. `identify --baseline` divides the measured current by g.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ..calibration import Calibration
from ..constants import CONSTANTS, apply
from ..errors import InputError
from ..faults import HEALTHY
from ..identification.context import Context
from ..identification.signals import CUTOFF_HZ
from ..kernels.monitor import simulate_lf_many
from ..models.lf import monitor_rows
from ..params import EmaParams

__all__ = ["CONSTANTS", "PRIOR_TOLERANCE", "BaselineFit", "apply", "fit_constants", "relative"]

# the constants fitted are `emaphm.constants.CONSTANTS`, in that order. The healthy backlash B0 is not fitted: on a twin drawn within ±2 % (its B0 the nameplate's) the
# fit moved it by +5.6 % (90 % interval 1.6-9.8 %), taking up what the other constants left, and
# every backlash fault is read against it (B = B0·(1 + 99·k2)): alone it took a case from 0.99 to
# 2.63 %err (bench_baseline.py's first actuator of seed 3307)
# the nameplate's tolerance on each (a uniform band ±T): ±10 % on a current sensor's gain, ±2 % on
# the magnet flux (k_t,eq and k_e,eq), the inertias and the friction (issue 33's default), ±5 % on the
# position gain as it acts
PRIOR_TOLERANCE: dict[str, float] = {
    "i_gain": 0.10, "k_t_eq": 0.02, "k_e_eq": 0.02, "J_eq": 0.02, "F_S0": 0.02, "F_D0": 0.02, "K_P0": 0.05,
}  # fmt: skip
# samples over which the 150 Hz-filtered residual stays correlated at 10 kHz: f_s / (2·f_c)
CORRELATION_SAMPLES = 10_000.0 / (2.0 * CUTOFF_HZ)
Z90 = 1.6448536269514722  # the 90 % two-sided normal quantile


@dataclass(frozen=True)
class BaselineFit:
    """The fitted factors, their 90 % intervals (as factors), and each recording's fit.

    factors : dict  constant → fitted factor about the nameplate (1: as the nameplate)
    low, high : dict  constant → the 90 % interval of the factor
    fit_nrmse : list of float  each recording's NRMSE at the fitted constants [-]
    start_nrmse : list of float  the same at the nameplate [-]
    details : dict  the optimiser's record (evaluations, status, cost)
    """

    factors: dict[str, float]
    low: dict[str, float]
    high: dict[str, float]
    fit_nrmse: list[float]
    start_nrmse: list[float]
    details: dict[str, Any] = field(default_factory=dict)


def _rows(params: EmaParams, calibration: Calibration, X: NDArray[np.float64]) -> NDArray[np.float64]:
    """The monitor's parameter rows of healthy runs, one per row of log-factors X."""
    rows = []
    for x in X:
        p, cal = apply(params, calibration, dict(zip(CONSTANTS, np.exp(x), strict=True)))
        rows.append(monitor_rows(np.array([HEALTHY]), p, [cal.coefficients], cal.n_lf, cal.monitor)[0])
    return np.array(rows)


class _Residuals:
    """Whitened residuals of all recordings and the priors, for rows of log-factors (parallel runs)."""

    def __init__(self, contexts: list[Context], params: EmaParams, calibration: Calibration) -> None:
        self.contexts, self.params, self.calibration = contexts, params, calibration
        self.parts = []
        for ctx in contexts:
            keep = np.flatnonzero(ctx.objective.weights > 0)
            _, theta_cmd = ctx.monitor.sample_grid(ctx.duration)
            self.parts.append((ctx, keep, np.sqrt(ctx.objective.weights[keep]), theta_cmd))
        self.scale = [1.0] * len(contexts)  # set from the nameplate's residual RMS (`whiten`)
        self.sigma = np.array([math.log1p(PRIOR_TOLERANCE[c]) / math.sqrt(3.0) for c in CONSTANTS])
        self.evaluations = 0

    def data(self, X: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        """Per recording, the weighted residual rows (one per row of X); NaN rows where a run diverged."""
        rows = _rows(self.params, self.calibration, X)
        out = []
        for ctx, keep, root_w, theta_cmd in self.parts:
            currents = np.empty((len(X), len(theta_cmd)))
            simulate_lf_many(theta_cmd, rows, currents)
            filtered = np.exp(X[:, :1]) * ctx.reference.filtered(currents)  # × the sensor's gain g
            out.append(root_w * (ctx.objective.comparison.reference[keep] - filtered[:, keep]))
        self.evaluations += len(X)
        return out

    def whiten(self) -> list[float]:
        """Set each recording's residual scale from its RMS at the nameplate; the start NRMSEs."""
        start = self.data(np.zeros((1, len(CONSTANTS))))
        self.scale = [float(np.sqrt(np.mean(r[0] ** 2)) * math.sqrt(CORRELATION_SAMPLES)) for r in start]
        return [self.nrmse(ctx, np.zeros(len(CONSTANTS))) for ctx in self.contexts]

    def __call__(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        parts = [r[0] / s for r, s in zip(self.data(x[None, :]), self.scale, strict=True)]
        return np.concatenate([*parts, x / self.sigma])

    def jacobian(self, x: NDArray[np.float64], step: float = 1e-3) -> NDArray[np.float64]:
        """Central differences, all 2·n perturbed runs in one parallel call per recording."""
        n = len(x)
        X = np.vstack([x + step * np.eye(n), x - step * np.eye(n)])
        parts = [r / s for r, s in zip(self.data(X), self.scale, strict=True)]
        stacked = np.concatenate(parts, axis=1)  # (2n, samples)
        J = ((stacked[:n] - stacked[n:]) / (2 * step)).T
        return np.vstack([J, np.diag(1.0 / self.sigma)])

    def nrmse(self, ctx: Context, x: NDArray[np.float64]) -> float:
        from ..identification.signals import nrmse

        rows = _rows(self.params, self.calibration, x[None, :])
        _, theta_cmd = ctx.monitor.sample_grid(ctx.duration)
        current = np.empty((1, len(theta_cmd)))
        simulate_lf_many(theta_cmd, rows, current)
        keep = ctx.mask > 0
        fitted = math.exp(x[0]) * ctx.reference.filtered(current)[0]
        return float(nrmse(ctx.reference.reference[keep], fitted[keep]))


def fit_constants(contexts: list[Context], params: EmaParams, calibration: Calibration) -> BaselineFit:
    """Fit the factors of `CONSTANTS` to the recordings prepared in `contexts` (module docstring)."""
    problem = _Residuals(contexts, params, calibration)
    start_nrmse = problem.whiten()
    if not all(np.isfinite(start_nrmse)):
        raise InputError("the monitor diverges on a recording at the nameplate: check the actuator file")
    result = least_squares(problem, np.zeros(len(CONSTANTS)), jac=problem.jacobian, method="trf", x_scale="jac",
                           max_nfev=60)  # fmt: skip
    J = problem.jacobian(result.x)
    covariance = np.linalg.pinv(J.T @ J)
    half = Z90 * np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    x = result.x
    return BaselineFit(
        factors={c: float(np.exp(v)) for c, v in zip(CONSTANTS, x, strict=True)},
        low={c: float(np.exp(v - h)) for c, v, h in zip(CONSTANTS, x, half, strict=True)},
        high={c: float(np.exp(v + h)) for c, v, h in zip(CONSTANTS, x, half, strict=True)},
        fit_nrmse=[problem.nrmse(ctx, x) for ctx in contexts],
        start_nrmse=start_nrmse,
        details={"evaluations": problem.evaluations, "status": int(result.status), "message": str(result.message),
                 "cost": float(result.cost), "log_covariance": covariance.round(10).tolist()},
    )  # fmt: skip


def relative(fit: BaselineFit, twin: BaselineFit) -> BaselineFit:
    """The actuator's factors against those the same fit finds on its nameplate's twin under the
    same commands: the monitor's own bias on a healthy actuator (what its calibration left, which
    a fit of the constants would otherwise take for the actuator's) cancels; the two fits' 90 %
    half-widths add in quadrature."""
    factors, low, high = {}, {}, {}
    for c in CONSTANTS:
        f = fit.factors[c] / twin.factors[c]
        half = math.hypot(*(math.log(x.high[c] / x.low[c]) / 2 for x in (fit, twin)))
        factors[c], low[c], high[c] = f, f * math.exp(-half), f * math.exp(half)
    covariance = np.asarray(fit.details["log_covariance"]) + np.asarray(twin.details["log_covariance"])
    return BaselineFit(factors, low, high, fit.fit_nrmse, fit.start_nrmse,
                       {**fit.details, "twin": {c: round(twin.factors[c], 6) for c in CONSTANTS},
                        "log_covariance": covariance.round(12).tolist()})  # fmt: skip
