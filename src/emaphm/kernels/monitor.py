"""Low-fidelity (LF) monitor model (paper §4.2, DESIGN §4): equivalent single-phase motor.

Same command, same PID (`controller.pid_step`) and same drive train (`mechanics.mechanics_step`)
as the HF twin; the three-phase stator and inverter are replaced by one equivalent RL circuit

    L_eq·di/dt = u − R_eq·φ_R·i − k_e,eq·φ_E·ω_m,      T_m = k_t,eq·φ_T·i

with a simplified current loop (a first-order lag of time constant τ_i towards i_q,ref, limited by
the available voltage ±U_max) and the paper's two shape functions of the electrical angle:

    φ_SC  = k_FT·{N_A[1 + k_FS·sin²(θ_e + π)] + N_B[1 + k_FS·sin²(θ_e + π/3)] + N_C[1 + k_FS·sin²(θ_e − π/3)]}   (eq. 1)
    φ_ECC = 1 − k_E·ζ·cos(θ_e + φ_e)                                                                      (eq. 2)
    φ_R = φ_SC,   φ_E = φ_T = φ_SC·φ_ECC                        (DESIGN §4.3; the paper's monitor)

The default monitor takes φ_E = φ_T from the eccentric flux linkage phase by phase (`phi_t`,
the twin's coupling g_x of `pmsm_abc.couplings` with k_E·ζ for ζ), which equals φ_SC·φ_ECC for a
balanced winding and differs where shorts and eccentricity meet (monitor-model.md §1).

One simulation is one row of parameters (`LF_FIELDS`), so a whole GA generation is one call of
`simulate_lf_many` (prange over rows), bit-identical to row-by-row `simulate_lf`. A step is a
chain of dependent operations whose latency sets its time, so two rows run interleaved in one
loop (`simulate_lf2`, each row's operations unchanged): 96 runs took 63-71 ms on one thread of
machine E against 82-88 ms one after the other (issue 36).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from ._jit import jit
from .controller import ControllerPack, pid_step
from .mechanics import MechanicsPack, mechanics_step
from .pmsm_abc import GAMMA
from .sensors import quantise
from .transforms import phase_directions

# the layout of one row of LF parameters (SI)
LF_FIELDS = (
    # faults applied (DESIGN §2)
    "F_S", "F_D", "B", "N_A", "N_B", "N_C", "zeta", "phi_e", "K_P",
    # drive train and controller, as the HF twin
    "J", "C", "tau", "eta", "theta_max", "T_load", "K_I", "K_D", "tau_D", "I_max", "T_s",
    # position ADC [rad]
    "lsb_theta", "fs_theta",
    # equivalent motor and calibration coefficients
    "p", "k_FT", "k_FS", "k_E", "k_t_eq", "k_e_eq", "R_eq", "L_eq", "tau_i", "U_max",
    # 1: φ_T from the eccentric flux linkage phase by phase (`phi_t`); 0: the paper's φ_SC·φ_ECC
    "ecc_coupling",
    # current-loop surrogate of the three-phase hysteresis loop's error (calibrated)
    "k_H", "delta_0", "delta_1", "delta_u", "delta_2", "V_H",
    # the loop's current ripple at a breakaway (calibrated; `mechanics.friction_step`) and its
    # dead zone at standstill (calibrated; `standstill_dead_zone`)
    "i_R", "i_D",
    # LF steps per sample period
    "n_lf",
    # the drive's current loop: 0 the hysteresis loop (the lag τ_i above), 1 an FOC drive's q-axis PI
    # (`foc_loop_step`): its gains, updates per LF step, computation delay [updates], back-EMF
    # feed-forward constant (0: none) and voltage limit
    "foc", "K_p_i", "K_i_i", "n_u", "delay", "k_e_ff", "V_lim",
)  # fmt: skip
IDX = {name: j for j, name in enumerate(LF_FIELDS)}
N_FIELDS = len(LF_FIELDS)

AUX_COLUMNS = ("theta_u", "theta_m", "omega_m", "theta_e", "i_q_ref", "T_m")
N_AUX = len(AUX_COLUMNS)
# no auxiliary output (`simulate_lf`'s aux with no rows), made here and passed in: a kernel that
# allocates it loads with numba's array module (kernels.fitness, STACK_SIZE's note)
NO_AUX = np.empty((0, N_AUX))

(F_S, F_D, B, N_A, N_B, N_C, ZETA, PHI_E, K_P, J, C, TAU, ETA, THETA_MAX, T_LOAD, K_I, K_D, TAU_D, I_MAX, T_S,
 LSB_THETA, FS_THETA, P, K_FT, K_FS, K_E, K_T_EQ, K_E_EQ, R_EQ, L_EQ, TAU_I, U_MAX, ECC_COUPLING,
 K_H, DELTA_0, DELTA_1, DELTA_U, DELTA_2, V_H, I_R, I_D, N_LF,
 FOC, K_P_I, K_I_I, N_U, DELAY, K_E_FF, V_LIM) = range(N_FIELDS)  # fmt: skip


@jit
def phi_sc(sin_e, cos_e, N_a, N_b, N_c, k_FT, k_FS):  # type: ignore[no-untyped-def]
    """Short-circuit shape function, paper eq. (1)."""
    u_a, u_b, u_c = phase_directions(sin_e, cos_e)  # u_x² = sin²(θ_e + π), sin²(θ_e + π/3), sin²(θ_e − π/3)
    return k_FT * (
        N_a * (1.0 + k_FS * u_a * u_a) + N_b * (1.0 + k_FS * u_b * u_b) + N_c * (1.0 + k_FS * u_c * u_c)
    )


@jit
def phi_ecc(sin_e, cos_e, kz_cos, kz_sin):  # type: ignore[no-untyped-def]
    """Eccentricity shape function, paper eq. (2), cos(θ_e + φ_e) expanded.

    kz_cos = k_E·ζ·cos φ_e and kz_sin = k_E·ζ·sin φ_e are constant over a run.
    """
    return 1.0 - (cos_e * kz_cos - sin_e * kz_sin)


@jit
def phi_t(sin_e, cos_e, N_a, N_b, N_c, k_FT, k_FS, f_ecc, e2):  # type: ignore[no-untyped-def]
    """Torque and back-EMF shape φ_T = φ_E from the eccentric flux linkage, phase by phase:

        φ_T = k_FT·Σ_x N_x·[φ_ECC + k_FS·u_x·(u_x + k_E·ζ·sin(2θ_e + φ_e − γ_x))]

    u_x + ζ·sin(2θ_e + φ_e − γ_x) is the twin's coupling g_x/k_e,x of phase x (`pmsm_abc.couplings`,
    ∂ψ_x/∂θ of ψ_x ∝ N_x·[1 − ζ·cos(θ_e + φ_e)]·cos(θ_e − γ_x)), and u_x its current direction
    (i_x = i_q·u_x), so the k_FS part is the twin's torque per unit i_q with ζ → k_E·ζ; the
    constant part follows φ_ECC as in eq. 1 × eq. 2. With equal N_x this is φ_SC·φ_ECC; with
    unequal ones it has the twin's 3θ_e term ∝ ζ·Σ_x (1 − N_x)·cos(3θ_e + φ_e − 2γ_x), where
    φ_SC·φ_ECC has half of it and a 1θ_e term at θ_e − φ_e − 2γ_x that no flux linkage gives.

    e2 = (a_A, a_B, a_C, b_A, b_B, b_C) with a_x = k_E·ζ·cos(φ_e − γ_x), b_x = k_E·ζ·sin(φ_e − γ_x),
    constant over a run (`pmsm_abc.ecc_harmonics` of k_E·ζ, the twin's own of ζ):
    k_E·ζ·sin(2θ_e + φ_e − γ_x) = a_x·sin 2θ_e + b_x·cos 2θ_e.
    """
    u_a, u_b, u_c = phase_directions(sin_e, cos_e)
    sin_2e = 2.0 * sin_e * cos_e
    cos_2e = cos_e * cos_e - sin_e * sin_e
    return k_FT * (
        N_a * (f_ecc + k_FS * u_a * (u_a + e2[0] * sin_2e + e2[3] * cos_2e))
        + N_b * (f_ecc + k_FS * u_b * (u_b + e2[1] * sin_2e + e2[4] * cos_2e))
        + N_c * (f_ecc + k_FS * u_c * (u_c + e2[2] * sin_2e + e2[5] * cos_2e))
    )


@jit
def unbalance_2(sin_e, cos_e, N_a, N_b, N_c):  # type: ignore[no-untyped-def]
    """c₂ = Σ_x (1 − N_x)·cos(2θ_e − 2γ_x): the 2θ_e pattern of the lost turns (0 when balanced).

    cos(2θ_e − 2γ_x) = 1 − 2u_x² with u_x the phase directions of `transforms.phase_directions`.
    """
    u_a, u_b, u_c = phase_directions(sin_e, cos_e)
    return (
        (1.0 - N_a) * (1.0 - 2.0 * u_a * u_a)
        + (1.0 - N_b) * (1.0 - 2.0 * u_b * u_b)
        + (1.0 - N_c) * (1.0 - 2.0 * u_c * u_c)
    )


@jit
def shape_harmonics(N_a, N_b, N_c, k_FT, k_FS, kz, phi_e):  # type: ignore[no-untyped-def]
    """The run's constants of φ_SC (eq. 1), φ_T (`phi_t`) and c₂ (`unbalance_2`) written as trig
    polynomials of θ_e, which `shapes` evaluates at each step (kz = k_E·ζ):

        φ_SC = P0 + P2c·cos 2θ_e + P2s·sin 2θ_e
        φ_T  = φ_SC + Q1c·cos θ_e + Q1s·sin θ_e + Q3c·cos 3θ_e + Q3s·sin 3θ_e
        c₂   = U_c·cos 2θ_e + U_s·sin 2θ_e

    From u_x² = [1 − cos(2θ_e − 2γ_x)]/2 and u_x·kz·sin(2θ_e + φ_e − γ_x) =
    −(kz/2)·[cos(θ_e + φ_e) − cos(3θ_e + φ_e − 2γ_x)] (u_x = −sin(θ_e − γ_x)), with S = Σ_x N_x:
    P0 = k_FT·S·(1 + k_FS/2); P2c, P2s = −(k_FT·k_FS/2)·Σ_x N_x·(cos 2γ_x, sin 2γ_x);
    U_c, U_s = Σ_x (1 − N_x)·(cos 2γ_x, sin 2γ_x); Q1c, Q1s = k_FT·S·kz·(1 + k_FS/2)·(−cos φ_e, sin φ_e);
    Q3c, Q3s = (k_FT·k_FS·kz/2)·Σ_x N_x·(cos(φ_e − 2γ_x), −sin(φ_e − 2γ_x)). The same functions to
    rounding (tests/kernels/test_monitor.py), in a third of the step's operations: one monitor run
    0.349 -> 0.316 ms, an interleaved pair 0.643 -> 0.541 ms on machine G (issue 36)."""
    c2g = (math.cos(2.0 * GAMMA[0]), math.cos(2.0 * GAMMA[1]), math.cos(2.0 * GAMMA[2]))
    s2g = (math.sin(2.0 * GAMMA[0]), math.sin(2.0 * GAMMA[1]), math.sin(2.0 * GAMMA[2]))
    n_sum = N_a + N_b + N_c
    half = 0.5 * k_FT * k_FS
    P0 = k_FT * n_sum * (1.0 + 0.5 * k_FS)
    P2c = -half * (N_a * c2g[0] + N_b * c2g[1] + N_c * c2g[2])
    P2s = -half * (N_a * s2g[0] + N_b * s2g[1] + N_c * s2g[2])
    U_c = (1.0 - N_a) * c2g[0] + (1.0 - N_b) * c2g[1] + (1.0 - N_c) * c2g[2]
    U_s = (1.0 - N_a) * s2g[0] + (1.0 - N_b) * s2g[1] + (1.0 - N_c) * s2g[2]
    q1 = k_FT * n_sum * kz * (1.0 + 0.5 * k_FS)
    q3 = half * kz
    Q3c = q3 * (N_a * math.cos(phi_e - 2.0 * GAMMA[0]) + N_b * math.cos(phi_e - 2.0 * GAMMA[1])
                + N_c * math.cos(phi_e - 2.0 * GAMMA[2]))  # fmt: skip
    Q3s = -q3 * (N_a * math.sin(phi_e - 2.0 * GAMMA[0]) + N_b * math.sin(phi_e - 2.0 * GAMMA[1])
                 + N_c * math.sin(phi_e - 2.0 * GAMMA[2]))  # fmt: skip
    return (P0, P2c, P2s, U_c, U_s, -q1 * math.cos(phi_e), q1 * math.sin(phi_e), Q3c, Q3s)


@jit(inline=True)
def shapes(sin_e, cos_e, hz, per_phase, kz_cos, kz_sin):  # type: ignore[no-untyped-def]
    """(φ_SC, φ_T, c₂) at θ_e from the run's `shape_harmonics` hz: φ_T as `phi_t` (per_phase), else
    the paper's φ_SC·φ_ECC (eq. 2 with kz_cos, kz_sin of `phi_ecc`)."""
    P0, P2c, P2s, U_c, U_s, Q1c, Q1s, Q3c, Q3s = hz
    sin_2e = 2.0 * sin_e * cos_e
    cos_2e = (cos_e - sin_e) * (cos_e + sin_e)
    f_sc = P0 + (P2c * cos_2e + P2s * sin_2e)
    if per_phase:
        sin_3e = sin_2e * cos_e + cos_2e * sin_e
        cos_3e = cos_2e * cos_e - sin_2e * sin_e
        f_t = f_sc + ((Q1c * cos_e + Q1s * sin_e) + (Q3c * cos_3e + Q3s * sin_3e))
    else:
        f_t = f_sc * phi_ecc(sin_e, cos_e, kz_cos, kz_sin)
    return f_sc, f_t, U_c * cos_2e + U_s * sin_2e


@jit
def unbalance(N_a, N_b, N_c):  # type: ignore[no-untyped-def]
    """|U|, U = Σ_x (1 − N_x)·e^(j2γ_x): the amplitude of c₂ (0 for equal shorts in all three phases).

    |U|² = Σ a_x² − (a_A·a_B + a_B·a_C + a_C·a_A) with a_x = 1 − N_x, since cos(±4π/3) = −1/2.
    """
    a, b, c = 1.0 - N_a, 1.0 - N_b, 1.0 - N_c
    return math.sqrt(max(a * a + b * b + c * c - a * b - b * c - c * a, 0.0))


@jit
def loop_error(i, omega_m, c2, offset_0, k_H, delta_2, R_eq, k_e_eq, V_H):  # type: ignore[no-untyped-def]
    """The current the motor carries and the sensors measure, given the loop state i (monitor-model.md §1):

        i_m = i·(1 + k_H·c₂) − (δ_H + δ_2·c₂)·tanh((R_eq·i + k_e,eq·ω_m)/V_H)
        δ_H = δ_0 + δ_1·Σ_x (1 − N_x) + δ_U·|U|        (offset_0, constant over a run)

    A calibrated surrogate of the three-phase hysteresis loop's own error: a 2θ_e ripple in step
    with the shorted phases, and an offset that opposes the q-axis voltage the inverter must
    supply (R_eq·i at standstill, where the delivered current falls short of the demand; the
    back-EMF k_e,eq·ω_m in motion, where it trails the rotation). It grows with the turns lost
    and with their unbalance between the phases (`unbalance`).
    """
    offset = offset_0 + delta_2 * c2
    return i * (1.0 + k_H * c2) - offset * saturated_tanh((R_eq * i + k_e_eq * omega_m) / V_H)


# tanh x is ±1 to the last bit beyond this (1 − tanh 22 ≈ 1.6e-19, below half an ulp of 1; glibc's
# tanh returns ±1 there itself). The loop's surrogate is mostly there (|x| > 22 once the voltage
# passes 22·V_H, about 0.1 V), and a step without the library call keeps its values in registers:
# a monitor run's interleaved pair 0.554 -> 0.529 ms on machine G, the same currents to the bit
TANH_SATURATED = 22.0


@jit(inline=True)
def saturated_tanh(x):  # type: ignore[no-untyped-def]
    """math.tanh(x), without the call where it is ±1 (`TANH_SATURATED`)."""
    if x > TANH_SATURATED:
        return 1.0
    if x < -TANH_SATURATED:
        return -1.0
    return math.tanh(x)


@jit
def current_loop_step(i, i_ref, omega_m, phi_R, phi_E, decay, g, R_eq, k_e_eq, U_max):  # type: ignore[no-untyped-def]
    """Equivalent current after one step: a first-order lag towards i_ref, within the voltage ±U_max.

    The lag (decay = exp(−dt/τ_i)) stands for the fast hysteresis loop. The voltage it needs,
    u = L_eq·Δi/dt + R_eq·φ_R·i + k_e,eq·φ_E·ω_m, must stay within ±U_max, which bounds the step
    to (±U_max − R_eq·φ_R·i − k_e,eq·φ_E·ω_m)·g with g = dt/L_eq [A/V] (explicit Euler).
    """
    drop = R_eq * phi_R * i + k_e_eq * phi_E * omega_m
    di = (i_ref - i) * (1.0 - decay)
    di_max = (U_max - drop) * g
    di_min = (-U_max - drop) * g
    if di > di_max:
        di = di_max
    elif di < di_min:
        di = di_min
    return i + di


@jit
def foc_loop_step(i, I_q, v_1, v_2, i_ref, omega_m, phi_R, phi_E, h_u, fq):  # type: ignore[no-untyped-def]
    """The q axis of an FOC drive over one LF step, in n_u PI updates of h_u each (kernels/foc.py):

        v = K_p·(i_ref − i) + I_q + k_e,ff·ω_m,   limited to ±V_lim (I_q held while limited),
        I_q += K_i·h_u·(i_ref − i),
        L_eq·di/dt = u − R_eq·φ_R·i − k_e,eq·φ_E·ω_m,   u: the v computed `delay` updates earlier.

    The PI sees the equivalent current, the plant is the monitor's equivalent circuit with its
    shape functions, so the part of the back-EMF the nameplate feed-forward does not cancel (the
    lost turns' 2θ_e ripple, the eccentricity) drives a current error through the loop's finite
    stiffness, as the twin's PI lets it through. fq: `foc_pack` of the row. Returns (i, I_q, v_1,
    v_2, mean of i over the step).
    """
    L_eq, k_e_eq, R_eq, k_e_ff, delay, n_u_f, K_p_i, K_i_i, V_lim = fq
    g = h_u / L_eq
    drop_e = k_e_eq * phi_E * omega_m
    r = R_eq * phi_R
    ff = k_e_ff * omega_m
    n_u = int(n_u_f)
    acc = 0.0
    for _ in range(n_u):
        e = i_ref - i
        v = K_p_i * e + I_q + ff
        if v > V_lim:
            v = V_lim
        elif v < -V_lim:
            v = -V_lim
        else:
            I_q += K_i_i * h_u * e
        if delay == 0.0:
            u = v
        elif delay == 1.0:
            u = v_1
            v_1 = v
        else:
            u = v_2
            v_2 = v_1
            v_1 = v
        i_new = i + g * (u - r * i - drop_e)
        acc += 0.5 * (i + i_new)  # the mean over the update period (trapezoid)
        i = i_new
    return i, I_q, v_1, v_2, acc / n_u


# Where exactly one zero vector holds (`standstill_dead_zone`), whether the twin's loop is at rest
# depends on its legs' switching state, which the monitor does not carry: on a locked rotor under the
# twin's own comparators it was at rest in 0.514 ± 0.018 of 800 trials coming from a running loop and
# 0.500 ± 0.018 coming from rest (on either zero vector), against 1.000 where both hold and < 0.01
# where none does (`python studies/loop_rest_study.py`). There the monitor carries the expected
# current, 1 − P(rest) ≈ 0.5 of the demand: least squares' best guess of a current that is either
# the demand or nothing, at even odds.
MAY_REST_CARRY = 0.5

# No zero vector holds beyond |i_q,ref| = RING_OUTER · i_D at any angle: one holds while
# |i_q,ref| · min(max_x u_x, −min_x u_x) < i_D (`standstill_dead_zone`), and that min is smallest,
# 1/2, where one phase direction is ±1 and the other two ∓1/2. `weights.moving_mask` leaves out the
# rests whose measured current is below this edge: there the twin's current is a coin flip.
RING_OUTER = 2.0


@jit
def standstill_dead_zone(i_q_ref, omega_m, sin_e, cos_e, i_D):  # type: ignore[no-untyped-def]
    """The fraction of the demand i_q,ref the hysteresis loop carries: 0 where it rests on a zero
    vector at standstill, 1 where it runs, `MAY_REST_CARRY` where it may do either
    (monitor-model.md §1).

    The twin's comparators switch a leg only when its phase current leaves the band
    i_x,ref ± h/2 on the far side: an upper leg down once i_x > i_x,ref + h/2, a lower one up once
    i_x < i_x,ref − h/2. With the motor stuck (ω_m = 0: no back-EMF) an inverter on a zero vector
    lets the currents decay to zero through the windings, so all legs up hold while
    min_x i_x,ref > −h/2 and all legs down while max_x i_x,ref < h/2, whatever the demand does
    inside that; i_D is that half-band seen by the monitor (h/2 in the twin; calibrated). Where
    both hold (the demand inside every band) the loop is at rest; where neither does, it runs;
    where only one does, it is at rest if it sits on that one, even odds whether it came from rest
    or from running.
    """
    if omega_m != 0.0 or not i_D > 0.0:
        return 1.0
    u_a, u_b, u_c = phase_directions(sin_e, cos_e)
    top = i_q_ref * max(u_a, u_b, u_c)  # max_x i_x,ref (with a negative demand: min_x)
    bottom = i_q_ref * min(u_a, u_b, u_c)
    up = min(top, bottom) > -i_D  # all legs up hold
    down = max(top, bottom) < i_D  # all legs down hold
    if up and down:
        return 0.0
    if up or down:
        return MAY_REST_CARRY
    return 1.0


# The step reads its parameters from tuples of floats taken from the row once (`step_pack`,
# `foc_pack`), not from the row itself: an array the inlined step indexes made numba keep it alive
# across the step's branches by a reference count taken and dropped at every step, two atomic
# operations in the step's chain (one run 0.42 -> 0.36 ms on machine G, the currents the same to
# the bit; issue 36, eighteenth session).


@jit
def foc_pack(prm):  # type: ignore[no-untyped-def]
    """`foc_loop_step`'s constants from a parameter row: (L_eq, k_e,eq, R_eq, k_e,ff, delay, n_u,
    K_p, K_i, V_lim)."""
    return (prm[L_EQ], prm[K_E_EQ], prm[R_EQ], prm[K_E_FF], prm[DELAY], prm[N_U], prm[K_P_I], prm[K_I_I], prm[V_LIM])


@jit
def step_pack(prm):  # type: ignore[no-untyped-def]
    """The row's values `lf_substep` reads: (k_t,eq, i_D, R_eq, k_e,eq, U_max, k_H, δ_2, V_H, i_R)."""
    return (prm[K_T_EQ], prm[I_D], prm[R_EQ], prm[K_E_EQ], prm[U_MAX], prm[K_H], prm[DELTA_2], prm[V_H], prm[I_R])


@jit(inline=True)
def lf_constants(prm):  # type: ignore[no-untyped-def]
    """What `simulate_lf` derives once from a parameter row `prm` (layout `LF_FIELDS`), constant
    over the run: (controller pack, mechanics pack, n_lf, dt, decay, decay_rl, g, p, offset_0,
    kz_cos, kz_sin, per_phase, `shape_harmonics`, foc, h_u, `step_pack`, `foc_pack`)."""
    cp = ControllerPack(prm[K_P], prm[K_I], prm[K_D], prm[TAU_D], prm[I_MAX], prm[T_S], prm[TAU])
    mp = MechanicsPack(
        prm[J], prm[C], prm[F_S], prm[F_D], prm[B], prm[TAU], prm[ETA], prm[THETA_MAX], prm[T_LOAD]
    )
    n_lf = int(prm[N_LF])
    dt = prm[T_S] / n_lf
    decay = math.exp(-dt / prm[TAU_I])
    decay_rl = math.exp(-dt * prm[R_EQ] / prm[L_EQ])  # the windings' own decay, in the dead zone
    g = dt / prm[L_EQ]
    # the loop's offset δ_H = δ_0 + δ_1·Σ_x (1 − N_x) + δ_U·|U|
    offset_0 = (
        prm[DELTA_0]
        + prm[DELTA_1] * (3.0 - prm[N_A] - prm[N_B] - prm[N_C])
        + prm[DELTA_U] * unbalance(prm[N_A], prm[N_B], prm[N_C])
    )
    kz_cos = prm[K_E] * prm[ZETA] * math.cos(prm[PHI_E])
    kz_sin = prm[K_E] * prm[ZETA] * math.sin(prm[PHI_E])
    per_phase = prm[ECC_COUPLING] != 0.0
    hz = shape_harmonics(prm[N_A], prm[N_B], prm[N_C], prm[K_FT], prm[K_FS], prm[K_E] * prm[ZETA], prm[PHI_E])
    foc = prm[FOC] != 0.0
    h_u = dt / prm[N_U] if foc else 0.0
    return (cp, mp, n_lf, dt, decay, decay_rl, g, prm[P], offset_0, kz_cos, kz_sin, per_phase, hz, foc, h_u,
            step_pack(prm), foc_pack(prm))


# The electrical angle's sine and cosine are carried from step to step and rotated through the
# step's angle d = p·(θ_m,new − θ_m) (`advance_angle`), instead of libm's sin and cos at every step
# (with the drive train's divisions hoisted, a run 25-29 % faster: `studies/step_timings.py` item 6,
# issue 36, fifteenth session). The series below are exact to rounding up to ROTATION_MAX (the first
# terms left out, d¹³/13! and d¹⁴/14!, are below 2e-18 there); a larger turn (an end-stop's jump)
# and every ANGLE_RESYNC-th step take libm's values afresh, so rounding cannot accumulate.
ROTATION_MAX = 0.2
ANGLE_RESYNC = 32
# Taylor coefficients of sin d and cos d − 1
S3, S5, S7, S9, S11 = -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0, -1.0 / 39916800.0
C2, C4, C6, C8, C10, C12 = -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0, -1.0 / 3628800.0, 1.0 / 479001600.0


@jit(inline=True)
def advance_angle(sin_e, cos_e, n_rot, p, theta_m, theta_new):  # type: ignore[no-untyped-def]
    """(sin θ_e, cos θ_e, steps since libm) after θ_m moved to theta_new: rotated through
    d = p·(theta_new − θ_m) by Taylor series (sin d to d¹¹, cos d − 1 to d¹²), or taken from libm
    every `ANGLE_RESYNC` steps and when |d| > `ROTATION_MAX`."""
    d = p * (theta_new - theta_m)
    n_rot += 1
    if n_rot >= ANGLE_RESYNC or abs(d) > ROTATION_MAX:
        theta_e = p * theta_new
        return math.sin(theta_e), math.cos(theta_e), 0
    d2 = d * d
    sin_d = d * (1.0 + d2 * (S3 + d2 * (S5 + d2 * (S7 + d2 * (S9 + d2 * S11)))))
    cos_d_m1 = d2 * (C2 + d2 * (C4 + d2 * (C6 + d2 * (C8 + d2 * (C10 + d2 * C12)))))
    return sin_e + (sin_e * cos_d_m1 + cos_e * sin_d), cos_e + (cos_e * cos_d_m1 - sin_e * sin_d), n_rot


@jit(inline=True)
def lf_substep(theta_m, omega_m, theta_u, i, I_q, v_1, v_2, i_q_ref, c, sin_e, cos_e, n_rot):  # type: ignore[no-untyped-def]
    """One LF step of dt (`simulate_lf`'s inner loop) from the state (θ_m, ω_m, θ_u, the loop's
    current i, the FOC loop's I_q, v_1, v_2, and sin θ_e, cos θ_e with the steps since they were
    libm's: `advance_angle`) under the held demand i_q_ref; c = `lf_constants`(prm). Returns the
    new state and the step's i_m and T_m (which `simulate_lf` averages)."""
    _, mp, _, dt, decay, decay_rl, g, p, offset_0, kz_cos, kz_sin, per_phase, hz, foc, h_u, q, fq = c
    k_t_eq, i_D, R_eq, k_e_eq, U_max, k_H, delta_2, V_H, i_R = q
    f_sc, f_t, c2 = shapes(sin_e, cos_e, hz, per_phase, kz_cos, kz_sin)
    k_t = k_t_eq * f_t  # the torque constant k_t,eq·φ_T (φ_T = φ_E)
    carry = standstill_dead_zone(i_q_ref, omega_m, sin_e, cos_e, i_D)
    if foc:
        i, I_q, v_1, v_2, i_loop = foc_loop_step(i, I_q, v_1, v_2, carry * i_q_ref, omega_m, f_sc, f_t, h_u, fq)
    else:
        if carry == 0.0:
            i *= decay_rl  # a zero vector: the current decays through R_eq, L_eq
        else:
            i = current_loop_step(
                i, carry * i_q_ref, omega_m, f_sc, f_t, decay, g, R_eq, k_e_eq, U_max
            )
        i_loop = i  # the loop's current over the step: its end value (hysteresis), its mean (FOC)
    # the current the motor carries and the sensors measure: the loop's surrogate error on top
    i_m = loop_error(i_loop, omega_m, c2, offset_0, k_H, delta_2, R_eq, k_e_eq, V_H)
    T_m = k_t * i_m
    # the hysteresis loop's ripple about i_m, which this step averages away, breaks a stuck
    # motor away at its peak: T_ripple = k_t,eq·φ_T·i_R (monitor-model.md §1)
    T_r = abs(k_t) * i_R
    theta_new, omega_m, theta_u = mechanics_step(theta_m, omega_m, theta_u, T_m, dt, mp, T_r)
    sin_e, cos_e, n_rot = advance_angle(sin_e, cos_e, n_rot, p, theta_m, theta_new)
    return theta_new, omega_m, theta_u, i, I_q, v_1, v_2, i_m, T_m, sin_e, cos_e, n_rot


@jit
def simulate_lf(theta_cmd, prm, i_out, aux):  # type: ignore[no-untyped-def]
    """Run the LF model for one parameter row `prm` (layout `LF_FIELDS`).

    Writes i_out[k], the equivalent current averaged over the sample period ending at t_k (the
    HF i_q convention), and, when aux has rows, the `AUX_COLUMNS` at t_k.

    The loop state i follows the demand (first-order lag), or, at standstill, the fraction of it
    the loop carries (`standstill_dead_zone`: none inside every phase's band, where the state
    decays through the windings; half in the ring where only one zero vector holds); the motor
    carries, and the sensors measure, i_m = `loop_error`(i, …): the calibrated surrogate of the
    three-phase hysteresis loop's own error, which grows with the phase unbalance
    (monitor-model.md §1). Each step is `lf_substep`.
    """
    n = theta_cmd.shape[0]
    record = aux.shape[0] > 0
    c = lf_constants(prm)
    cp, n_lf, p = c[0], c[2], c[7]
    I_q = v_1 = v_2 = 0.0  # the FOC loop's integrator and its queued voltages
    theta_m = omega_m = theta_u = 0.0
    i = integral = omega_f = 0.0
    acc_i = acc_T = 0.0
    sin_e, cos_e, n_rot = 0.0, 1.0, 0  # θ_e = 0 at rest
    for k in range(n):
        theta_meas = quantise(theta_u, prm[LSB_THETA], prm[FS_THETA])
        i_q_ref, integral, omega_f = pid_step(theta_cmd[k], theta_meas, omega_m, integral, omega_f, cp)
        i_out[k] = acc_i / n_lf
        if record:
            aux[k, 0] = theta_u
            aux[k, 1] = theta_m
            aux[k, 2] = omega_m
            aux[k, 3] = p * theta_m
            aux[k, 4] = i_q_ref
            aux[k, 5] = acc_T / n_lf
        if k == n - 1:
            break
        acc_i = 0.0
        acc_T = 0.0
        for _ in range(n_lf):
            theta_m, omega_m, theta_u, i, I_q, v_1, v_2, i_m, T_m, sin_e, cos_e, n_rot = lf_substep(
                theta_m, omega_m, theta_u, i, I_q, v_1, v_2, i_q_ref, c, sin_e, cos_e, n_rot
            )
            acc_i += i_m
            acc_T += T_m


@jit
def simulate_lf2(theta_cmd, prm_a, prm_b, out_a, out_b, no_aux):  # type: ignore[no-untyped-def]
    """`simulate_lf` of two rows at once, their steps interleaved, into out_a and out_b (no aux;
    no_aux: an empty (0, `N_AUX`) array, `NO_AUX`).

    One step is a chain of dependent operations (sin and cos of θ_e, the loop, tanh, the
    friction's divisions, back to θ_m) whose latency, not the core's throughput, sets its time;
    two independent chains in one loop overlap in the core. Each row's operations are
    `simulate_lf`'s, in its order, so each current is the one `simulate_lf` gives, to the bit. Rows
    with other steps per sample (n_lf) run one after the other.
    """
    n = theta_cmd.shape[0]
    ca = lf_constants(prm_a)
    cb = lf_constants(prm_b)
    n_lf = ca[2]
    if cb[2] != n_lf:
        simulate_lf(theta_cmd, prm_a, out_a, no_aux)
        simulate_lf(theta_cmd, prm_b, out_b, no_aux)
        return
    cpa, cpb = ca[0], cb[0]
    Iqa = v1a = v2a = Iqb = v1b = v2b = 0.0
    tma = oma = tua = tmb = omb = tub = 0.0
    ia = inta = ofa = ib = intb = ofb = 0.0
    acc_a = acc_b = 0.0
    sa, csa, na = 0.0, 1.0, 0  # each row's sin θ_e, cos θ_e and steps since libm's
    sb, csb, nb = 0.0, 1.0, 0
    for k in range(n):
        meas_a = quantise(tua, prm_a[LSB_THETA], prm_a[FS_THETA])
        meas_b = quantise(tub, prm_b[LSB_THETA], prm_b[FS_THETA])
        ref_a, inta, ofa = pid_step(theta_cmd[k], meas_a, oma, inta, ofa, cpa)
        ref_b, intb, ofb = pid_step(theta_cmd[k], meas_b, omb, intb, ofb, cpb)
        out_a[k] = acc_a / n_lf
        out_b[k] = acc_b / n_lf
        if k == n - 1:
            break
        acc_a = 0.0
        acc_b = 0.0
        for _ in range(n_lf):
            tma, oma, tua, ia, Iqa, v1a, v2a, ima, _, sa, csa, na = lf_substep(
                tma, oma, tua, ia, Iqa, v1a, v2a, ref_a, ca, sa, csa, na
            )
            tmb, omb, tub, ib, Iqb, v1b, v2b, imb, _, sb, csb, nb = lf_substep(
                tmb, omb, tub, ib, Iqb, v1b, v2b, ref_b, cb, sb, csb, nb
            )
            acc_a += ima
            acc_b += imb


# `simulate_lf_many` runs rows in interleaved pairs from this many rows on: a pair took 1.2-1.6x one
# row's time on one thread (96 rows 53-71 ms in pairs, 82-88 ms one by one, machine E), so on 2
# threads 4 rows as 2 pairs beat 2 rows on each, while 2 rows as a pair would leave one thread idle
PAIR_MIN_ROWS = 4


def simulate_lf_many(theta_cmd: np.ndarray, prm: np.ndarray, i_out: np.ndarray) -> None:
    """One LF run per row of `prm` (shape (n_runs, N_FIELDS)) into i_out (shape (n_runs, n)), in
    parallel: in interleaved pairs (`simulate_lf2`) from `PAIR_MIN_ROWS` rows, else one row per
    thread (two rows as a pair would leave the second thread idle). Each row's current is
    `simulate_lf`'s, to the bit."""
    simulate_lf_many_kernel(theta_cmd, prm, i_out, NO_AUX)


@jit(parallel=True)
def simulate_lf_many_kernel(theta_cmd, prm, i_out, no_aux):  # type: ignore[no-untyped-def]
    """`simulate_lf_many` (no_aux: `NO_AUX`)."""
    n_runs = prm.shape[0]
    if n_runs < PAIR_MIN_ROWS:
        for r in prange(n_runs):
            simulate_lf(theta_cmd, prm[r], i_out[r], no_aux)
        return
    for q in prange((n_runs + 1) // 2):
        r = 2 * q
        if r + 1 < n_runs:
            simulate_lf2(theta_cmd, prm[r], prm[r + 1], i_out[r], i_out[r + 1], no_aux)
        else:
            simulate_lf(theta_cmd, prm[r], i_out[r], no_aux)
