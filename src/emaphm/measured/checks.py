"""Plausibility checks of measured signals (next-features §D.3): the usual mistakes, caught early.

Each check returns a one-line problem with the likely cause, or nothing:

- **outlier**: a sample more than `OUTLIER_FACTOR` robust spreads (1st–99th percentile range)
  from the median, named by its row (a corrupt sample, e.g. 1e30);
- **current range**: |i| above `CURRENT_FACTOR` × I_max on more than `FEW_SAMPLES` samples ("is
  the current in mA?");
- **position range**: |θ| above `POSITION_FACTOR` × theta_max ("is it in degrees?");
- **constant current**: 98 % of the samples equal (an unconnected channel);
- **span**: longer than `MAX_SPAN` ("is the time axis in seconds?") or shorter than `MIN_DURATION`;
- **angle ratio**: the rotor angle must turn p·τ times the surface angle (τ for θ_m); the ratio of
  standard deviations is compared within `ANGLE_RATIO_TOLERANCE` (θ_u) or
  `ANGLE_RATIO_TOLERANCE_CMD` (θ_cmd, which the position loop tracks with lag). A ratio near 1
  means the surface angle was mapped as the rotor angle.

`plausibility` runs them on any trace in SI (native emaphm traces included); `to_reference` runs
them on each channel of a measurement before resampling.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..params import EmaParams
from ..results import SimResult
from .limits import (
    ANGLE_RATIO_TOLERANCE,
    ANGLE_RATIO_TOLERANCE_CMD,
    CURRENT_FACTOR,
    FEW_SAMPLES,
    MAX_SPAN,
    MIN_DURATION,
    OUTLIER_FACTOR,
    POSITION_FACTOR,
    SPREAD_FLOOR,
)

__all__ = ["CURRENTS", "POSITIONS", "angle_ratio", "plausibility", "span_problems", "value_problems"]

CURRENTS = ("i_q", "i_a", "i_b", "i_c")
POSITIONS = ("theta_cmd", "theta_u")
_STILL = 1e-4  # [rad] a reference angle moving less than this (std) cannot check the rotor angle


def _sample(i: int) -> str:
    return f"sample {i}"


def value_problems(
    role: str,
    x: NDArray[np.float64],
    params: EmaParams,
    *,
    label: str | None = None,
    row: Callable[[int], str] = _sample,
) -> list[str]:
    """Outlier, range and constant-value problems of one signal in SI (NaN samples ignored)."""
    label = label or role
    finite = np.flatnonzero(np.isfinite(x))
    if len(finite) == 0:
        return [f"{label} holds no finite sample"]
    v = x[finite]
    med = float(np.median(v))
    lo, hi = (float(q) for q in np.percentile(v, [1.0, 99.0]))
    spread = hi - lo
    # the spread, but never below 1 % of the channel's physical range: a recording that mostly
    # rests (a long hold) has a percentile spread of sensor noise, against which its own motion
    # would look corrupt
    floor = (
        SPREAD_FLOOR * params.controller.I_max
        if role in CURRENTS
        else SPREAD_FLOOR * params.transmission.theta_max
        if role in POSITIONS
        else 0.0
    )
    scale = max(spread, floor)
    if scale > 0:
        far = np.abs(v - med) > OUTLIER_FACTOR * scale
        if far.any():
            k = int(np.argmax(np.abs(v - med)))
            return [
                f"{label}: {v[k]:.3g} at {row(int(finite[k]))} lies {abs(v[k] - med) / scale:.3g} times the "
                f"signal's spread from its median ({int(far.sum())} such sample(s)): a corrupt sample? "
                "remove it or set it to NaN"
            ]
    problems = []
    if role in CURRENTS:
        limit = CURRENT_FACTOR * params.controller.I_max
        over = int(np.count_nonzero(np.abs(v) > limit))
        if over > FEW_SAMPLES:
            problems.append(
                f"{label} exceeds {CURRENT_FACTOR:g} × I_max = {limit:g} A on {over} samples (up to "
                f"{np.max(np.abs(v)):.3g} A): is the current in mA? check its unit"
            )
        if spread == 0:
            problems.append(
                f"{label} is constant ({med:g} A on 98 % of the samples): an unconnected or wrong channel?"
            )
    if role in POSITIONS:
        limit = POSITION_FACTOR * params.transmission.theta_max
        over = int(np.count_nonzero(np.abs(v) > limit))
        if over > FEW_SAMPLES:
            problems.append(
                f"{label} reaches {np.max(np.abs(v)):.3g} rad, beyond {POSITION_FACTOR:g} × theta_max = {limit:g} rad "
                f"on {over} samples: is it in degrees? check its unit"
            )
    return problems


def span_problems(span: float, what: str = "the record") -> list[str]:
    """The record's length [s]: too long for seconds, or too short to identify on."""
    if span > MAX_SPAN:
        return [
            f"{what} spans {span:.6g} s (more than {MAX_SPAN:g} s): is the time axis in seconds? "
            "check the time unit"
        ]
    if span < MIN_DURATION:
        return [f"{what} lasts {span:.3g} s; at least {MIN_DURATION:g} s are needed"]
    return []


