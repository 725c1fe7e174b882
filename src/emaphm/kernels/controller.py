"""Actuator control electronics (ACE): sampled PID position loop (DESIGN §3.2), shared by both fidelities.

    i_q,ref = sat( K_P·e + K_I·∫e dt − K_D·ω̃_m/τ , ±I_max ),   e = θ_cmd − θ_u,meas

ω̃_m is the measured motor speed through a first-order filter of time constant τ_D. The
derivative acts on that speed, not on the error: on the error the K_P drift (k8) becomes nearly
invisible, and through the backlash it sets up a limit cycle. Anti-windup by conditional
integration: the integrator holds while the output is saturated and the error drives it further
into saturation. Called once per sample period T_s; its output is held (zero-order hold).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ._jit import jit


class ControllerPack(NamedTuple):
    """Position-loop parameters with the K_P drift applied."""

    K_P: float  # proportional gain [A/rad]
    K_I: float  # integral gain [A/(rad·s)]
    K_D: float  # derivative gain on user-side speed [A·s/rad]
    tau_D: float  # speed filter time constant [s]
    I_max: float  # current demand saturation [A]
    T_s: float  # sample period [s]
    tau: float  # gear ratio, to refer the motor speed to the user side [-]


@jit
def pid_step(
    theta_cmd: float, theta_meas: float, omega_m: float, integral: float, omega_f: float, cp: ControllerPack
):  # type: ignore[no-untyped-def]
    """One controller sample: returns (i_q,ref [A], new ∫e [rad·s], new filtered speed ω̃_m [rad/s])."""
    # first-order speed filter, exact (zero-order-hold) discretisation
    omega_f += (1.0 - math.exp(-cp.T_s / cp.tau_D)) * (omega_m - omega_f)
    e = theta_cmd - theta_meas
    u = cp.K_P * e + cp.K_I * integral - cp.K_D * omega_f / cp.tau
    if u > cp.I_max:
        i_q_ref = cp.I_max
        if e < 0.0:
            integral += e * cp.T_s
    elif u < -cp.I_max:
        i_q_ref = -cp.I_max
        if e > 0.0:
            integral += e * cp.T_s
    else:
        i_q_ref = u
        integral += e * cp.T_s
    return i_q_ref, integral, omega_f
