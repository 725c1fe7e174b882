"""Stage 7a: the preconditions of the diagnosis checked at the estimate (issue 34): the motion
here, the current's scale in `current_scale` (`estimate_doubts` runs both).

The monitor, run at the estimate under the recorded command, predicts how the surface moves;
the measured position must agree with it. Two rig mistakes show there and nowhere else as clearly:

- **a command out of step with the motion** (two loggers, one stamped late): the measured motion
  leads or trails the one the command drives, by the loggers' offset τ.
- **a position scale that is not the surface's** (a lever arm, a sensor gain): the measured
  position is a·θ_u of the model's, a ≠ 1.

Both are fitted together: measured(t) ≈ a·θ_u(t − τ), by least squares (`lag_and_scale`).

Either is a reason for the verdict "doubtful" (`errors.Doubt`). Measured with the monitor at the
truth (`python studies/motion_agreement.py`, noise on): on 12 random twin actuators |τ| ≤ 0.38 ms
and |a − 1| ≤ 0.16 %; on 8 drawn within ±2 % tolerances (``--tolerance 0.02 --seed 78``) 0.82 ms
and 0.26 %; a command stamped 5 ms late gives τ = −4.3 to −5.8 ms, positions × 0.9 give a =
0.90. An FOC twin whose current loop two shorts made unstable (docs/theory/hf-model.md §4b) moves
otherwise than its monitor (τ at the 8 ms bound, a = 0.78): a diagnosis the monitor cannot give,
said so. Without a measured position nothing is checked.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import Doubt
from . import limits
from .context import Context
from .current_scale import current_scale, scale_doubts, scale_limit

__all__ = ["estimate_doubts", "lag_and_scale", "motion_doubts"]

LAG_ITERATIONS = 20  # Gauss–Newton steps of `lag_and_scale` (a few suffice within the loop's band)


def lag_and_scale(
    t: NDArray[np.float64], measured: NDArray[np.float64], model: NDArray[np.float64], max_lag: float
) -> tuple[float, float]:
    """(τ [s], a): the least-squares fit measured(t) ≈ a·model(t − τ), τ within ±`max_lag` (τ > 0:
    the measurement trails), by Gauss–Newton from (0, 1) on the samples at least `max_lag` from
    either end; NaN when the model does not move."""
    if not np.ptp(model) > 0:
        return float("nan"), float("nan")
    inner = (t >= t[0] + max_lag) & (t <= t[-1] - max_lag)
    lag, scale = 0.0, 1.0
    for _ in range(LAG_ITERATIONS):
        shifted = np.interp(t - lag, t, model)
        design = np.column_stack([shifted, -scale * np.gradient(shifted, t)])[inner]
        (d_scale, d_lag), *_ = np.linalg.lstsq(design, (measured - scale * shifted)[inner], rcond=None)
        scale, lag = scale + float(d_scale), float(np.clip(lag + d_lag, -max_lag, max_lag))
        if abs(d_lag) < 1e-8:
            break
    return lag, scale


def motion_doubts(
    context: Context, faults: ArrayLike, t: ArrayLike, theta_u: ArrayLike | None
) -> tuple[list[str], dict[str, Any] | None]:
    """The reasons the measured motion gives for "doubtful" (the module docstring) and the record
    {"lag_s", "scale", "lag_max_s", "scale_tolerance"}; ([], None) without a measured position."""
    if theta_u is None:
        return [], None
    run = context.monitor.simulate(faults, duration=context.duration)
    t = np.asarray(t, dtype=np.float64)
    measured = np.interp(run.t, t - t[0], np.asarray(theta_u, dtype=np.float64))
    lag, scale = lag_and_scale(run.t, measured, run.signals["theta_u"], 4 * limits.MOTION_LAG_MAX_S)
    record = {
        "lag_s": None if not np.isfinite(lag) else round(lag, 6),
        "scale": None if not np.isfinite(scale) else round(scale, 5),
        "lag_max_s": limits.MOTION_LAG_MAX_S, "scale_tolerance": limits.POSITION_SCALE_TOLERANCE,
    }  # fmt: skip
    doubts: list[str] = []
    if np.isfinite(lag) and abs(lag) > limits.MOTION_LAG_MAX_S:
        doubts.append(
            Doubt(
                f"the measured surface {'leads' if lag < 0 else 'trails'} the motion the command drives by "
                f"{1000 * abs(lag):.1f} ms (the position loop explains up to {1000 * limits.MOTION_LAG_MAX_S:g} ms): "
                "the command and the other channels are out of step (two loggers? a time stamp offset?)"
            )
        )
    if np.isfinite(scale) and abs(scale - 1.0) > limits.POSITION_SCALE_TOLERANCE:
        doubts.append(
            Doubt(
                f"the measured surface position is {scale:.3f} x the motion the command drives (at most "
                f"{100 * limits.POSITION_SCALE_TOLERANCE:g} % off): a position scale that is not the surface's "
                "(a lever arm, a sensor gain); check the position channels' scale in the channel map"
            )
        )
    return doubts, record


def estimate_doubts(
    context: Context,
    faults: ArrayLike,
    detected: list[str],
    t: ArrayLike,
    theta_u: ArrayLike | None,
    params: Any,
) -> tuple[list[str], dict[str, Any]]:
    """The preconditions checked at the estimate of a fit that explains the recording: the motion
    (`motion_doubts`) and the current's scale (`current_scale.current_scale`, its limit from the
    actuator file `params`); their reasons for "doubtful" and their records {"motion",
    "current_scale"}."""
    doubts, motion = motion_doubts(context, faults, t, theta_u)
    scale = current_scale(context, faults, detected)
    if scale:
        limit, scale["limit_source"] = scale_limit(params)
        scale["limit"] = round(limit, 5)
        doubts += scale_doubts(scale, scale["limit"], scale["limit_source"])
    return doubts, {"motion": motion, "current_scale": scale or None}
