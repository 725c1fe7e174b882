"""Phase currents and a rotor angle → i_q, with the angle offset θ0 estimated (next-features §D.3 items 6–7).

On the currents' own grid:

1. **third phase** — the twin's neutral is isolated, so with two phases i_c = −i_a − i_b. With
   three, the zero sequence i_0 = i_a + i_b + i_c is checked: its RMS, low-passed to the
   comparison band (`signals.lowpass`, 150 Hz, so white ADC noise does not count), must stay below
   `ZERO_SEQUENCE_MAX` of the phase RMS; otherwise a warning, and i_0/3 is removed from each
   phase (an offset or a neutral path the twin does not have). The amplitude-invariant Clarke
   transform ignores the zero sequence anyway; the removal makes the stored phases consistent.
2. **Clarke, Park** — `kernels.transforms.clarke` and `park` (DESIGN §3.9), amplitude invariant::

       i_alpha = (2/3)·(i_a − i_b/2 − i_c/2),  i_beta = (i_b − i_c)/√3
       i_d = i_alpha·cos θ + i_beta·sin θ,      i_q = −i_alpha·sin θ + i_beta·cos θ,  θ = θ_e + θ0

3. **θ0** — the controller holds i_d = 0 (DESIGN §3.3), so θ0 minimises J(θ0) = mean(i_d²).
   With (u, v) the Park components at θ0 = 0, J = A·cos²θ0 + B·sin²θ0 + 2C·sinθ0·cosθ0
   (A = mean u², B = mean v², C = mean uv): evaluated on a 1° grid, then refined by a bounded
   scalar search (`scipy.optimize.minimize_scalar`) within ±1° of the best grid point. J has
   period π: θ0 and θ0 + π fit equally, with opposite signs of i_q.
4. **sign** — the twin's convention: positive i_q gives positive motor torque. The torque the
   motion needs is estimated from the measured angle itself, θ_m = θ_e/p low-passed to 150 Hz:
   T̂ = J·θ̈_m + C·θ̇_m + F_D0·sign(θ̇_m) (DESIGN §3.8, `params.transmission`, motor side); θ0 + π is taken
   when the low-passed i_q correlates negatively with T̂. Checked on the HF twin for every
   single fault: correlation 0.87–0.99 (the command's acceleration is no proxy: the position
   loop lags the chirp so much that i_q correlates *negatively* with J·τ·θ̈_cmd).
5. **fit check** — the residual mean(i_d²)/mean(i_d² + i_q²) must stay below
   `ALIGNMENT_RESIDUAL_MAX`; a larger one means the angle does not follow the current vector
   (wrong pole pairs, an angle counting the other way, or not the rotor angle): `InputError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize_scalar

from ..errors import Doubt, InputError
from ..identification.signals import lowpass
from ..kernels.transforms import clarke, park
from ..params import EmaParams
from .limits import ALIGNMENT_RESIDUAL_MAX, OFFSET_DISAGREE_DEG, ZERO_SEQUENCE_MAX

__all__ = ["Alignment", "estimate_offset", "phases_to_iq", "torque_proxy"]

_WEAK_CORRELATION = 0.2  # below this the sign of i_q is reported as uncertain


@dataclass(frozen=True)
class Alignment:
    """i_q on the currents' grid and how it was obtained.

    i_q : ndarray  quadrature current [A]
    phases : tuple of 3 ndarrays  i_a, i_b, i_c after the zero-sequence treatment [A]
    theta_e : ndarray  the electrical angle with θ0 added [rad] (unwrapped)
    theta0 : float  the offset added to the angle [rad], in [0, 2π)
    report : dict  JSON-ready figures (offset in degrees, method, residual, correlation, phases)
    warnings : list of str
    """

    i_q: NDArray[np.float64]
    phases: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    theta_e: NDArray[np.float64]
    theta0: float
    report: dict[str, Any]
    warnings: list[str] = field(default_factory=list)


def estimate_offset(
    i_alpha: NDArray[np.float64], i_beta: NDArray[np.float64], theta_e: NDArray[np.float64]
) -> tuple[float, float]:
    """θ0 in [0, π) minimising mean(i_d²) at θ_e + θ0, and that minimum over mean(i_d² + i_q²).

    1° grid, then a bounded scalar refinement (module docstring, item 3).
    """
    u, v = park(i_alpha, i_beta, theta_e)
    A, B, C = float(np.mean(u * u)), float(np.mean(v * v)), float(np.mean(u * v))

    def J(theta0: float) -> float:
        c, s = math.cos(theta0), math.sin(theta0)
        return A * c * c + B * s * s + 2.0 * C * s * c

    grid = np.deg2rad(np.arange(180.0))
    values = A * np.cos(grid) ** 2 + B * np.sin(grid) ** 2 + 2.0 * C * np.sin(grid) * np.cos(grid)
    best = float(grid[int(np.argmin(values))])
    step = math.radians(1.0)
    res = minimize_scalar(J, bounds=(best - step, best + step), method="bounded", options={"xatol": 1e-9})
    theta0 = float(res.x) % math.pi
    total = A + B
    return theta0, (J(theta0) / total if total > 0 else 1.0)


def torque_proxy(
    theta_e: NDArray[np.float64], t: NDArray[np.float64], f_s: float, params: EmaParams
) -> NDArray[np.float64]:
    """T̂ = J·θ̈_m + C·θ̇_m + F_D0·sign(θ̇_m) [N·m] from θ_m = θ_e/p, low-passed to 150 Hz."""
    tr = params.transmission
    theta_m = lowpass(theta_e / params.motor.p, f_s)
    omega = np.gradient(theta_m, t)
    alpha = np.gradient(omega, t)
    return tr.J * alpha + tr.C * omega + tr.F_D0 * np.sign(omega)  # type: ignore[no-any-return]


def _rms(x: NDArray[np.float64]) -> float:
    return float(np.sqrt(np.mean(x * x)))


def _zero_sequence(
    i_a: NDArray[np.float64],
    i_b: NDArray[np.float64],
    i_c: NDArray[np.float64],
    f_s: float,
    report: dict[str, Any],
    warnings: list[str],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Three measured phases with the zero sequence removed when it exceeds `ZERO_SEQUENCE_MAX`
    of the phase RMS in the comparison band (recorded in `report`, warned in `warnings`)."""
    i_0 = i_a + i_b + i_c
    phase_rms = (_rms(i_a) + _rms(i_b) + _rms(i_c)) / 3.0
    ratio = _rms(lowpass(i_0, f_s)) / phase_rms if phase_rms > 0 else 0.0
    report["zero_sequence_ratio"] = ratio
    report["zero_sequence_removed"] = bool(ratio > ZERO_SEQUENCE_MAX)
    if ratio > ZERO_SEQUENCE_MAX:
        warnings.append(
            f"i_a + i_b + i_c has {100 * ratio:.1f} % of the phase RMS in the comparison band "
            f"(more than {100 * ZERO_SEQUENCE_MAX:g} %): a current-sensor offset or a neutral path; "
            "the zero sequence was removed"
        )
        i_a, i_b, i_c = i_a - i_0 / 3.0, i_b - i_0 / 3.0, i_c - i_0 / 3.0
    return i_a, i_b, i_c


