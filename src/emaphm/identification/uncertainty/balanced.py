"""A magnet flux below its nameplate reads as a short in every phase (issue 34, item 2).

The monitor's current needs k_t,eq ∝ ψ_m: an actuator whose ψ_m is δ below the nameplate draws
δ more current for the same torque, and the monitor, whose ψ_m is the nameplate's, explains that
by shorting turns in all three phases (a short of n turns weakens that phase's flux by n).
Measured (`python studies/psi_m_as_shorts.py`, `studies/psi_m_profile.py`): a healthy twin with
ψ_m −2 % reads shorts 0.025 / 0.008 / 0.021, one with ψ_m −1.6 % (and R_s +1.7 %) 0.032 / 0.023 /
0.030, with short A "present" and verdict "fits"; a true balanced short of 0.02 reads 0.021 /
0.013 / 0.026. Refitting with monitors whose ψ_m is 0.97–1.02 × the nameplate's moves the
shorts by about 1.5 × the flux's change while the fit's NRMSE stays within its search noise
(1.46–1.60 % on the −1.6 % twin): the recording does not hold ψ_m. A baseline does: it fits
k_t,eq and k_e,eq on the healthy actuator (`emaphm baseline`). Without one, the linearised
widening of the constants (`constants.shift_covariance`) gives the shorts only about one phase's
share of it (σ 0.002 / 0.012 / 0.027 on the −1.6 % twin).

So, without a baseline and with a ψ_m tolerance T (the actuator file's ``[tolerances] psi_m``,
±2 % by default), each short may hold a balanced part of up to the `allowance`
β = `SLOPE` · `BAND` · T (0.024 by default; `BAND`: ψ_m is more than 0.8 T below its nameplate
with probability 0.1 in the uniform band). Where every short reads at least `CONSISTENT` (the
estimate is what a lower ψ_m gives; one phase near 0 rules that out), `widen` takes
min(k̂_i, β) off each short's lower 90 % end, so that a short whose presence rests on that part is
"cannot tell", not "present". A flux above its nameplate reads every short lower by as much (the
independent simulator: ψ_m +1.7 % took 0.08 off the three shorts' sum, ../shared/notes/off-twin.md),
so `widen` raises every short's upper end by β too. On 24 runs drawn within ±2 % (bench_foc.py
--tolerance 0.02 --case-seed 3307) the shorts' intervals that still missed after the lower ends
came down all missed above, on actuators with ψ_m up to 2 % high. A result whose three shorts are
all within 2β and one of which that part alone kept from "present" (`doubts`) is "doubtful": all
it found in the windings may be the magnet's.
"""

from __future__ import annotations

import os
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ...errors import Doubt
from ...faults import FAULT_NAMES, SHORTS

if TYPE_CHECKING:
    from .intervals import Uncertainty

__all__ = ["BAND", "CONSISTENT", "SLOPE", "allowance", "allowed", "discounted", "doubts", "widen"]

SLOPE = 1.5  # the balanced short per relative change of ψ_m (the module docstring: 1.25-2 measured)
BAND = 0.8  # the one-sided 90 % point of a uniform band ±T, in units of T
CONSISTENT = 0.004  # every short reads at least this when ψ_m is low by 1 % (short B reads least)


def allowance(params: Any, baseline: bool) -> tuple[float, str]:
    """β: how much of each short a ψ_m within the actuator file `params`' tolerance (an
    `EmaParams` or none: the defaults) may explain, and where it comes from; 0 with a `baseline`,
    which fits the flux."""
    if baseline:
        return 0.0, "the baseline's fitted k_t,eq and k_e,eq"
    from ...constants import load_tolerances

    path = params if isinstance(params, (str, os.PathLike)) else None
    t = load_tolerances(path)["psi_m"]
    return SLOPE * BAND * t, f"psi_m ±{100 * t:g} % ({f'the tolerances of {path}' if path else 'the default tolerances'})"


