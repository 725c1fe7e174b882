"""The drive: `InverterParams`, the two-level inverter and its current control.

``control = "hysteresis"`` is the paper's per-phase hysteresis comparators (band ``h``);
``control = "foc"`` is field-oriented control, dq PI current loops driving a PWM inverter. Which
fields belong to which mode is `MODE_KEYS`, the one list the actuator file's reader and template
(`emaphm.actuator`) and `InverterParams.to_dict` (hence the params hash) go by.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ._fields import _choice, _flag, _p, _Validated
from .errors import InputError

__all__ = ["CONTROL_MODES", "MODE_KEYS", "InverterParams"]

CONTROL_MODES = ("hysteresis", "foc")

# the InverterParams fields of each current-control mode (V_dc serves both; `control` chooses):
# the actuator file refuses the other mode's keys, the template and `to_dict` write only its own
MODE_KEYS: dict[str, tuple[str, ...]] = {
    "hysteresis": ("h",),
    "foc": (
        "f_pwm", "dead_time", "dead_time_compensation", "K_p_i", "K_i_i", "modulation", "update",
        "computation_delay", "decoupling", "emf_feedforward", "angle_compensation", "voltage_limit",
        "pwm_phase",
    ),
}  # fmt: skip


@dataclass(frozen=True)
class InverterParams(_Validated):
    """Two-level inverter: hysteresis current control (the paper's) or field-oriented control with PWM.

    V_dc : float  DC bus voltage [V] (both modes)
    h : float  total width of the hysteresis band [A] (hysteresis only)
    control : str  current control: "hysteresis" (per-phase comparators, the paper's) or "foc"
        (dq PI current loops with PWM) [-]

    The rest serve "foc" only:

    f_pwm : float  PWM carrier frequency, centre-aligned (triangle) carrier [Hz]
    dead_time : float  dead time per leg [s], less than a quarter of the PWM period
    dead_time_compensation : bool  add ±dead_time/T_pwm to each leg's duty by the sign of its
        sampled current [-]
    K_p_i : float  proportional gain of the dq current PI loops [V/A]
    K_i_i : float  integral gain of the dq current PI loops [V/(A·s)]
    modulation : str  "svpwm" (space vector: min-max zero-sequence injection) or "sine"
        (sine-triangle) [-]
    update : str  current sampling and duty update: "single" (once per PWM period, at the carrier
        peak) or "double" (at the peak and the valley) [-]
    computation_delay : int  update periods the computed voltage waits before it is applied, 0..2 [-]
    decoupling : bool  dq cross-coupling decoupling: −ω_e·L_s·i_q in d, +ω_e·L_s·i_d in q, with
        the nameplate L_s [-]
    emf_feedforward : bool  back-EMF feed-forward ω_e·ψ_m in q, with the nameplate ψ_m [-]
    angle_compensation : bool  advance the inverse-Park angle by (computation_delay + 0.5)·ω_e·T_update [-]
    voltage_limit : float  limit of the dq voltage vector, as a fraction of the modulation's
        linear range `V_linear` [-]
    pwm_phase : float  carrier phase at t = 0, as a fraction of a PWM period, in [0, 1) [-]

    The defaults K_p_i = L_s·ω_c and K_i_i = R_s·ω_c are the pole-zero-cancellation tuning at
    ω_c = 2π·1 kHz for the nominal motor. The fields of the mode not chosen must keep their
    defaults: they describe nothing, and `to_dict` (hence the params hash) leaves them out.
    """

    V_dc: float = _p(48.0, "V_dc", "V", "DC bus voltage")
    h: float = _p(0.1, "h", "A", "hysteresis band, total width")
    control: str = _choice(
        "hysteresis", "control", "current control: hysteresis or foc (dq PI loops, PWM)", CONTROL_MODES
    )
    f_pwm: float = _p(20e3, "f_PWM", "Hz", "PWM carrier frequency, centre-aligned")
    dead_time: float = _p(1e-6, "t_d", "s", "dead time per leg", "nonnegative")
    dead_time_compensation: bool = _flag(
        True, "DTC", "dead-time compensation by the sign of the sampled phase current"
    )
    K_p_i: float = _p(9.42, "K_p,i", "V/A", "dq current-loop PI, proportional gain")
    K_i_i: float = _p(3141.6, "K_i,i", "V/(A·s)", "dq current-loop PI, integral gain", "nonnegative")
    modulation: str = _choice(
        "svpwm", "modulation", "svpwm (min-max injection) or sine (sine-triangle)", ("svpwm", "sine")
    )
    update: str = _choice(
        "single",
        "update",
        "sampling, duty update: single (peak) or double (peak, valley)",
        ("single", "double"),
    )
    computation_delay: int = _p(
        1, "n_d", "-", "update periods the computed voltage waits before it is applied (0..2)", "nonnegative"
    )
    decoupling: bool = _flag(True, "decoupling", "dq cross-coupling decoupling with the nameplate L_s")
    emf_feedforward: bool = _flag(True, "EMF FF", "back-EMF feed-forward ω_e·ψ_m in q, nameplate ψ_m")
    angle_compensation: bool = _flag(
        False, "angle comp.", "advance the inverse-Park angle by (computation_delay + 0.5)·ω_e·T_update"
    )
    voltage_limit: float = _p(
        1.0, "m_max", "-", "dq voltage limit, fraction of V_dc/√3 (svpwm) or V_dc/2 (sine)", "fraction"
    )
    pwm_phase: float = _p(0.0, "φ_PWM", "-", "carrier phase at t = 0, fraction of a PWM period", "cycle")

    def _check(self) -> None:
        if int(self.computation_delay) != self.computation_delay or not 0 <= self.computation_delay <= 2:
            raise InputError(
                f"InverterParams.computation_delay must be a whole number 0..2, got {self.computation_delay!r}"
            )
        if self.dead_time >= self.T_pwm / 4:
            raise InputError(
                f"InverterParams.dead_time = {self.dead_time:g} s must be less than a quarter of the PWM "
                f"period, T_pwm/4 = {self.T_pwm / 4:g} s at f_pwm = {self.f_pwm:g} Hz"
            )
        defaults = InverterParams.__dataclass_fields__
        for mode, keys in MODE_KEYS.items():
            if mode == self.control:
                continue
            for key in keys:
                if getattr(self, key) != defaults[key].default:
                    raise InputError(
                        f'InverterParams.{key} = {getattr(self, key)!r} belongs to control = "{mode}", '
                        f'but control is "{self.control}" (leave it at its default)'
                    )

    @property
    def foc(self) -> bool:
        """True for field-oriented control (control == "foc")."""
        return self.control == "foc"

    @property
    def T_pwm(self) -> float:
        """PWM period 1/f_pwm [s]."""
        return 1.0 / self.f_pwm

    @property
    def T_update(self) -> float:
        """Period of current sampling and duty update [s]: T_pwm ("single") or T_pwm/2 ("double")."""
        return self.T_pwm if self.update == "single" else self.T_pwm / 2.0

    @property
    def V_linear(self) -> float:
        """Linear range of the modulation, peak phase voltage [V]: V_dc/√3 (svpwm) or V_dc/2 (sine)."""
        return self.V_dc / math.sqrt(3.0) if self.modulation == "svpwm" else self.V_dc / 2.0

    def fields_in_use(self) -> tuple[str, ...]:
        """control, V_dc and the keys of the chosen mode (`MODE_KEYS`)."""
        return ("control", "V_dc", *MODE_KEYS[self.control])

    def to_dict(self) -> dict[str, Any]:
        """The fields in use, by name; for "hysteresis" exactly {"V_dc", "h"} (no "control"), the
        form of the parameter sets recorded before FOC existed, so that their hash stays."""
        data = super().to_dict()
        if self.control == "hysteresis":
            del data["control"]
        return data
