"""What the actuator's constants' uncertainty does to the faults' (issue 33, item 4).

The estimate k̂ is the least-squares fit of eq. (3) with the constants (`emaphm.constants`: the
sensor's gain, k_t,eq, k_e,eq, J_eq, the friction levels, K_P0) at their values; were they off by
δc (log-factors), the model's current would move by J_c·δc and the fit would follow by
δu = −(JᵀJ)⁺Jᵀ·J_c·δc, J the model's Jacobian in the search's coordinates u (`laplace`). With the
constants' covariance Σ_c (a baseline's fit, or the actuator file's tolerances), the faults'
covariance grows by S·Σ_c·Sᵀ, S = (JᵀJ)⁺JᵀJ_c. J_c is taken by central differences: 2·7 runs of
the monitor at k̂ in one parallel call.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ...constants import CONSTANTS, apply
from ...kernels.monitor import simulate_lf_many
from ...models.lf import monitor_rows
from ..limits import PINV_RCOND

if TYPE_CHECKING:
    from ...models import MonitorEma
    from ..fitness import Fitness

__all__ = ["BASELINE_FLOOR", "STEP", "constants_covariance", "shift_covariance"]

STEP = 0.01  # the log-factor step of the central differences (1 %: well above the kernel's rounding)
# a baseline's constants are uncertain to at least this fraction of the tolerances' band: its fit is
# the monitor's, which leaves R_s, L_s, the drive and the integration unfitted. On twins drawn within
# ±2 % (bench_baseline.py, 6 actuators, 30 runs, the packaged interval calibration fitted to the
# widened intervals) the baseline's 90 % intervals held the truth 0.770 of the time with 0.5, 0.867
# with 0.75 and 0.894 with 1 (the nameplate's 0.854): the baseline moves the intervals to where the
# truth is (%err 2.24 -> 1.31 median), it does not yet make them narrower
BASELINE_FLOOR = 1.0


def shift_covariance(
    objective: Fitness,
    monitor: MonitorEma,
    k_hat: NDArray[np.float64],
    J: NDArray[np.float64],
    cov_c: NDArray[np.float64],
    duration: float | None,
) -> NDArray[np.float64]:
    """S·Σ_c·Sᵀ in the search's coordinates u (module docstring); J is ∂model/∂u over the compared samples."""
    keep = objective.weights > 0
    sw = np.sqrt(objective.weights[keep])
    _, theta_cmd = monitor.sample_grid(duration)
    n = len(CONSTANTS)
    rows = []
    for sign in (1.0, -1.0):
        for c in CONSTANTS:
            params, calibration = apply(monitor.params, monitor.calibration, {c: float(np.exp(sign * STEP))})
            rows.append(monitor_rows(k_hat[None, :], params, [calibration.coefficients], calibration.n_lf,
                                     calibration.monitor)[0])  # fmt: skip
    currents = np.empty((len(rows), len(theta_cmd)))
    simulate_lf_many(theta_cmd, np.array(rows), currents)
    model = sw * objective.comparison.filtered(currents)[:, keep]
    Jc = ((model[:n] - model[n:]) / (2.0 * STEP)).T
    gain = CONSTANTS.index("i_gain")  # the sensor's gain scales the measured current itself
    Jc[:, gain] = 0.5 * (model[gain] + model[n + gain])
    if not np.all(np.isfinite(Jc)):
        return np.zeros((J.shape[1], J.shape[1]))
    S = np.linalg.pinv(J.T @ J, rcond=PINV_RCOND) @ (J.T @ Jc)
    return np.asarray(S @ cov_c @ S.T, dtype=np.float64)


def constants_covariance(record: dict | None, params: object) -> tuple[NDArray[np.float64], str]:
    """Σ_c and where it comes from: a baseline's fit (the interval calibration's record
    ``constants.log_covariance``, written by `emaphm.baseline`) with `BASELINE_FLOOR`² × the
    tolerances', else the tolerances of the actuator file `params` (its ``[tolerances]``; an
    `EmaParams` or none: the defaults, `constants.TOLERANCES`)."""
    import os

    from ...constants import load_tolerances, tolerance_covariance

    path = params if isinstance(params, (str, os.PathLike)) else None
    tolerances = tolerance_covariance(load_tolerances(path))
    fitted = ((record or {}).get("constants") or {}).get("log_covariance")
    if fitted is not None:
        floor = BASELINE_FLOOR**2 * tolerances
        return np.asarray(
            fitted, dtype=np.float64
        ) + floor, f"the baseline's fit (+{BASELINE_FLOOR:g} x the tolerances)"
    return tolerances, f"the tolerances of {path or 'the defaults'}"