def _questioned(given: float, estimated: float, params: EmaParams, report: dict[str, Any]) -> list[str]:
    """A warning when the map's offset and the one the currents show differ by more than
    `OFFSET_DISAGREE_DEG` (mod 180°: i_d² cannot tell the two), with the likely slip: mechanical
    degrees written for electrical ones (the given value × p matches), or a wrong offset."""

    def apart(a: float, b: float) -> float:
        return abs((math.degrees(a - b) + 90.0) % 180.0 - 90.0)

    report["offset_estimate_deg"] = math.degrees(estimated)
    if apart(given, estimated) <= OFFSET_DISAGREE_DEG:
        return []
    p = params.motor.p
    hint = (
        f'it reads as mechanical degrees ({math.degrees(given):.1f} x {p} pole pairs matches): write [angle] kind = "mechanical"'
        if apart(given * p, estimated) <= OFFSET_DISAGREE_DEG
        else 'check it, or let emaphm estimate it (offset = "estimate")'
    )
    return [
        Doubt(
            f"the channel map's angle offset {math.degrees(given):.1f} deg (electrical) differs by "
            f"{apart(given, estimated):.1f} deg from the one the currents show ({math.degrees(estimated) % 180:.1f} deg, "
            f"mod 180): {hint}; the given one is used"
        )
    ]


