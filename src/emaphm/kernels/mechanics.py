"""Gearbox mechanics shared by both fidelities (DESIGN §3.8).

One rigid degree of freedom referred to the motor shaft:

    J·dω_m/dt = T_m − C·ω_m − T_fric − T_load/(τ·η),   J = J_m + J_u/τ²

with Borello's discontinuous dry-friction model (static F_S, dynamic F_D), a backlash dead band of
total width B between the gear output θ_m/τ and the user position θ_u (the position sensor is on
the user side, so the backlash is inside the loop), and inelastic end-stops at ±θ_max on the user
side. Semi-implicit Euler with a fixed step.
"""

from __future__ import annotations

from typing import NamedTuple

from ._jit import jit


class MechanicsPack(NamedTuple):
    """Mechanical parameters with faults applied (SI, motor side unless stated)."""

    J: float  # inertia at the motor shaft [kg·m²]
    C: float  # viscous coefficient [N·m·s/rad]
    F_S: float  # static friction [N·m]
    F_D: float  # dynamic friction [N·m]
    B: float  # total backlash, user side [rad]
    tau: float  # gear ratio [-]
    eta: float  # gear efficiency [-]
    theta_max: float  # end-stops, user side [rad]
    T_load: float  # load torque, user side [N·m]


@jit
def friction_step(
    omega_m: float,
    T_act: float,
    dt: float,
    J: float,
    C: float,
    F_S: float,
    F_D: float,
    T_ripple: float = 0.0,
) -> float:
    """Speed after one step of Borello's dry-friction model [rad/s].

    T_act is the active (driving) torque on the shaft. Four cases, decided every step:
    1. stuck (ω = 0) and |T_act| + T_ripple ≤ F_S: stays stuck;
    2. stuck and |T_act| + T_ripple > F_S: breaks away against F_D·sign(T_act);
    3. sliding: dynamic friction F_D·sign(ω) opposes the motion;
    4. the speed would cross zero within the step: it stops exactly (ω = 0), and case 1 or 2
       decides the next step. This is what makes stick–slip work with a fixed step.

    T_ripple ≥ 0 is the peak of a torque ripple the step's T_act is the mean of: a model that
    averages the ripple away (the LF monitor, over the hysteresis loop's switching) breaks away
    when the ripple's peak would. 0 (the HF twin, which resolves its ripple) is the plain model.
    A breakaway whose mean torque cannot beat F_D stays stuck for the step.
    """
    # Δt/J: a division a run rather than one a step in the chain ω → θ → torque → ω, once a
    # caller's loop hoists it (its operands are the loop's constants; issue 36, fifteenth session)
    dt_J = dt / J
    if omega_m == 0.0:
        if abs(T_act) + T_ripple <= F_S:  # case 1
            return 0.0
        s = 1.0 if T_act > 0.0 else -1.0  # case 2
        return dt_J * max(abs(T_act) - F_D, 0.0) * s
    s = 1.0 if omega_m > 0.0 else -1.0
    omega_new = omega_m + dt_J * (T_act - C * omega_m - F_D * s)  # case 3
    if omega_new * s <= 0.0:  # case 4
        return 0.0
    return omega_new


@jit
def backlash(theta_g: float, theta_u: float, B: float) -> float:
    """User position after the backlash dead band (a play operator) [rad].

    The user side stays where it is while the gear output θ_g moves inside the gap
    |θ_g − θ_u| ≤ B/2, and is dragged along by the flank in contact otherwise.
    """
    half = 0.5 * B
    if theta_u < theta_g - half:
        return theta_g - half
    if theta_u > theta_g + half:
        return theta_g + half
    return theta_u


@jit
def mechanics_step(
    theta_m: float,
    omega_m: float,
    theta_u: float,
    T_m: float,
    dt: float,
    mp: MechanicsPack,
    T_ripple: float = 0.0,
):  # type: ignore[no-untyped-def]
    """One fixed step of the drive train: (θ_m, ω_m, θ_u) after motor torque T_m acted for dt
    (T_ripple: the peak of a ripple about T_m that the step does not resolve, `friction_step`)."""
    T_act = T_m - mp.T_load / (mp.tau * mp.eta)  # DESIGN §3.8, load reflected through the gear
    omega_m = friction_step(omega_m, T_act, dt, mp.J, mp.C, mp.F_S, mp.F_D, T_ripple)
    theta_m += dt * omega_m
    theta_u = backlash(theta_m * (1.0 / mp.tau), theta_u, mp.B)  # 1/τ a run (as Δt/J above)
    # inelastic end-stops on the user side: the gear flank pressing the user into the stop is
    # held at the stop and loses its speed towards it
    if theta_u > mp.theta_max:
        theta_u = mp.theta_max
        theta_m = mp.tau * (mp.theta_max + 0.5 * mp.B)
        if omega_m > 0.0:
            omega_m = 0.0
    elif theta_u < -mp.theta_max:
        theta_u = -mp.theta_max
        theta_m = -mp.tau * (mp.theta_max + 0.5 * mp.B)
        if omega_m < 0.0:
            omega_m = 0.0
    return theta_m, omega_m, theta_u