def angle_ratio(
    angle_role: str,
    angle: NDArray[np.float64],
    ref_role: str,
    ref: NDArray[np.float64],
    params: EmaParams,
) -> tuple[str | None, dict[str, Any]]:
    """Does the rotor angle turn p·τ (θ_e) or τ (θ_m) times the surface angle? Both on one grid.

    Returns the problem (or None) and the figures for the report.
    """
    p, tau = params.motor.p, params.transmission.tau
    expected, name = (p * tau, "p·tau") if angle_role == "theta_e" else (tau, "tau")
    info: dict[str, Any] = {"against": ref_role, "expected": expected}
    ok = np.isfinite(angle) & np.isfinite(ref)
    a, r = angle[ok], ref[ok]
    if len(a) < 3 or np.std(r) < _STILL:
        info["checked"] = False
        return None, info
    ratio = float(np.std(a) / np.std(r))
    corr = float(np.corrcoef(a, r)[0, 1]) if np.std(a) > 0 else 0.0
    info.update(checked=True, ratio=ratio / expected, correlation=corr)
    tolerance = ANGLE_RATIO_TOLERANCE if ref_role == "theta_u" else ANGLE_RATIO_TOLERANCE_CMD
    which = "the surface angle" if ref_role == "theta_u" else "the position demand"
    if not (expected / tolerance <= ratio <= expected * tolerance):
        hint = (
            "is it the surface angle?"
            if ratio < expected / 20
            else f"check the pole pairs p = {p}, the gear ratio tau = {tau:g}, and the units of {angle_role} and {ref_role}"
        )
        return f"{angle_role} turns {ratio:.3g}× {which}, expected {name} = {expected:g}: {hint}", info
    if ref_role == "theta_u" and corr < -0.5:
        return (
            f"{angle_role} turns against the surface angle (correlation {corr:.2f}): set scale = -1 on "
            f"{angle_role} (or on theta_u and theta_cmd if the surface angle is the one reversed)",
            info,
        )
    return None, info


def plausibility(trace: SimResult, params: EmaParams | None = None) -> list[str]:
    """Problems found on a trace in SI on any grid (an empty list: nothing implausible).

    Checks the span, each current (outliers, |i| vs I_max, constant) and position (outliers,
    |θ| vs theta_max) the trace holds, and, with ``theta_e``, that the rotor angle turns p·τ
    times ``theta_u`` (or ``theta_cmd``). See the module docstring for the thresholds.

    Parameters
    ----------
    trace : SimResult
        The trace, in SI.
    params : EmaParams, optional
        The actuator whose I_max and theta_max bound the signals (default: the nominal one).
    """
    params = params if params is not None else EmaParams()
    t = np.asarray(trace.t, dtype=np.float64)
    problems = span_problems(float(t[-1] - t[0])) if len(t) > 1 else ["the trace has fewer than 2 samples"]

    def row(i: int) -> str:
        return f"sample {i} (t = {t[i]:.6g} s)"

    for role in (*CURRENTS, *POSITIONS):
        if role in trace.names:
            problems += value_problems(role, np.asarray(trace[role], dtype=np.float64), params, row=row)
    if "theta_e" in trace.names:
        ref_role = "theta_u" if "theta_u" in trace.names else "theta_cmd"
        if ref_role in trace.names:
            theta_e = np.unwrap(np.asarray(trace["theta_e"], dtype=np.float64))
            problem, _ = angle_ratio("theta_e", theta_e, ref_role, np.asarray(trace[ref_role]), params)
            if problem:
                problems.append(problem)
    return problems
