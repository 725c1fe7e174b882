"""The one fixed-step loop of the high-fidelity twin (DESIGN §3).

Every sample period T_s = 1/f_s (n_per_sample steps of dt):
  1. the user position is sampled through the ADC (noise added by the caller's array) and the
     PID computes i_q,ref, held until the next sample (controller.pid_step);
  2. n_per_sample steps of: inverter + stator (the equations of pmsm_abc.stator_step,
     sub-stepped) → torque → mechanics (the equations of mechanics.mechanics_step), accumulating
     the oversampled currents.

Output row k (time t_k = k·T_s) holds the positions and speed at t_k, the i_q,ref computed at t_k,
and the phase currents, i_q and torque averaged over the period (t_k − T_s, t_k] (an oversampling
ADC: point sampling at f_s would alias the 5–30 kHz hysteresis ripple). Row 0 is the initial rest.

Speed. The step is one long dependency chain (ω_m → θ_e → back-EMF → currents → torque → ω_m),
so the loop below writes the same equations as `stator_step` and `mechanics_step` in an order
that keeps that chain short (tests/kernels/test_pmsm_abc.py checks it against them step by step;
results differ by rounding only):
  * sin θ_e and cos θ_e are advanced by a rotation through the step's angle p·Δt·ω_m (short
    Taylor series, exact to rounding; the part known a step ahead, the previous angle step, is
    applied first and the small change eps after the torque is known), and recomputed exactly
    with libm at every sample start, after an end-stop and when the angle step or its change is
    large (ROTATION_MAX, EPS_MAX);
  * the electrical sub-step is the linear map i ← i + D·i + V·s + β of `pmsm_abc.euler_map`,
    with its coefficients and the other run constants (reciprocals instead of divisions) computed
    once; the isolated neutral keeps i_a + i_b + i_c = 0 (DESIGN §3.4), so the loop carries i_a
    and i_b and takes i_c = −(i_a + i_b);
  * the back-EMF term β and the torque coefficients are linear forms in (sin θ_e, cos θ_e,
    sin 2θ_e, cos 2θ_e) with run-constant coefficients (the coupling k_e,x·[u_x +
    ζ·sin(2θ_e + φ_e − γ_x)] of `pmsm_abc`, DESIGN §3.7); the 2θ_e part, a few ns per step, is
    skipped when ζ = 0, where its coefficients are exact zeros; the part of the speed update that
    does not depend on the torque is formed before it;
  * the comparators branch on their state (a leg can only switch away from the side it is on),
    and V·s is recomputed only when a leg switches;
  * with n_sub = 1 (healthy) the sub-step runs without a loop.
"""

from __future__ import annotations

import math

from ._jit import jit
from .controller import pid_step
from .foc import carried, drive_update, leg_state, window
from .pmsm_abc import euler_map
from .sensors import quantise
from .transforms import HALF_SQRT3, SQRT3

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

# largest angle step [rad] advanced by the rotation: the series below is then exact to rounding
# (the first omitted terms, δ⁷/5040 and δ⁶/720, are below 1e-17 relative); 5e-3 rad per 1 µs step
# is 1250 rad/s of motor speed at p = 4, far above what the actuator reaches
ROTATION_MAX = 5e-3
# largest change of the angle step between two steps advanced to second order (error eps³/6 below
# 2e-19); eps = p·Δt²·T/J is ~1e-7 at the largest torque of the actuator
EPS_MAX = 1e-6
INV_SQRT3 = 1.0 / SQRT3


@jit
def _comparators(i_a, i_b, i_c, s_a, s_b, s_c, lo_a, lo_b, lo_c, hi_a, hi_b, hi_c):  # type: ignore[no-untyped-def]
    """Hysteresis comparators (pmsm_abc.hysteresis) for the three legs in states s_x = ±1.

    lo_x, hi_x = i_x,ref ∓ h/2. A leg on +V_dc/2 can only switch down (i_x > hi_x) and a leg on
    −V_dc/2 only up (i_x < lo_x). Returns the states and whether any leg switched.
    """
    switched = False
    if s_a > 0.0:
        if i_a > hi_a:
            s_a = -1.0
            switched = True
    elif i_a < lo_a:
        s_a = 1.0
        switched = True
    if s_b > 0.0:
        if i_b > hi_b:
            s_b = -1.0
            switched = True
    elif i_b < lo_b:
        s_b = 1.0
        switched = True
    if s_c > 0.0:
        if i_c > hi_c:
            s_c = -1.0
            switched = True
    elif i_c < lo_c:
        s_c = 1.0
        switched = True
    return s_a, s_b, s_c, switched