def _parts(K: ArrayLike, beta: float) -> np.ndarray:
    """min(k̂_i, β) per short of each row of `K` (m, 8), (m, 3); a row's 0 where its shorts are not
    what a lower ψ_m gives (one below `CONSISTENT`), and all 0 with β = 0."""
    shorts = np.array(K, dtype=np.float64, ndmin=2)[:, list(SHORTS)]
    consistent = np.all(shorts >= CONSISTENT, axis=1, keepdims=True)
    return np.where(consistent & (beta > 0), np.minimum(shorts, beta), 0.0)  # type: ignore[no-any-return]


def discounted(k_hat: ArrayLike, beta: float) -> np.ndarray:
    """k̂ with each short's balanced part taken off: what the point rule (`detection.detect`)
    judges without intervals."""
    k = np.array(k_hat, dtype=np.float64, copy=True)
    k[list(SHORTS)] -= _parts(k, beta)[0]
    return k


def allowed(
    K: ArrayLike, low: ArrayLike, high: ArrayLike, beta: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 90 % ends of rows of estimates `K` (m, 8) with the allowance β (the module docstring):
    (low, high, part), part the balanced part taken off each short's lower end (`_parts`). What
    `widen` and the interval calibration's fit (`factors.fit_factors`) apply alike."""
    lo, hi = (np.array(a, dtype=np.float64, ndmin=2, copy=True) for a in (low, high))
    rows = list(SHORTS)
    part = _parts(K, beta)
    if beta > 0:
        hi[:, rows] = np.minimum(hi[:, rows] + beta, 1.0)
        lo[:, rows] = np.maximum(lo[:, rows] - part, 0.0)
    return lo, hi, part


def widen(interval: Uncertainty, k_hat: ArrayLike, beta: float, source: str) -> Uncertainty:
    """`interval` with each short's upper 90 % end raised by β (a flux above its nameplate reads
    every short lower, one at 0 hiding below the bound) and, where every short reads at least
    `CONSISTENT`, its lower end lowered by its balanced part min(k̂, β) (`allowed`); recorded in
    ``details["balanced_allowance"]``. Unchanged with β = 0 (a baseline)."""
    record: dict[str, Any] = {"beta": round(beta, 5), "source": source, "lowered_by": None, "low_before": None}
    if not beta > 0:
        return replace(interval, details={**interval.details, "balanced_allowance": record})
    lo, hi, part = allowed(k_hat, interval.ci90_low, interval.ci90_high, beta)
    if np.any(part > 0):
        record["low_before"] = [round(float(interval.ci90_low[i]), 5) for i in SHORTS]
        record["lowered_by"] = [round(float(v), 5) for v in part[0]]
    return replace(interval, ci90_low=lo[0], ci90_high=hi[0], details={**interval.details, "balanced_allowance": record})


def doubts(
    k_hat: ArrayLike, beta: float, source: str, thresholds: dict[str, float] | None, interval: Uncertainty | None
) -> list[str]:
    """The reason for "doubtful" a balanced part gives: every short within 2β and one that its
    balanced part alone kept from "present" (`interval`'s lower end before `widen` beyond its
    detection threshold; without intervals, its estimate: the point rule's), for `thresholds`
    (None: the shipped ones). Else nothing found rests on it, and the result is not doubted."""
    shorts = np.asarray(k_hat, dtype=np.float64)[list(SHORTS)]
    if not np.any(_parts(k_hat, beta) > 0) or not np.all(shorts <= 2.0 * beta):
        return []
    if thresholds is None:
        from ..detection import load_thresholds

        thresholds = load_thresholds()["thresholds"]
    record = (interval.details.get("balanced_allowance") or {}) if interval is not None else {}
    judged = shorts if interval is None else np.asarray(record.get("low_before") or np.zeros(3), dtype=np.float64)
    if not any(v > thresholds.get(FAULT_NAMES[i], np.inf) for i, v in zip(SHORTS, judged, strict=True)):
        return []
    return [
        Doubt(
            f"every phase reads a small short ({', '.join(f'{v:.3f}' for v in shorts)}), as a magnet flux up to "
            f"{100 * beta / SLOPE:.1f} % below its nameplate would ({source}): without a baseline the two cannot "
            "be told apart; record one when the actuator is healthy ('emaphm baseline')"
        )
    ]
