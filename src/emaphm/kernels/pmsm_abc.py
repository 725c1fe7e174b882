"""Three-phase PMSM stator and hysteresis inverter of the high-fidelity twin (DESIGN §3.3–§3.7).

Per phase x ∈ {a, b, c}, with γ_a = 0, γ_b = 2π/3, γ_c = −2π/3, u_x = −sin(θ_e − γ_x) and
v_x = cos(θ_e − γ_x) (so dv_x/dθ_e = u_x):

    current reference   i_x,ref = i_q,ref·u_x                                (DESIGN §3.3, i_d = 0)
    comparator          +V_dc/2 when i_x < i_x,ref − h/2, −V_dc/2 when i_x > i_x,ref + h/2, else hold
    stator              v_xn = R_x·i_x + L_x·di_x/dt + e_x                    (DESIGN §3.5)
    magnet flux         ψ_x(θ) = N_x·ψ_m·ecc(θ)·v_x,   ecc = 1 − ζ·cos(θ_e + φ_e)   (DESIGN §3.7)
    back-EMF            e_x = dψ_x/dt = g_x(θ)·ω_m,     g_x = ∂ψ_x/∂θ_m
    torque (co-energy)  T_m = Σ_x i_x·∂ψ_x/∂θ_m = Σ_x g_x(θ)·i_x   (power into e_x = T_m·ω_m)
    isolated neutral    v_n0 = Σ_x (v_x0 − R_x·i_x − e_x)/L_x ⁄ Σ_x 1/L_x       (DESIGN §3.4)
    short circuit       R_x = N_x·R_s, L_x = N_x²·L_s, k_e,x = N_x·k_e        (DESIGN §3.6)

The coupling g_x. With θ_e = p·θ_m and k_e = p·ψ_m, ∂/∂θ_m = p·∂/∂θ_e and ∂ecc/∂θ_e = ζ·sin(θ_e + φ_e):

    g_x = k_e,x·[ecc·u_x + ζ·sin(θ_e + φ_e)·v_x]          (product rule: `couplings`)
        = k_e,x·[u_x + ζ·sin(2θ_e + φ_e − γ_x)]            (sin A·cos B + cos A·sin B, A = θ_e + φ_e)

Healthy (ζ = 0) this is e_x = k_e,x·ω_m·u_x exactly (bit for bit). ψ_x repeats every electrical
revolution, so at constant speed the mean of e_x over a revolution is zero; the first version,
g_x = k_e,x·ecc·u_x (no ∂ecc/∂θ term), had the mean −(ζ/2)·k_e,x·ω_m·sin(φ_e + γ_x). Both give the
same torque for the i_d = 0 currents i_x = i_q·u_x of a balanced winding, T_m = 1.5·k_e·i_q·ecc
(Σ_x u_x² = 3/2 and Σ_x sin(2θ_e + φ_e − γ_x)·u_x = −(3/2)·cos(θ_e + φ_e)); they differ in the
back-EMF: the old one is k_e,x·ω_m·{u_x + (ζ/2)·[sin(2θ_e + φ_e − γ_x) − sin(φ_e + γ_x)]}, half the
2θ_e harmonic and a DC term, the physical one the whole harmonic and no DC. The inductances stay
constant (the eccentric air gap's effect on L_x and the cogging torque are not modelled).

The neutral formula is the general one: it follows from Σ_x di_x/dt = 0 and keeps
i_a + i_b + i_c = 0 with unequal phases (the mean of v_x0 holds only for balanced phases).
With the neutral eliminated the stator is linear in the currents, di/dt = M·(v_0 − R·i − e) with
M_xy = (δ_xy − L_n/L_y)/L_x and L_n = 1/Σ_y(1/L_y); `euler_map` gives one explicit-Euler sub-step
of it as the linear map the fast loop (`hf_twin.simulate_hf`) uses.

Because L_x ∝ N_x², a shorted coil's current moves much faster; the electrical part is
therefore sub-stepped (n_sub sub-steps per mechanical step, chosen by the API so that no current
moves by more than a set fraction of the band per sub-step), with the angle and speed held over
the step.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ._jit import jit
from .transforms import HALF_SQRT3, clarke, phase_directions

GAMMA = (0.0, 2.0 * math.pi / 3.0, -2.0 * math.pi / 3.0)  # γ_a, γ_b, γ_c [rad]


class StatorPack(NamedTuple):
    """Inverter and per-phase stator parameters with faults applied; build it with `stator_pack`.

    The reciprocal inductances and the eccentricity components are stored so that the hot loop
    multiplies instead of dividing and calls no trigonometry for φ_e: ζ·cos(θ_e + φ_e) =
    zeta_cos·cos θ_e − zeta_sin·sin θ_e, and the 2θ_e harmonic of the coupling (module docstring)
    ζ·sin(2θ_e + φ_e − γ_x) = ecc2_sin_x·sin 2θ_e + ecc2_cos_x·cos 2θ_e.
    """

    V_dc: float  # DC bus [V]
    h: float  # hysteresis band, total [A]
    p: float  # pole pairs [-]
    R_a: float  # phase resistances [Ω]
    R_b: float
    R_c: float
    L_a: float  # phase inductances [H]
    L_b: float
    L_c: float
    k_e_a: float  # back-EMF constants N_x·k_e [V·s/rad]
    k_e_b: float
    k_e_c: float
    zeta: float  # relative static eccentricity [-]
    phi_e: float  # eccentricity direction [rad]
    inv_L_a: float  # 1/L_x [1/H]
    inv_L_b: float
    inv_L_c: float
    L_n: float  # 1/Σ_x(1/L_x), the neutral's parallel inductance [H]
    zeta_cos: float  # ζ·cos φ_e [-]
    zeta_sin: float  # ζ·sin φ_e [-]
    ecc2_sin_a: float  # ζ·cos(φ_e − γ_x) [-]
    ecc2_sin_b: float
    ecc2_sin_c: float
    ecc2_cos_a: float  # ζ·sin(φ_e − γ_x) [-]
    ecc2_cos_b: float
    ecc2_cos_c: float


@jit
def ecc_harmonics(zeta, phi_e):  # type: ignore[no-untyped-def]
    """(a_a, a_b, a_c, b_a, b_b, b_c) with a_x = ζ·cos(φ_e − γ_x), b_x = ζ·sin(φ_e − γ_x): the 2θ_e
    harmonic of the eccentric coupling, ζ·sin(2θ_e + φ_e − γ_x) = a_x·sin 2θ_e + b_x·cos 2θ_e
    (the `StatorPack` fields ecc2_sin_x, ecc2_cos_x; the LF monitor's `phi_t` with k_E·ζ)."""
    return (
        zeta * math.cos(phi_e - GAMMA[0]), zeta * math.cos(phi_e - GAMMA[1]), zeta * math.cos(phi_e - GAMMA[2]),
        zeta * math.sin(phi_e - GAMMA[0]), zeta * math.sin(phi_e - GAMMA[1]), zeta * math.sin(phi_e - GAMMA[2]),
    )  # fmt: skip


def stator_pack(V_dc, h, p, R, L, k_e, zeta, phi_e):  # type: ignore[no-untyped-def]
    """StatorPack from per-phase triples R, L, k_e, with the derived fields filled in."""
    inv_L = [1.0 / x for x in L]
    zeta, phi_e = float(zeta), float(phi_e)
    return StatorPack(
        float(V_dc), float(h), float(p), *map(float, R), *map(float, L), *map(float, k_e),
        zeta, phi_e, *inv_L, 1.0 / sum(inv_L),
        zeta * math.cos(phi_e), zeta * math.sin(phi_e), *ecc_harmonics(zeta, phi_e),
    )  # fmt: skip


@jit
def flux_directions(sin_e, cos_e):  # type: ignore[no-untyped-def]
    """v_x = cos(θ_e − γ_x) for x = a, b, c: the healthy magnet flux linkage ψ_x/(N_x·ψ_m).

    dv_x/dθ_e = u_x (`transforms.phase_directions`).
    """
    return cos_e, -0.5 * cos_e + HALF_SQRT3 * sin_e, -0.5 * cos_e - HALF_SQRT3 * sin_e


@jit
def couplings(sin_e, cos_e, sp):  # type: ignore[no-untyped-def]
    """g_x = ∂ψ_x/∂θ_m [V·s/rad = N·m/A] at θ_e: back-EMF per rad/s and torque per ampere.

    ψ_x = N_x·ψ_m·ecc·v_x with ecc = 1 − ζ·cos(θ_e + φ_e) (DESIGN §3.7), differentiated by the
    product rule: g_x = k_e,x·(ecc·u_x + ∂ecc/∂θ_e·v_x), ∂ecc/∂θ_e = ζ·sin(θ_e + φ_e).
    """
    u_a, u_b, u_c = phase_directions(sin_e, cos_e)
    v_a, v_b, v_c = flux_directions(sin_e, cos_e)
    # cos(θ_e + φ_e) and sin(θ_e + φ_e) expanded
    ecc = 1.0 - (cos_e * sp.zeta_cos - sin_e * sp.zeta_sin)
    d_ecc = sin_e * sp.zeta_cos + cos_e * sp.zeta_sin
    return (
        sp.k_e_a * (ecc * u_a + d_ecc * v_a),
        sp.k_e_b * (ecc * u_b + d_ecc * v_b),
        sp.k_e_c * (ecc * u_c + d_ecc * v_c),
    )


@jit
def hysteresis(i: float, i_ref: float, state: float, h: float) -> float:
    """Comparator state (+1: upper switch on, −1: lower switch on) for one inverter leg."""
    if i < i_ref - 0.5 * h:
        return 1.0
    if i > i_ref + 0.5 * h:
        return -1.0
    return state


@jit
def stator_derivatives(i_a, i_b, i_c, v_a0, v_b0, v_c0, e_a, e_b, e_c, sp):  # type: ignore[no-untyped-def]
    """di_x/dt [A/s] of the star winding with isolated neutral for leg voltages v_x0 [V]."""
    w_a = v_a0 - sp.R_a * i_a - e_a
    w_b = v_b0 - sp.R_b * i_b - e_b
    w_c = v_c0 - sp.R_c * i_c - e_c
    # DESIGN §3.4: v_n0 = Σ w_x/L_x ⁄ Σ 1/L_x
    v_n0 = (w_a * sp.inv_L_a + w_b * sp.inv_L_b + w_c * sp.inv_L_c) * sp.L_n
    return (w_a - v_n0) * sp.inv_L_a, (w_b - v_n0) * sp.inv_L_b, (w_c - v_n0) * sp.inv_L_c


@jit
def stator_step(i_a, i_b, i_c, s_a, s_b, s_c, theta_e, omega_m, i_q_ref, dt, n_sub, sp):  # type: ignore[no-untyped-def]
    """Advance inverter and stator by dt in n_sub explicit-Euler sub-steps.

    Returns (i_a, i_b, i_c, s_a, s_b, s_c, T_m, i_q): currents [A] and comparator states at the
    end of the step, the motor torque averaged over the sub-steps [N·m], and the quadrature
    current at the end of the step [A].
    """
    sin_e = math.sin(theta_e)
    cos_e = math.cos(theta_e)
    u_a, u_b, u_c = phase_directions(sin_e, cos_e)
    # DESIGN §3.5, §3.7: g_x = ∂ψ_x/∂θ_m, back-EMF per rad/s and torque per ampere
    g_a, g_b, g_c = couplings(sin_e, cos_e, sp)
    e_a = g_a * omega_m
    e_b = g_b * omega_m
    e_c = g_c * omega_m
    r_a = i_q_ref * u_a  # DESIGN §3.3
    r_b = i_q_ref * u_b
    r_c = i_q_ref * u_c
    half_V = 0.5 * sp.V_dc
    h_sub = dt / n_sub
    T_sum = 0.0
    for _ in range(n_sub):
        s_a = hysteresis(i_a, r_a, s_a, sp.h)
        s_b = hysteresis(i_b, r_b, s_b, sp.h)
        s_c = hysteresis(i_c, r_c, s_c, sp.h)
        d_a, d_b, d_c = stator_derivatives(
            i_a, i_b, i_c, s_a * half_V, s_b * half_V, s_c * half_V, e_a, e_b, e_c, sp
        )
        i_a += h_sub * d_a
        i_b += h_sub * d_b
        i_c += h_sub * d_c
        T_sum += g_a * i_a + g_b * i_b + g_c * i_c  # DESIGN §3.5
    i_alpha, i_beta = clarke(i_a, i_b, i_c)
    i_q = -i_alpha * sin_e + i_beta * cos_e  # Park, DESIGN §3.9
    return i_a, i_b, i_c, s_a, s_b, s_c, T_sum / n_sub, i_q


@jit
def euler_map(sp, h_sub):  # type: ignore[no-untyped-def]
    """One explicit-Euler sub-step of `stator_derivatives` as a linear map (DESIGN §3.4–§3.7).

    With the comparator states s_x held over the sub-step, i ← i + h·M·(v_0 − R·i − e) is

        i ← i + Δ,   Δ = D·i + V·s + β,   D = −h·M·R,   V = h·(V_dc/2)·M,   β = −h·M·e,
        β_x = ω_m·(S_x·sin θ_e + C_x·cos θ_e + S2_x·sin 2θ_e + C2_x·cos 2θ_e),

    because e_y = ω_m·k_e,y·[u_y + ζ·sin(2θ_e + φ_e − γ_y)] (module docstring) with
    u_y = a_y·sin θ_e + b_y·cos θ_e (a = (−1, ½, ½), b = (0, √3/2, −√3/2),
    `transforms.phase_directions`) and ζ·sin(2θ_e + φ_e − γ_y) = ecc2_sin_y·sin 2θ_e +
    ecc2_cos_y·cos 2θ_e (`StatorPack`): S_x = −h·Σ_y M_xy·k_e,y·a_y, C_x = −h·Σ_y M_xy·k_e,y·b_y,
    S2_x = −h·Σ_y M_xy·k_e,y·ecc2_sin_y and C2_x = −h·Σ_y M_xy·k_e,y·ecc2_cos_y. Every column of M
    sums to zero (Σ_x di_x/dt = 0), so Δ_c = −(Δ_a + Δ_b). Same equations as `stator_step`, grouped
    so that the step's one dependency chain is short; the results differ from it by rounding only.

    Returns (D, V, S, C, S2, C2): D and V as three rows (x = a, b, c) of three, S, C, S2 and C2
    as triples.
    """
    inv_L = (sp.inv_L_a, sp.inv_L_b, sp.inv_L_c)
    R = (sp.R_a, sp.R_b, sp.R_c)
    ke = (sp.k_e_a, sp.k_e_b, sp.k_e_c)
    a = (-1.0, 0.5, 0.5)
    b = (0.0, HALF_SQRT3, -HALF_SQRT3)
    a2 = (sp.ecc2_sin_a, sp.ecc2_sin_b, sp.ecc2_sin_c)
    b2 = (sp.ecc2_cos_a, sp.ecc2_cos_b, sp.ecc2_cos_c)
    half_V = 0.5 * sp.V_dc

    def m(x, y):  # type: ignore[no-untyped-def]
        # DESIGN §3.4: M_xy = (δ_xy − L_n/L_y)/L_x
        return ((1.0 if x == y else 0.0) - sp.L_n * inv_L[y]) * inv_L[x]

    def row(x):  # type: ignore[no-untyped-def]
        D = (-h_sub * m(x, 0) * R[0], -h_sub * m(x, 1) * R[1], -h_sub * m(x, 2) * R[2])
        V = (h_sub * half_V * m(x, 0), h_sub * half_V * m(x, 1), h_sub * half_V * m(x, 2))
        S = -h_sub * (m(x, 0) * ke[0] * a[0] + m(x, 1) * ke[1] * a[1] + m(x, 2) * ke[2] * a[2])
        C = -h_sub * (m(x, 0) * ke[0] * b[0] + m(x, 1) * ke[1] * b[1] + m(x, 2) * ke[2] * b[2])
        S2 = -h_sub * (m(x, 0) * ke[0] * a2[0] + m(x, 1) * ke[1] * a2[1] + m(x, 2) * ke[2] * a2[2])
        C2 = -h_sub * (m(x, 0) * ke[0] * b2[0] + m(x, 1) * ke[1] * b2[1] + m(x, 2) * ke[2] * b2[2])
        return D, V, S, C, S2, C2

    D_a, V_a, S_a, C_a, S2_a, C2_a = row(0)
    D_b, V_b, S_b, C_b, S2_b, C2_b = row(1)
    D_c, V_c, S_c, C_c, S2_c, C2_c = row(2)
    return ((D_a, D_b, D_c), (V_a, V_b, V_c), (S_a, S_b, S_c), (C_a, C_b, C_c),
            (S2_a, S2_b, S2_c), (C2_a, C2_b, C2_c))  # fmt: skip