def phases_to_iq(
    t: NDArray[np.float64],
    i_a: NDArray[np.float64],
    i_b: NDArray[np.float64],
    i_c: NDArray[np.float64] | None,
    theta_e: NDArray[np.float64],
    params: EmaParams,
    *,
    offset: float | None = None,
) -> Alignment:
    """i_q from the phase currents and the (unwrapped) electrical angle, all on the grid t [s].

    Parameters
    ----------
    t : ndarray  sample times of the currents [s] (uniform to within jitter)
    i_a, i_b, i_c : ndarray  phase currents [A]; i_c None for two measured phases
    theta_e : ndarray  electrical angle at t [rad], unwrapped, without offset
    params : EmaParams  the actuator (pole pairs, transmission for the sign proxy)
    offset : float or None  θ0 [rad] to use; None estimates it

    Returns
    -------
    Alignment
    """
    f_s = float(1.0 / np.median(np.diff(t)))
    warnings: list[str] = []
    report: dict[str, Any] = {"phases_measured": 2 if i_c is None else 3}
    if i_c is None:
        i_c = -i_a - i_b  # isolated neutral (DESIGN §3.4)
        report["i_c"] = "reconstructed as -i_a - i_b"
    else:
        report["i_c"] = "measured"
        i_a, i_b, i_c = _zero_sequence(i_a, i_b, i_c, f_s, report, warnings)
    i_alpha, i_beta = clarke(i_a, i_b, i_c)
    if offset is None:
        theta0, residual = estimate_offset(i_alpha, i_beta, theta_e)
        report["offset_method"] = "estimated: min mean(i_d^2), 1 deg grid + bounded refinement"
    else:
        theta0 = float(offset) % (2.0 * math.pi)
        report["offset_method"] = "given in the channel map"
        warnings += _questioned(theta0, estimate_offset(i_alpha, i_beta, theta_e)[0], params, report)
    i_d, i_q = park(i_alpha, i_beta, theta_e + theta0)
    total = float(np.mean(i_d * i_d + i_q * i_q))
    residual = float(np.mean(i_d * i_d)) / total if total > 0 else 1.0
    report["alignment_residual"] = residual
    if residual > ALIGNMENT_RESIDUAL_MAX:
        hint = (
            "check angle.offset"
            if offset is not None
            else "wrong pole pairs p, an angle counting the other way (scale = -1), phases in another order "
            "(i_a and i_b swapped), or not the rotor angle"
        )
        raise InputError(
            f"the angle does not follow the current vector: mean(i_d^2) is {100 * residual:.0f} % of the "
            f"current's power at the best offset (at most {100 * ALIGNMENT_RESIDUAL_MAX:g} %): {hint}"
        )
    proxy = torque_proxy(theta_e, t, f_s, params)
    i_q_band = lowpass(i_q, f_s)
    correlation = (
        float(np.corrcoef(i_q_band, proxy)[0, 1]) if np.std(proxy) > 0 and np.std(i_q_band) > 0 else 0.0
    )
    flipped = False
    if offset is None and correlation < 0:
        theta0, i_q, correlation, flipped = (theta0 + math.pi) % (2 * math.pi), -i_q, -correlation, True
    elif offset is not None and correlation < 0:
        warnings.append(
            Doubt(
                f"with the given angle.offset, i_q opposes the torque the motion needs (correlation {correlation:.2f}): "
                "is the offset 180 deg off?"
            )
        )
    if abs(correlation) < _WEAK_CORRELATION:
        warnings.append(
            Doubt(
                f"the sign of i_q is uncertain: its correlation with the torque the motion needs is {correlation:.2f}"
            )
        )
    report.update(offset_deg=math.degrees(theta0), pi_added=flipped, torque_correlation=correlation)
    return Alignment(i_q, (i_a, i_b, i_c), theta_e + theta0, theta0, report, warnings)
