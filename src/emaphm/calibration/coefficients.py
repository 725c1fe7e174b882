"""The coefficients of the LF monitor model and the box the calibration searches them in.

The coefficients are those of the paper §4.2 (DESIGN §4.4): the shape-function coefficients
k_FS, k_E (k_FT follows from them, see `Coefficients.k_FT`), the equivalent torque and back-EMF
gains k_t,eq and k_e,eq, plus the inertia J_eq the LF model sees and the time constant τ_i of its
simplified current loop, and the loop-error surrogate of the default monitor (`SURROGATE`).
`emaphm calibrate` fits them with a GA against the HF twin (`emaphm.calibration.fit_monitor`)
within `coefficient_bounds(params)`; `emaphm.calibration.files` stores them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import InputError
from ..params import EmaParams

__all__ = [
    "ACTUATOR_SCALED",
    "BAND_SCALED",
    "COEFFICIENT_BOUNDS",
    "NAMEPLATE_SCALED",
    "SURROGATE",
    "Coefficients",
    "checked_free",
    "coefficient_bounds",
]

# GA search bounds of each calibrated coefficient (SI)
COEFFICIENT_BOUNDS: dict[str, tuple[float, float]] = {
    "k_FS": (0.0, 100.0),  # [-]
    "k_E": (0.0, 3.0),  # [-]
    "k_t_eq": (0.10, 0.20),  # [N·m/A]
    "k_e_eq": (0.05, 0.20),  # [V·s/rad]
    "J_eq": (4.0e-5, 6.5e-5),  # [kg·m²]
    "tau_i": (1e-6, 3e-4),  # [s]
    "k_H": (-0.1, 0.1),  # [-]
    "delta_0": (0.0, 0.02),  # [A]
    "delta_1": (0.0, 0.1),  # [A]
    "delta_u": (-0.05, 0.1),  # [A]
    "delta_2": (-0.05, 0.05),  # [A]
    "V_H": (1e-4, 0.05),  # [V]
    # [A]; the q current's ripple peak cannot exceed the hysteresis band's width h (0.1 A here):
    # scaled with the actuator's h (`coefficient_bounds`)
    "i_R": (0.0, 0.1),
    # [A]; the half-band of the loop's dead zone at standstill: h/2 in the twin's comparators, up
    # to h for what the monitor's averaged loop needs; scaled with the actuator's h too
    "i_D": (0.0, 0.1),
}


@dataclass(frozen=True)
class Coefficients:
    """Equivalent single-phase motor and shape-function coefficients.

    The defaults are the first guess before calibration: nameplate gains (k_t,eq = 1.5·p·ψ_m,
    k_e,eq = p·ψ_m, J_eq = J_m + J_u/τ²), unit shape coefficients, a one-sample current lag and
    no current-loop surrogate error.

    k_FS : float  single-phase contribution of the short-circuit shape function [-]
    k_E : float  eccentricity calibration coefficient [-]
    k_t_eq : float  equivalent torque gain (healthy, φ_T = 1) [N·m/A]
    k_e_eq : float  equivalent back-EMF coefficient (healthy) [V·s/rad]
    J_eq : float  inertia at the motor shaft seen by the LF model [kg·m²]
    tau_i : float  time constant of the simplified current loop [s]
    k_H : float  2θ_e ripple of the loop's current per unit of lost turns [-]
    delta_0 : float  loop offset of the measured current, healthy [A]
    delta_1 : float  growth of that offset per unit of lost turns Σ(1 − N_x) [A]
    delta_u : float  growth of that offset with the unbalance of the lost turns |U| (kernels.monitor.unbalance) [A]
    delta_2 : float  part of that offset in step with the shorted phases' 2θ_e pattern c₂ [A]
    V_H : float  q-axis voltage (R_eq·i + k_e,eq·ω_m) over which the offset reverses its sign [V]
    i_R : float  peak of the loop's current ripple about i_m that breaks a stuck motor away [A]
    i_D : float  half-band of the loop's dead zone at standstill (kernels.monitor.standstill_dead_zone) [A]
    """

    k_FS: float = 1.0
    k_E: float = 1.0
    k_t_eq: float = 0.15
    k_e_eq: float = 0.10
    J_eq: float = 5.125e-5
    tau_i: float = 1e-4
    k_H: float = 0.0
    delta_0: float = 0.0
    delta_1: float = 0.0
    delta_u: float = 0.0
    delta_2: float = 0.0
    V_H: float = 0.01
    i_R: float = 0.0
    i_D: float = 0.0

    def __post_init__(self) -> None:
        # the nameplate-scaled coefficients, i_R and i_D are checked against their actuator's box by
        # `check_bounds`; here only that they are positive (i_R, i_D: not negative)
        for name, (lo, hi) in COEFFICIENT_BOUNDS.items():
            v = getattr(self, name)
            if name in ACTUATOR_SCALED:
                lo, hi = 0.0, math.inf
                ok = (
                    isinstance(v, (int, float))
                    and math.isfinite(v)
                    and (v > 0 or (name in BAND_SCALED and v == 0))
                )
            else:
                ok = isinstance(v, (int, float)) and math.isfinite(v) and lo <= v <= hi
            if not ok:
                raise InputError(
                    f"calibration coefficient {name}={v!r} is outside its range [{lo:g}, {hi:g}]"
                )

    @classmethod
    def first_guess(cls, params: EmaParams | None = None) -> Coefficients:
        """The coefficients before calibration for an actuator: the defaults with its nameplate k_t, k_e, J."""
        nominal, ratio = cls(), _nameplate_ratios(params)
        return cls(**{name: getattr(nominal, name) * r for name, r in ratio.items()})

    def check_bounds(self, params: EmaParams | None = None, *, where: str = "calibration") -> None:
        """`InputError` unless every coefficient lies in `coefficient_bounds(params)`."""
        for name, (lo, hi) in coefficient_bounds(params).items():
            v = getattr(self, name)
            if not lo <= v <= hi:
                raise InputError(
                    f"{where}: coefficient {name}={v!r} is outside its range [{lo:.4g}, {hi:.4g}]"
                    + (" for these actuator parameters" if name in ACTUATOR_SCALED else "")
                )

    @property
    def k_FT(self) -> float:
        """Global short-circuit coefficient, k_FT = 1/(3 + 1.5·k_FS) so that a healthy φ_SC = 1.

        k_FT multiplies k_t,eq and k_e,eq everywhere it appears, so the GA would only see their
        products; fixing φ_SC(healthy) = 1 removes that degenerate direction and makes k_t,eq
        the healthy torque constant.
        """
        return 1.0 / (3.0 + 1.5 * self.k_FS)

    def as_vector(self) -> list[float]:
        return [float(getattr(self, n)) for n in COEFFICIENT_BOUNDS]

    @classmethod
    def from_vector(cls, x: Any) -> Coefficients:
        return cls(**{n: float(v) for n, v in zip(COEFFICIENT_BOUNDS, x, strict=True)})


# the coefficients whose search box scales with the actuator's nameplate value (k_t = 1.5·p·ψ_m,
# k_e = p·ψ_m, J = J_m + J_u/τ²): COEFFICIENT_BOUNDS holds their box for the nominal actuator
NAMEPLATE_SCALED = ("k_t_eq", "k_e_eq", "J_eq")
# the coefficients whose box scales with the actuator's hysteresis band h (and may be 0)
BAND_SCALED = ("i_R", "i_D")
# all the coefficients whose box follows the actuator
ACTUATOR_SCALED = (*NAMEPLATE_SCALED, *BAND_SCALED)


def coefficient_bounds(params: EmaParams | None = None) -> dict[str, tuple[float, float]]:
    """The calibration's search box for an actuator (`COEFFICIENT_BOUNDS` for the nominal one).

    k_t,eq, k_e,eq and J_eq keep the nominal box's ratios to the nameplate k_t, k_e and J, so a
    motor with twice the flux, say, is searched around its own constants, and i_R its ratio to
    the hysteresis band h; the dimensionless shape coefficients and the loop surrogate keep their
    boxes.

    Parameters
    ----------
    params : EmaParams, optional
        The actuator (default: the paper's nominal one).
    """
    ratio = _nameplate_ratios(params)
    return {
        name: (lo * ratio[name], hi * ratio[name]) if name in ratio else (lo, hi)
        for name, (lo, hi) in COEFFICIENT_BOUNDS.items()
    }


def _nameplate_ratios(params: EmaParams | None) -> dict[str, float]:
    """k_t, k_e, J and the band h of `params` over the nominal actuator's (exactly 1 for the nominal one)."""
    nominal = EmaParams()
    params = params if params is not None else nominal
    return {
        "k_t_eq": params.motor.k_t / nominal.motor.k_t,
        "k_e_eq": params.motor.k_e / nominal.motor.k_e,
        "J_eq": params.transmission.J / nominal.transmission.J,
        **{name: current_ripple(params) / nominal.inverter.h for name in BAND_SCALED},
    }


def current_ripple(params: EmaParams) -> float:
    """The scale of the drive's current ripple [A]: the band h of a hysteresis drive; for an FOC
    drive V_dc/(8·L_s·f_pwm), the largest peak-to-peak ripple of a centre-aligned PWM leg into the
    phase inductance (at duty ½)."""
    inv = params.inverter
    if inv.foc:
        return inv.V_dc / (8.0 * params.motor.L_s * inv.f_pwm)
    return inv.h


# the coefficients an FOC drive's monitor does not use: the hysteresis loop's lag (the drive's own PI
# is simulated, kernels.monitor.foc_loop_step) and its dead zone at standstill (a PI loop has none)
FOC_UNUSED = ("tau_i", "i_D")


# the loop-error surrogate's coefficients, the loop's breakaway ripple and its dead zone, which
# the paper's monitor holds at zero (V_H, a scale, has no effect then)
SURROGATE = ("k_H", "delta_0", "delta_1", "delta_u", "delta_2", "i_R", "i_D")


def checked_free(free: Sequence[str] | None, allowed: Sequence[str], monitor: str) -> list[str]:
    """The coefficients a calibration fits: `free` checked against the monitor's (all when None)."""
    if free is None:
        return list(allowed)
    names = list(dict.fromkeys(free))
    if not names:
        raise InputError("free must name at least one coefficient to fit")
    for n in names:
        if n not in allowed:
            raise InputError(
                f"cannot fit {n!r} for the {monitor!r} monitor; choose from {', '.join(allowed)}"
            )
    return [n for n in allowed if n in names]  # in the box's order
