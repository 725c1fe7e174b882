"""The one fixed-step loop of the high-fidelity twin (DESIGN §3).

Every sample period T_s = 1/f_s (n_per_sample steps of dt):
  1. the user position is sampled through the ADC (noise added by the caller's array) and the
     PID computes i_q,ref, held until the next sample (controller.pid_step);
  2. n_per_sample steps of: inverter + stator (pmsm_abc.stator_step, sub-stepped) → torque →
     mechanics (mechanics.mechanics_step), accumulating the oversampled currents.

Output row k (time t_k = k·T_s) holds the positions and speed at t_k, the i_q,ref computed at t_k,
and the phase currents, i_q and torque averaged over the period (t_k − T_s, t_k] (an oversampling
ADC: point sampling at f_s would alias the 5–30 kHz hysteresis ripple). Row 0 is the initial rest.
"""

from __future__ import annotations

from ._jit import jit
from .controller import pid_step
from .mechanics import mechanics_step
from .pmsm_abc import stator_step
from .sensors import quantise

OUT_COLUMNS = (
    "theta_u",  # user position, true [rad]
    "theta_u_meas",  # user position after ADC and noise, as the controller saw it [rad]
    "theta_m",  # motor position [rad]
    "omega_m",  # motor speed [rad/s]
    "theta_e",  # electrical angle p·θ_m [rad]
    "i_a",  # phase currents, period average [A]
    "i_b",
    "i_c",
    "i_q",  # quadrature current, period average of the per-step Clarke–Park value [A]
    "i_q_ref",  # quadrature current demand [A]
    "T_m",  # motor torque, period average [N·m]
)
N_OUT = len(OUT_COLUMNS)


@jit
def simulate_hf(theta_cmd, theta_noise, lsb_theta, fs_theta, cp, sp, mp, dt, n_per_sample, n_sub, out):  # type: ignore[no-untyped-def]
    """Run the HF twin over len(theta_cmd) samples, writing `out` (shape (n, N_OUT)).

    theta_cmd : command at the sample instants [rad]; theta_noise : position noise per sample [rad];
    lsb_theta, fs_theta : position ADC step and full scale [rad]; cp, sp, mp : controller, stator
    and mechanics packs; dt : step [s]; n_per_sample : steps per sample; n_sub : electrical
    sub-steps per step.
    """
    n = theta_cmd.shape[0]
    theta_m = 0.0
    omega_m = 0.0
    theta_u = 0.0
    i_a = 0.0
    i_b = 0.0
    i_c = 0.0
    s_a = 1.0
    s_b = 1.0
    s_c = 1.0
    integral = 0.0
    omega_f = 0.0
    acc_a = 0.0
    acc_b = 0.0
    acc_c = 0.0
    acc_q = 0.0
    acc_T = 0.0
    inv = 1.0 / n_per_sample
    for k in range(n):
        theta_meas = quantise(theta_u + theta_noise[k], lsb_theta, fs_theta)
        i_q_ref, integral, omega_f = pid_step(theta_cmd[k], theta_meas, omega_m, integral, omega_f, cp)
        row = out[k]
        row[0] = theta_u
        row[1] = theta_meas
        row[2] = theta_m
        row[3] = omega_m
        row[4] = sp.p * theta_m
        row[5] = acc_a * inv
        row[6] = acc_b * inv
        row[7] = acc_c * inv
        row[8] = acc_q * inv
        row[9] = i_q_ref
        row[10] = acc_T * inv
        if k == n - 1:
            break
        acc_a = 0.0
        acc_b = 0.0
        acc_c = 0.0
        acc_q = 0.0
        acc_T = 0.0
        for _ in range(n_per_sample):
            i_a, i_b, i_c, s_a, s_b, s_c, T_m, i_q = stator_step(
                i_a, i_b, i_c, s_a, s_b, s_c, sp.p * theta_m, omega_m, i_q_ref, dt, n_sub, sp
            )
            theta_m, omega_m, theta_u = mechanics_step(theta_m, omega_m, theta_u, T_m, dt, mp)
            acc_a += i_a
            acc_b += i_b
            acc_c += i_c
            acc_q += i_q
            acc_T += T_m
