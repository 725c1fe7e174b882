"""Nominal parameters of the EMA (DESIGN §7) as frozen, validated dataclasses.

Every field carries its symbol, unit and meaning in the field metadata; the documentation's
parameter table is generated from that metadata (`parameter_table_markdown`), so the two cannot
drift. All values are SI.

The groups mirror the block diagram: `MotorParams` (PMSM), `InverterParams` (the drive:
hysteresis current control or field-oriented control with PWM), `TransmissionParams` (gearbox,
friction, backlash, end-stops), `ControllerParams` (ACE position loop), `SensorParams` (ADC and
noise), `IntegrationParams` (fixed-step solver), bundled in `EmaParams`.

The field-metadata mechanism (`_p`, `_choice`, `_flag`, `_Validated`) is `emaphm._fields`;
`InverterParams` and the keys of each control mode (`MODE_KEYS`) are `emaphm.drive`, re-exported
here.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from ._fields import _p, _Validated, format_value
from .drive import CONTROL_MODES, MODE_KEYS, InverterParams
from .errors import InputError

__all__ = [
    "CONTROL_MODES",
    "MODE_KEYS",
    "ControllerParams",
    "EmaParams",
    "IntegrationParams",
    "InverterParams",
    "MotorParams",
    "SensorParams",
    "TransmissionParams",
    "parameter_table_markdown",
]


@dataclass(frozen=True)
class MotorParams(_Validated):
    """Three-phase surface PMSM, star connected.

    p : int  pole pairs [-]
    R_s : float  phase resistance [Ω]
    L_s : float  synchronous (phase) inductance [H]
    psi_m : float  permanent-magnet flux linkage [Wb]
    """

    p: int = _p(4, "p", "-", "pole pairs")
    R_s: float = _p(0.5, "R_s", "Ω", "phase resistance")
    L_s: float = _p(1.5e-3, "L_s", "H", "synchronous inductance per phase")
    psi_m: float = _p(0.025, "psi_m", "Wb", "permanent-magnet flux linkage")

    def _check(self) -> None:
        if int(self.p) != self.p:
            raise InputError(f"MotorParams.p must be a whole number of pole pairs, got {self.p!r}")

    @property
    def k_e(self) -> float:
        """Back-EMF constant per phase, k_e = p·psi_m [V·s/rad] (peak phase volts per mechanical rad/s)."""
        return self.p * self.psi_m

    @property
    def k_t(self) -> float:
        """Torque constant, k_t = 1.5·k_e [N·m/A] (amplitude-invariant i_q)."""
        return 1.5 * self.k_e


@dataclass(frozen=True)
class TransmissionParams(_Validated):
    """Gearbox and user load, referred to the motor shaft where stated.

    J_m : float  motor-side inertia [kg·m²]
    J_u : float  user-side (surface) inertia [kg·m²]
    tau : float  gear ratio θ_m/θ_u [-]
    eta : float  gear efficiency, applied to the user load torque [-]
    C : float  viscous coefficient, motor side [N·m·s/rad]
    F_S0 : float  nominal static (breakaway) friction torque, motor side [N·m]
    F_D0 : float  nominal dynamic (Coulomb) friction torque, motor side [N·m]
    B0 : float  nominal total backlash, user side [rad]
    theta_max : float  end-stop position, user side [rad]
    T_load : float  constant external load torque on the user side [N·m]
    """

    J_m: float = _p(5e-5, "J_m", "kg·m²", "motor-side inertia")
    J_u: float = _p(0.05, "J_u", "kg·m²", "user-side inertia")
    tau: float = _p(200.0, "tau", "-", "gear ratio θ_m/θ_u")
    eta: float = _p(0.9, "eta", "-", "gear efficiency (on the user load)", "fraction")
    C: float = _p(1e-5, "C", "N·m·s/rad", "viscous coefficient, motor side", "nonnegative")
    F_S0: float = _p(0.02, "F_S0", "N·m", "static friction, motor side, healthy", "nonnegative")
    F_D0: float = _p(0.014, "F_D0", "N·m", "dynamic friction, motor side, healthy", "nonnegative")
    B0: float = _p(2e-4, "B0", "rad", "total backlash, user side, healthy", "nonnegative")
    theta_max: float = _p(0.5, "theta_max", "rad", "end-stops at ±theta_max, user side")
    T_load: float = _p(0.0, "T_load", "N·m", "constant load torque, user side", "nonnegative")

    def _check(self) -> None:
        if self.F_D0 > self.F_S0:
            raise InputError(
                f"TransmissionParams: dynamic friction F_D0={self.F_D0} exceeds static F_S0={self.F_S0}"
            )

    @property
    def J(self) -> float:
        """Inertia referred to the motor shaft, J = J_m + J_u/tau² [kg·m²]."""
        return self.J_m + self.J_u / self.tau**2


@dataclass(frozen=True)
class ControllerParams(_Validated):
    """Actuator control electronics (ACE): sampled PID position loop with i_d = 0 current references.

    K_P0 : float  nominal proportional gain [A/rad]
    K_I : float  integral gain [A/(rad·s)]
    K_D : float  derivative gain, on the measured user-side speed [A·s/rad]
    tau_D : float  time constant of the first-order speed filter of the D term [s]
    I_max : float  saturation of the quadrature current demand [A]
    f_s : float  controller and sensor sampling rate [Hz]
    """

    K_P0: float = _p(60.0, "K_P0", "A/rad", "proportional gain, healthy")
    K_I: float = _p(200.0, "K_I", "A/(rad·s)", "integral gain", "nonnegative")
    K_D: float = _p(3.5, "K_D", "A·s/rad", "derivative gain (on measured speed)", "nonnegative")
    tau_D: float = _p(1e-3, "tau_D", "s", "speed filter time constant of the D term")
    I_max: float = _p(10.0, "I_max", "A", "current demand saturation")
    f_s: float = _p(1e4, "f_s", "Hz", "controller and sensor sampling rate")


@dataclass(frozen=True)
class SensorParams(_Validated):
    """ADC quantisation and white measurement noise of the sampled signals.

    A resolution of 0 bits means an ideal converter (no quantisation). Noise is applied only when a
    simulation is run with ``noise=True``.

    bits_current : int  phase-current ADC resolution [bit]
    full_scale_current : float  phase-current ADC range ±full_scale [A]
    sigma_current : float  phase-current noise, standard deviation [A]
    bits_position : int  user-position ADC resolution [bit]
    full_scale_position : float  user-position ADC range ±full_scale [rad]
    sigma_position : float  user-position noise, standard deviation [rad]
    """

    bits_current: int = _p(12, "n_i", "bit", "phase-current ADC resolution (0: ideal)", "nonnegative")
    full_scale_current: float = _p(20.0, "I_fs", "A", "phase-current ADC range ±I_fs")
    sigma_current: float = _p(0.02, "sigma_i", "A", "phase-current noise, std", "nonnegative")
    bits_position: int = _p(16, "n_theta", "bit", "position ADC resolution (0: ideal)", "nonnegative")
    full_scale_position: float = _p(0.6, "theta_fs", "rad", "position ADC range ±theta_fs")
    sigma_position: float = _p(1e-5, "sigma_theta", "rad", "position noise, std", "nonnegative")

    def _check(self) -> None:
        for name in ("bits_current", "bits_position"):
            bits = getattr(self, name)
            if int(bits) != bits or bits > 32:
                raise InputError(f"SensorParams.{name} must be a whole number 0..32, got {bits!r}")

    @property
    def lsb_current(self) -> float:
        """Current quantisation step [A], 0 for an ideal converter."""
        return _lsb(self.bits_current, self.full_scale_current)

    @property
    def lsb_position(self) -> float:
        """Position quantisation step [rad], 0 for an ideal converter."""
        return _lsb(self.bits_position, self.full_scale_position)


def _lsb(bits: int, full_scale: float) -> float:
    return 0.0 if bits == 0 else 2.0 * full_scale / 2 ** int(bits)


@dataclass(frozen=True)
class IntegrationParams(_Validated):
    """Fixed-step solver of the high-fidelity twin.

    dt : float  integration step [s]
    ripple_fraction : float  largest current change per electrical sub-step, as a fraction of h [-]
    """

    dt: float = _p(1e-6, "Δt", "s", "HF integration step")
    ripple_fraction: float = _p(
        0.4, "r_h", "-", "max current change per electrical sub-step, fraction of h", "fraction"
    )


@dataclass(frozen=True)
class EmaParams(_Validated):
    """All parameters of the EMA, grouped as the block diagram.

    motor : MotorParams  the PMSM
    inverter : InverterParams  the two-level inverter and its current control (hysteresis or FOC)
    transmission : TransmissionParams  gearbox and user load
    controller : ControllerParams  the control electronics: sampled PID position loop, sample rate f_s
    sensors : SensorParams  ADC quantisation and measurement noise
    integration : IntegrationParams  the HF twin's fixed step
    """

    motor: MotorParams = field(default_factory=MotorParams)
    inverter: InverterParams = field(default_factory=InverterParams)
    transmission: TransmissionParams = field(default_factory=TransmissionParams)
    controller: ControllerParams = field(default_factory=ControllerParams)
    sensors: SensorParams = field(default_factory=SensorParams)
    integration: IntegrationParams = field(default_factory=IntegrationParams)

    def _check(self) -> None:
        ratio = 1.0 / (self.controller.f_s * self.integration.dt)
        if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
            raise InputError(
                f"the sample period 1/f_s must be a whole number of steps dt, got {ratio:.6g} steps"
            )

    @property
    def steps_per_sample(self) -> int:
        """Integration steps per controller/sensor sample period."""
        return round(1.0 / (self.controller.f_s * self.integration.dt))

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """Plain nested dict of every value in use (for result metadata and the params hash): each
        group's `to_dict`, so the inverter holds only its control mode's keys."""
        return {f.name: getattr(self, f.name).to_dict() for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, data: dict[str, dict[str, Any]]) -> EmaParams:
        """Inverse of `to_dict` (missing fields take their defaults); unknown groups or fields
        raise `InputError`."""
        groups: dict[str, Any] = {f.name: f.default_factory for f in dataclasses.fields(cls)}
        unknown = set(data) - set(groups)
        if unknown:
            raise InputError(f"unknown parameter group(s): {', '.join(sorted(unknown))}")
        try:
            return cls(**{name: groups[name](**values) for name, values in data.items()})
        except TypeError as exc:
            raise InputError(f"bad parameter set: {exc}") from None


_GROUPS = (MotorParams, InverterParams, TransmissionParams, ControllerParams, SensorParams, IntegrationParams)


def parameter_table_markdown() -> str:
    """The nominal parameter table (Markdown), generated from the dataclass metadata; the inverter
    fields of one control mode only say so."""
    only = {key: mode for mode, keys in MODE_KEYS.items() for key in keys}  # InverterParams' names
    lines = ["| group | symbol | meaning | value | unit |", "|---|---|---|---|---|"]
    for group in _GROUPS:
        instance = group()
        for f in dataclasses.fields(group):
            m = f.metadata
            value = format_value(getattr(instance, f.name))
            doc = m["doc"] + (f" (control = {only[f.name]} only)" if f.name in only else "")
            lines.append(f"| {group.__name__} | `{f.name}` ({m['symbol']}) | {doc} | {value} | {m['unit']} |")
    return "\n".join(lines) + "\n"