@jit(nogil=True)  # a batch of runs on Python threads (`HighFidelityEma.simulate_batch`)
def simulate_hf(theta_cmd, theta_noise, lsb_theta, fs_theta, cp, sp, mp, fp, dt, n_per_sample, n_sub, out):  # type: ignore[no-untyped-def]
    """Run the HF twin over len(theta_cmd) samples, writing `out` (shape (n, N_OUT)).

    theta_cmd : command at the sample instants [rad]; theta_noise : position noise per sample [rad];
    lsb_theta, fs_theta : position ADC step and full scale [rad]; cp, sp, mp, fp : controller,
    stator, mechanics and drive packs (fp.on = 0: the hysteresis comparators, states s_x starting
    at +1; else the FOC drive of `foc`, duties starting at ½); dt : step [s]; n_per_sample : steps
    per sample; n_sub : electrical sub-steps per step.
    """
    n = theta_cmd.shape[0]
    # ---- run constants ------------------------------------------------------------------------
    p = sp.p
    p_dt = p * dt  # θ_e advances by p·Δt·ω_m per step
    half_h = 0.5 * sp.h
    inv_sub = 1.0 / n_sub
    inv_per = 1.0 / n_per_sample
    # one Euler sub-step of the stator, i ← i + D·i + V·s + β (pmsm_abc.euler_map, DESIGN
    # §3.4–§3.7). The isolated neutral keeps i_c = −(i_a + i_b) (every column of M sums to zero),
    # so the loop carries i_a and i_b only: i_x ← A_xa·i_a + A_xb·i_b + V_x·s + β_x for x = a, b,
    # with A_xy = δ_xy + D_xy − D_xc.
    D, V, S, C, S2, C2 = euler_map(sp, dt / n_sub)
    A_aa = 1.0 + (D[0][0] - D[0][2])
    A_ab = D[0][1] - D[0][2]
    A_ba = D[1][0] - D[1][2]
    A_bb = 1.0 + (D[1][1] - D[1][2])
    V_aa, V_ab, V_ac = V[0]
    V_ba, V_bb, V_bc = V[1]
    S_a, S_b = S[0], S[1]
    C_a, C_b = C[0], C[1]
    S2_a, S2_b = S2[0], S2[1]
    C2_a, C2_b = C2[0], C2[1]
    # g_x − g_c = q_sin_x·sin θ_e + q_cos_x·cos θ_e + q2_sin_x·sin 2θ_e + q2_cos_x·cos 2θ_e with the
    # coupling g_x = k_e,x·[u_x + ζ·sin(2θ_e + φ_e − γ_x)] (pmsm_abc, DESIGN §3.7; u_x:
    # transforms.phase_directions, ζ·sin(2θ_e + φ_e − γ_x) = ecc2_sin_x·sin 2θ_e + ecc2_cos_x·cos 2θ_e)
    q_sin_a = -sp.k_e_a - 0.5 * sp.k_e_c
    q_cos_a = HALF_SQRT3 * sp.k_e_c
    q_sin_b = 0.5 * (sp.k_e_b - sp.k_e_c)
    q_cos_b = HALF_SQRT3 * (sp.k_e_b + sp.k_e_c)
    q2_sin_a = sp.k_e_a * sp.ecc2_sin_a - sp.k_e_c * sp.ecc2_sin_c
    q2_cos_a = sp.k_e_a * sp.ecc2_cos_a - sp.k_e_c * sp.ecc2_cos_c
    q2_sin_b = sp.k_e_b * sp.ecc2_sin_b - sp.k_e_c * sp.ecc2_sin_c
    q2_cos_b = sp.k_e_b * sp.ecc2_cos_b - sp.k_e_c * sp.ecc2_cos_c
    eccentric = sp.zeta != 0.0  # else every 2θ_e coefficient is an exact zero: skip them
    # mechanics (DESIGN §3.8, mechanics.mechanics_step)
    T_load_m = mp.T_load / (mp.tau * mp.eta)  # load reflected through the gear
    dt_J = dt / mp.J
    visc = mp.C
    F_S = mp.F_S
    F_D = mp.F_D
    inv_tau = 1.0 / mp.tau
    half_B = 0.5 * mp.B
    theta_max = mp.theta_max
    theta_m_stop = mp.tau * (mp.theta_max + 0.5 * mp.B)  # gear flank held at the stop
    p_dt_J = p_dt * dt_J
    # Taylor coefficients of sin δ and cos δ − 1
    s3 = -1.0 / 6.0
    s5 = 1.0 / 120.0
    c2 = -0.5
    c4 = 1.0 / 24.0

    # ---- state --------------------------------------------------------------------------------
    theta_m = 0.0
    omega_m = 0.0
    theta_u = 0.0
    delta = 0.0  # electrical angle step p·Δt·ω_m [rad], sin δ and cos δ − 1
    sin_d = 0.0
    cos_d_m1 = 0.0
    i_a = 0.0
    i_b = 0.0
    s_a = 1.0
    s_b = 1.0
    s_c = 1.0
    vs_a = V_aa * s_a + V_ab * s_b + V_ac * s_c  # V·s: the inverter legs seen through the neutral
    vs_b = V_ba * s_a + V_bb * s_b + V_bc * s_c
    integral = 0.0
    omega_f = 0.0
    # FOC drive (foc.py): PI integrators, the duties in force and the two queued behind them, the
    # current update interval (its start, whether it starts at a carrier peak, the legs' windows)
    foc = fp.on != 0.0
    delay = int(fp.delay)
    I_d = 0.0
    I_q = 0.0
    d_a = d_b = d_c = q1_a = q1_b = q1_c = q2_a = q2_b = q2_c = 0.5
    n_update = 0
    next_update = fp.t_first
    t_window = fp.t_first - fp.T_u
    peak = fp.first_peak == 0.0 if fp.double != 0.0 else True
    wl_a, wh_a = window(0.5, peak, fp)
    wl_b, wh_b = wl_a, wh_a
    wl_c, wh_c = wl_a, wh_a
    ce_a = ce_b = ce_c = ck_a = ck_b = ck_c = 0.0  # dead time carried into the interval (foc.carried)
    n_step = 0
    acc_a = 0.0
    acc_b = 0.0
    acc_q = 0.0
    acc_T = 0.0
    for k in range(n):
        theta_meas = quantise(theta_u + theta_noise[k], lsb_theta, fs_theta)
        i_q_ref, integral, omega_f = pid_step(theta_cmd[k], theta_meas, omega_m, integral, omega_f, cp)
        row = out[k]
        row[0] = theta_u
        row[1] = theta_meas
        row[2] = theta_m
        row[3] = omega_m
        row[4] = p * theta_m
        row[5] = acc_a * inv_per
        row[6] = acc_b * inv_per
        row[7] = -(acc_a + acc_b) * inv_per  # i_c = −(i_a + i_b)
        row[8] = acc_q * inv_per
        row[9] = i_q_ref
        row[10] = acc_T * inv_per
        if k == n - 1:
            break
        acc_a = 0.0
        acc_b = 0.0
        acc_q = 0.0
        acc_T = 0.0
        sin_e = math.sin(p * theta_m)  # exact at every sample start
        cos_e = math.cos(p * theta_m)
        for _ in range(n_per_sample):
            # ---- inverter + stator over the step, angle and speed held (pmsm_abc.stator_step)
            u_a = -sin_e  # u_x = −sin(θ_e − γ_x), transforms.phase_directions
            u_b = 0.5 * sin_e + HALF_SQRT3 * cos_e
            u_c = 0.5 * sin_e - HALF_SQRT3 * cos_e
            # β = −h·M·e, e_x = g_x·ω_m (DESIGN §3.5), folded by euler_map into S, C, S2, C2
            be_a = (omega_m * S_a) * sin_e + (omega_m * C_a) * cos_e
            be_b = (omega_m * S_b) * sin_e + (omega_m * C_b) * cos_e
            # T_m = Σ_x g_x·i_x (DESIGN §3.5) = g_ac·i_a + g_bc·i_b with i_c = −(i_a + i_b)
            g_ac = q_sin_a * sin_e + q_cos_a * cos_e
            g_bc = q_sin_b * sin_e + q_cos_b * cos_e
            if eccentric:
                # DESIGN §3.7: the eccentric flux linkage adds the 2θ_e harmonic to every coupling
                sin_2e = (sin_e + sin_e) * cos_e
                cos_2e = (cos_e - sin_e) * (cos_e + sin_e)
                be_a += (omega_m * S2_a) * sin_2e + (omega_m * C2_a) * cos_2e
                be_b += (omega_m * S2_b) * sin_2e + (omega_m * C2_b) * cos_2e
                g_ac += q2_sin_a * sin_2e + q2_cos_a * cos_2e
                g_bc += q2_sin_b * sin_2e + q2_cos_b * cos_2e
            w_a = -sin_e + INV_SQRT3 * cos_e  # i_q = −i_α·sin θ_e + i_β·cos θ_e
            w_b = 2.0 * INV_SQRT3 * cos_e
            lo_a = i_q_ref * u_a - half_h  # DESIGN §3.3: band i_x,ref ± h/2
            lo_b = i_q_ref * u_b - half_h
            lo_c = i_q_ref * u_c - half_h
            hi_a = i_q_ref * u_a + half_h
            hi_b = i_q_ref * u_b + half_h
            hi_c = i_q_ref * u_c + half_h
            # the FOC drive's legs, then the same Euler step as below, written apart so that the
            # hysteresis branches keep their operations (and results) as they were
            if foc:
                t_now = n_step * dt
                if t_now >= next_update - 1e-3 * dt:  # sample, PI, duties (foc.drive_update)
                    n_a, n_b, n_c, I_d, I_q = drive_update(
                        i_a, i_b, sin_e, cos_e, omega_m, i_q_ref, I_d, I_q, fp
                    )
                    if delay == 0:
                        d_a, d_b, d_c = n_a, n_b, n_c
                    elif delay == 1:
                        d_a, d_b, d_c = q1_a, q1_b, q1_c
                        q1_a, q1_b, q1_c = n_a, n_b, n_c
                    else:
                        d_a, d_b, d_c = q2_a, q2_b, q2_c
                        q2_a, q2_b, q2_c = q1_a, q1_b, q1_c
                        q1_a, q1_b, q1_c = n_a, n_b, n_c
                    t_window = next_update
                    n_update += 1
                    next_update = fp.t_first + n_update * fp.T_u
                    if fp.double != 0.0:
                        peak = not peak
                    nl_a, nh_a = window(d_a, peak, fp)
                    nl_b, nh_b = window(d_b, peak, fp)
                    nl_c, nh_c = window(d_c, peak, fp)
                    ce_a, ck_a = carried(wl_a, wh_a, nl_a, nh_a, fp)
                    ce_b, ck_b = carried(wl_b, wh_b, nl_b, nh_b, fp)
                    ce_c, ck_c = carried(wl_c, wh_c, nl_c, nh_c, fp)
                    wl_a, wh_a, wl_b, wh_b, wl_c, wh_c = nl_a, nh_a, nl_b, nh_b, nl_c, nh_c
                tau_w = t_now - t_window
                s_a = leg_state(tau_w, dt, wl_a, wh_a, ce_a, ck_a, i_a, fp)
                s_b = leg_state(tau_w, dt, wl_b, wh_b, ce_b, ck_b, i_b, fp)
                s_c = leg_state(tau_w, dt, wl_c, wh_c, ce_c, ck_c, -(i_a + i_b), fp)
                vs_a = V_aa * s_a + V_ab * s_b + V_ac * s_c
                vs_b = V_ba * s_a + V_bb * s_b + V_bc * s_c
                n_step += 1
                if n_sub == 1:
                    i_a, i_b = (
                        (A_aa * i_a + A_ab * i_b + vs_a) + be_a,
                        (A_ba * i_a + A_bb * i_b + vs_b) + be_b,
                    )
                    T_m = g_ac * i_a + g_bc * i_b
                else:
                    T_sum = 0.0
                    bv_a = vs_a + be_a  # the step's volt-seconds spread evenly over its sub-steps
                    bv_b = vs_b + be_b
                    for _ in range(n_sub):
                        i_a, i_b = (
                            (A_aa * i_a + A_ab * i_b) + bv_a,
                            (A_ba * i_a + A_bb * i_b) + bv_b,
                        )
                        T_sum += g_ac * i_a + g_bc * i_b
                    T_m = T_sum * inv_sub
            elif n_sub == 1:
                s_a, s_b, s_c, switched = _comparators(
                    i_a, i_b, -(i_a + i_b), s_a, s_b, s_c, lo_a, lo_b, lo_c, hi_a, hi_b, hi_c
                )
                if switched:
                    vs_a = V_aa * s_a + V_ab * s_b + V_ac * s_c
                    vs_b = V_ba * s_a + V_bb * s_b + V_bc * s_c
                i_a, i_b = (
                    (A_aa * i_a + A_ab * i_b + vs_a) + be_a,
                    (A_ba * i_a + A_bb * i_b + vs_b) + be_b,
                )
                T_m = g_ac * i_a + g_bc * i_b
            else:
                T_sum = 0.0
                bv_a = vs_a + be_a  # V·s + β, constant between switches
                bv_b = vs_b + be_b
                for _ in range(n_sub):
                    s_a, s_b, s_c, switched = _comparators(
                        i_a, i_b, -(i_a + i_b), s_a, s_b, s_c, lo_a, lo_b, lo_c, hi_a, hi_b, hi_c
                    )
                    if switched:
                        vs_a = V_aa * s_a + V_ab * s_b + V_ac * s_c
                        vs_b = V_ba * s_a + V_bb * s_b + V_bc * s_c
                        bv_a = vs_a + be_a
                        bv_b = vs_b + be_b
                    i_a, i_b = (
                        (A_aa * i_a + A_ab * i_b) + bv_a,
                        (A_ba * i_a + A_bb * i_b) + bv_b,
                    )
                    T_sum += g_ac * i_a + g_bc * i_b
                T_m = T_sum * inv_sub  # torque averaged over the sub-steps
            # oversampled outputs: currents and Clarke–Park i_q at the end of the step, with the
            # angle of the step (DESIGN §3.9, transforms.clarke with i_c = −(i_a + i_b):
            # i_α = i_a, i_β = (i_a + 2·i_b)/√3, so i_q = w_a·i_a + w_b·i_b)
            acc_a += i_a
            acc_b += i_b
            acc_q += w_a * i_a + w_b * i_b
            acc_T += T_m

            # ---- mechanics (mechanics.mechanics_step, DESIGN §3.8) ---------------------------
            # Borello's dry friction (mechanics.friction_step): stuck, break-away, sliding, stop.
            # eps = p·Δt·ω_new − δ: the change of the electrical angle step, for the rotation below
            if omega_m == 0.0:
                T_act = T_m - T_load_m
                if abs(T_act) <= F_S:
                    omega_new = 0.0
                else:
                    sgn = 1.0 if T_act > 0.0 else -1.0
                    omega_new = dt_J * (T_act - F_D * sgn)
                eps = p_dt * omega_new - delta
            else:
                sgn = 1.0 if omega_m > 0.0 else -1.0
                # ω + Δt·(T_m − T_load/(τη) − C·ω − F_D·sign ω)/J, the part without T_m first
                omega_free = omega_m - dt_J * (T_load_m + (visc * omega_m + F_D * sgn))
                omega_new = omega_free + dt_J * T_m
                eps = (p_dt * omega_free - delta) + p_dt_J * T_m
                if omega_new * sgn <= 0.0:
                    omega_new = 0.0
                    eps = -delta
            omega_m = omega_new
            theta_m += dt * omega_m
            # backlash (mechanics.backlash): the user side is dragged by the flank in contact
            theta_g = theta_m * inv_tau
            if theta_u < theta_g - half_B:
                theta_u = theta_g - half_B
            elif theta_u > theta_g + half_B:
                theta_u = theta_g + half_B
            # inelastic end-stops on the user side; θ_m jumps, so the angle is taken afresh
            stop = False
            if theta_u > theta_max:
                theta_u = theta_max
                theta_m = theta_m_stop
                if omega_m > 0.0:
                    omega_m = 0.0
                stop = True
            elif theta_u < -theta_max:
                theta_u = -theta_max
                theta_m = -theta_m_stop
                if omega_m < 0.0:
                    omega_m = 0.0
                stop = True

            # ---- θ_e = p·θ_m for the next step: rotate (sin θ_e, cos θ_e) by p·Δt·ω_new = δ + eps,
            # first by the previous angle step δ (sin δ and cos δ − 1 known from the last step),
            # then by the small change eps to second order (sin eps ≈ eps, cos eps ≈ 1 − eps²/2)
            if stop or abs(eps) > EPS_MAX or abs(delta) > ROTATION_MAX:
                sin_e = math.sin(p * theta_m)
                cos_e = math.cos(p * theta_m)
            else:
                sin_1 = sin_e + (sin_e * cos_d_m1 + cos_e * sin_d)
                cos_1 = cos_e + (cos_e * cos_d_m1 - sin_e * sin_d)
                half_sin_1 = 0.5 * sin_1
                half_cos_1 = 0.5 * cos_1
                sin_e = sin_1 + (eps * cos_1 - eps * (eps * half_sin_1))
                cos_e = cos_1 - (eps * sin_1 + eps * (eps * half_cos_1))
            delta = p_dt * omega_m  # the next step's δ, its sine and cosine − 1 by Taylor series
            d2 = delta * delta
            sin_d = delta + delta * d2 * (s3 + d2 * s5)
            cos_d_m1 = d2 * (c2 + d2 * c4)
