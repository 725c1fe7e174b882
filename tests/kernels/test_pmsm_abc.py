"""Stator and inverter kernel against analytic RL solutions and the magnet flux linkage
(independent references)."""

import numpy as np
import pytest

from emaphm.kernels.pmsm_abc import stator_pack, stator_step

R_s, L_s, V_dc, k_e = 0.5, 1.5e-3, 48.0, 0.1
P = 4  # pole pairs
GAMMA = np.array([0.0, 2 * np.pi / 3, -2 * np.pi / 3])


def flux_linkage(theta_m, N, zeta, phi_e):
    """DESIGN §3.7, written here from the documented formula: ψ_x = N_x·ψ_m·[1 − ζ·cos(θ_e + φ_e)]·
    cos(θ_e − γ_x), θ_e = p·θ_m, ψ_m = k_e/p. Rows: angles; columns: phases a, b, c [Wb]."""
    th_e = P * np.asarray(theta_m, dtype=float)[:, None]
    return np.asarray(N) * (k_e / P) * (1 - zeta * np.cos(th_e + phi_e)) * np.cos(th_e - GAMMA)


def emf_from_one_step(theta_e, omega, sp, dt=1e-6):
    """The back-EMF stator_step applies, read from the kernel itself: from zero currents with the
    legs at 0 V (states 0, a band too wide to switch) one Euler step gives i = −dt·M·e, and for
    equal phases (Σ_x e_x = 0, so v_n0 = 0) e_x = −L·i_x/dt."""
    sp = sp._replace(h=1e9)
    return np.array([stator_step(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, th, omega, 0.0, dt, 1, sp)[:3]
                     for th in theta_e]) * (-sp.L_a / dt)  # fmt: skip


def pack(N=(1.0, 1.0, 1.0), h=1e9):
    return stator_pack(
        V_dc, h, 4, [n * R_s for n in N], [n**2 * L_s for n in N], [n * k_e for n in N], 0.0, 0.0
    )


def locked_rotor(sp, t_end=6e-3, dt=1e-6):
    """Leg A at +V_dc/2, legs B and C at -V_dc/2 (a huge band keeps the comparators as set)."""
    state = (0.0, 0.0, 0.0, 1.0, -1.0, -1.0)
    out = []
    for _ in range(round(t_end / dt)):
        *state, _, _ = stator_step(*state, 0.0, 0.0, 0.0, dt, 1, sp)
        out.append(state[:3])
    return np.arange(1, len(out) + 1) * dt, np.array(out)


@pytest.mark.parametrize("N_bc", [1.0, 0.4])
def test_locked_rotor_step_matches_rl_solution(N_bc):
    # A in series with B ∥ C (equal): R = R_A + R_B/2, L = L_A + L_B/2, one time constant
    sp = pack((1.0, N_bc, N_bc))
    t, i = locked_rotor(sp)
    R = R_s + N_bc * R_s / 2
    L = L_s + N_bc**2 * L_s / 2
    i_ref = V_dc / R * (1 - np.exp(-t * R / L))
    # explicit Euler at dt = 1 µs against tau >= 1.9 ms: relative error ~ dt/(2 tau) < 1e-3
    np.testing.assert_allclose(i[:, 0], i_ref, rtol=2e-3, atol=1e-6)
    np.testing.assert_allclose(i[:, 1], -i[:, 0] / 2, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(i.sum(axis=1), 0.0, atol=1e-10)


def test_unequal_phases_keep_star_currents_summing_to_zero():
    # a badly unbalanced winding and a spinning rotor: the neutral formula keeps Σi = 0
    sp = pack((0.3, 1.0, 0.7), h=0.2)
    state = (0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    worst = 0.0
    for j in range(20000):
        *state, _, _ = stator_step(*state, 4e-3 * j, 40.0, 2.0, 1e-6, 4, sp)
        worst = max(worst, abs(sum(state[:3])))
    assert worst < 1e-10


def test_hysteresis_keeps_current_within_band():
    # healthy phase, locked rotor, constant reference: i_a stays within ±h/2 plus one step of slope
    h = 0.2
    sp = pack(h=h)
    state = (0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    theta_e = np.pi / 2  # u_a = -1, so i_a,ref = -i_q,ref
    errs = []
    for j in range(20000):
        *state, _, _i_q = stator_step(*state, theta_e, 0.0, 1.5, 1e-6, 1, sp)
        if j > 2000:
            errs.append(state[0] + 1.5)
    max_slope_step = V_dc * 1e-6 / L_s
    assert np.max(np.abs(errs)) <= h / 2 + max_slope_step
    assert np.std(errs) > h / 10  # it does switch: the ripple fills the band


# ---- eccentricity: back-EMF and torque from the eccentric magnet flux linkage (DESIGN §3.7) ------


@pytest.mark.parametrize("phi_e", [0.0, np.pi / 2, 2.0])
@pytest.mark.parametrize("N", [(1.0, 1.0, 1.0), (0.6, 1.0, 0.85)], ids=["balanced", "unequal"])
def test_back_emf_has_zero_mean_over_an_electrical_revolution(N, phi_e):
    # ψ_x repeats every electrical revolution, so at constant speed and zero current the back-EMF
    # of every phase averages to zero over one revolution (the first model, k_e,x(θ)·u_x, gave
    # −(ζ/2)·k_e·ω·sin(φ_e + γ_x): up to 1.5 V here). The kernel's one-step current response from
    # zero, −dt·M·e, must average to zero too (M's null space is only the common mode, and the
    # old DC terms are not common mode); 360 equal steps average a trigonometric polynomial of
    # degree 2 exactly
    omega, zeta, dt = 100.0, 0.3, 1e-6
    sp = stator_pack(V_dc, 1e9, P, [n * R_s for n in N], [n**2 * L_s for n in N],
                     [n * k_e for n in N], zeta, phi_e)  # fmt: skip
    th = np.linspace(0.0, 2 * np.pi, 361)[:-1]
    i = np.array([stator_step(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, t, omega, 0.0, dt, 1, sp)[:3] for t in th])
    i_scale = dt * k_e * omega / L_s  # a back-EMF of k_e·ω seen through one step [A]
    assert np.max(np.abs(i.mean(axis=0))) <= 1e-12 * i_scale
    assert np.max(np.abs(i)) > 0.5 * i_scale  # and the EMF is there
    if N == (1.0, 1.0, 1.0):
        e = emf_from_one_step(th, omega, sp, dt)
        assert np.max(np.abs(e.mean(axis=0))) <= 1e-10 * k_e * omega  # [V]


@pytest.mark.parametrize("zeta, phi_e", [(0.0, 0.0), (0.3, 0.0), (0.3, 2.0), (0.8, -1.2)])
def test_back_emf_is_the_derivative_of_the_flux_linkage(zeta, phi_e):
    # e_x = ω_m·∂ψ_x/∂θ_m against a central difference of the documented ψ_x(θ): read from the
    # kernel's step (equal phases) and from the coupling the torque uses (unequal phases)
    from emaphm.kernels.pmsm_abc import couplings

    omega, h = 100.0, 1e-5  # h: mechanical angle step of the central difference [rad]
    th_m = np.linspace(0.0, 2 * np.pi / P, 97)
    for N in ((1.0, 1.0, 1.0), (0.6, 1.0, 0.85)):
        sp = stator_pack(V_dc, 1e9, P, [n * R_s for n in N], [n**2 * L_s for n in N],
                         [n * k_e for n in N], zeta, phi_e)  # fmt: skip
        dpsi = (flux_linkage(th_m + h, N, zeta, phi_e) - flux_linkage(th_m - h, N, zeta, phi_e)) / (2 * h)
        g = np.array([couplings(np.sin(P * t), np.cos(P * t), sp) for t in th_m])
        # central-difference error ≈ h²·p³·k_e·(1 + 8ζ)/6 ≈ 3e-10·k_e; rounding ≈ 1e-17/h
        np.testing.assert_allclose(g, dpsi, rtol=0, atol=1e-8 * k_e)
        if N == (1.0, 1.0, 1.0):
            e = emf_from_one_step(P * th_m, omega, sp)
            np.testing.assert_allclose(e, omega * dpsi, rtol=0, atol=1e-8 * k_e * omega)


def test_healthy_coupling_is_exactly_the_sinusoid():
    # ζ = 0: g_x = k_e,x·u_x bit for bit (the eccentric terms add exact zeros), and the fast
    # loop's 2θ_e coefficients are exact zeros, so healthy and short-only runs are unchanged
    from emaphm.kernels.pmsm_abc import couplings, euler_map
    from emaphm.kernels.transforms import phase_directions

    N = (0.6, 1.0, 0.85)
    sp = stator_pack(V_dc, 0.1, P, [n * R_s for n in N], [n**2 * L_s for n in N],
                     [n * k_e for n in N], 0.0, 1.3)  # fmt: skip
    ke = np.array([sp.k_e_a, sp.k_e_b, sp.k_e_c])
    for th in np.random.default_rng(5).uniform(-20.0, 20.0, 200):
        s, c = np.sin(th), np.cos(th)
        np.testing.assert_array_equal(couplings(s, c, sp), ke * np.array(phase_directions(s, c)))
    *_, S2, C2 = euler_map(sp, 1e-6 / 3)
    assert not np.any(np.array([S2, C2]))


def test_torque_is_the_coenergy_derivative():
    # T_m = Σ_x i_x·∂ψ_x/∂θ_m (co-energy, constant inductances) with ∂ψ_x/∂θ_m from a central
    # difference of ψ_x; one sub-step, so T_m is formed with the currents at the end of the step.
    # The angle sweeps faster than ω·t (half an electrical revolution in 4000 steps): the identity
    # holds at every angle and speed
    omega, zeta, phi_e, dt, h = 40.0, 0.3, 0.9, 1e-6, 1e-5
    N = (0.6, 1.0, 0.85)
    sp = stator_pack(V_dc, 0.1, P, [n * R_s for n in N], [n**2 * L_s for n in N],
                     [n * k_e for n in N], zeta, phi_e)  # fmt: skip
    state = (0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    rows = []
    for j in range(4000):
        th_m = 2e-4 * j
        *state, T, _ = stator_step(*state, P * th_m, omega, 3.0, dt, 1, sp)
        rows.append((th_m, *state[:3], T))
    th_m, i_a, i_b, i_c, T = np.array(rows).T
    i = np.column_stack([i_a, i_b, i_c])
    dpsi = (flux_linkage(th_m + h, N, zeta, phi_e) - flux_linkage(th_m - h, N, zeta, phi_e)) / (2 * h)
    np.testing.assert_allclose(T, (i * dpsi).sum(axis=1), rtol=0, atol=1e-7 * k_e * np.max(np.abs(i)))
    assert np.max(np.abs(T)) > 0.1  # [N·m]: a real torque, not a trivial zero


# ---- the fast loop of hf_twin against the reference kernels -----------------------------------


def test_euler_map_is_one_euler_substep_of_stator_derivatives():
    # i + D·i + V·s + β equals i + h·di/dt from the neutral formula, and every column of the map
    # sums to zero (the isolated neutral: Σ_x di_x/dt = 0)
    from emaphm.kernels.pmsm_abc import euler_map, stator_derivatives
    from emaphm.kernels.transforms import phase_directions

    N = np.array([0.5, 0.8, 1.0])
    zeta, phi_e = 0.3, 1.1
    sp = stator_pack(V_dc, 0.1, P, N * R_s, N**2 * L_s, N * k_e, zeta, phi_e)
    h = 1e-6 / 3
    D, V, S, C, S2, C2 = map(np.array, euler_map(sp, h))
    for M in (D, V, S[:, None], C[:, None], S2[:, None], C2[:, None]):
        assert np.max(np.abs(M.sum(axis=0))) <= 1e-15 * np.max(np.abs(M))
    rng = np.random.default_rng(3)
    for _ in range(20):
        i = rng.normal(0.0, 2.0, 3)
        i -= i.mean()
        s = rng.choice([-1.0, 1.0], 3)
        th, om = rng.uniform(-10.0, 10.0), rng.uniform(-80.0, 80.0)
        u = np.array(phase_directions(np.sin(th), np.cos(th)))
        # e_x = ω_m·∂ψ_x/∂θ_m of ψ_x = N_x·ψ_m·[1 − ζ·cos(θ_e + φ_e)]·cos(θ_e − γ_x), by hand
        ecc = 1.0 - zeta * np.cos(th + phi_e)
        e = N * k_e * om * (ecc * u + zeta * np.sin(th + phi_e) * np.cos(th - GAMMA))
        d = np.array(stator_derivatives(*i, *(s * V_dc / 2), *e, sp))
        harm = S * np.sin(th) + C * np.cos(th) + S2 * np.sin(2 * th) + C2 * np.cos(2 * th)
        step = D @ i + V @ s + om * harm
        np.testing.assert_allclose(step, h * d, rtol=1e-11, atol=1e-13 * np.max(np.abs(h * d)))


def reference_hf(theta_cmd, theta_noise, lsb, fs, cp, sp, mp, dt, n_per_sample, n_sub):
    """simulate_hf written plainly with the reference kernels stator_step and mechanics_step."""
    from emaphm.kernels.controller import pid_step
    from emaphm.kernels.hf_twin import N_OUT
    from emaphm.kernels.mechanics import mechanics_step
    from emaphm.kernels.sensors import quantise

    n = len(theta_cmd)
    out = np.zeros((n, N_OUT))
    th_m = om = th_u = integral = om_f = 0.0
    i_s = (0.0, 0.0, 0.0, 1.0, 1.0, 1.0)  # currents and comparator states
    acc = np.zeros(5)  # i_a, i_b, i_c, i_q, T_m
    for k in range(n):
        th_meas = quantise(th_u + theta_noise[k], lsb, fs)
        i_q_ref, integral, om_f = pid_step(theta_cmd[k], th_meas, om, integral, om_f, cp)
        out[k] = (th_u, th_meas, th_m, om, sp.p * th_m, *(acc[:3] / n_per_sample),
                  acc[3] / n_per_sample, i_q_ref, acc[4] / n_per_sample)  # fmt: skip
        acc[:] = 0.0
        for _ in range(n_per_sample if k < n - 1 else 0):
            *i_s, T_m, i_q = stator_step(*i_s, sp.p * th_m, om, i_q_ref, dt, n_sub, sp)
            th_m, om, th_u = mechanics_step(th_m, om, th_u, T_m, dt, mp)
            acc += (*i_s[:3], i_q, T_m)
    return out


@pytest.mark.parametrize(
    "case",
    [
        # healthy (n_sub = 1): friction break-away from rest, saturated current demand, load
        dict(N=(1.0, 1.0, 1.0), zeta=0.0, n_sub=1, cmd="step", theta_max=0.5, t_end=4e-3),
        # unequal phases with eccentricity, sub-stepped, a fast sine: speed reversals (case 4)
        dict(N=(1.0, 0.55, 0.8), zeta=0.3, n_sub=3, cmd="sine", theta_max=0.5, t_end=4e-3),
        # eccentricity alone (n_sub = 1, the loop without sub-steps)
        dict(N=(1.0, 1.0, 1.0), zeta=0.3, n_sub=1, cmd="sine", theta_max=0.5, t_end=4e-3),
        # the end-stop is reached after ≈ 2 ms and then pressed into
        dict(N=(0.7, 1.0, 1.0), zeta=0.1, n_sub=2, cmd="step", theta_max=2e-4, t_end=4e-3),
    ],
    ids=["healthy", "unequal-ecc", "ecc", "end-stop"],
)
def test_fast_loop_matches_stator_step_and_mechanics_step(case):
    # hf_twin.simulate_hf reorders the same equations for speed (rotation of sin/cos θ_e, the
    # linear Euler map, i_c = −(i_a + i_b)); thousands of steps with hundreds of comparator
    # switches must agree with the reference kernels to rounding
    from emaphm.kernels.controller import ControllerPack
    from emaphm.kernels.hf_twin import N_OUT, simulate_hf
    from emaphm.kernels.mechanics import MechanicsPack
    from emaphm.models.hf import foc_pack
    from emaphm.params import EmaParams

    N = case["N"]
    sp = stator_pack(V_dc, 0.1, 4, [n * R_s for n in N], [n**2 * L_s for n in N],
                     [n * k_e for n in N], case["zeta"], 2.0)  # fmt: skip
    cp = ControllerPack(60.0, 200.0, 3.5, 1e-3, 10.0, 1e-4, 200.0)
    mp = MechanicsPack(5e-5 + 0.05 / 200.0**2, 1e-5, 0.02, 0.014, 2e-4, 200.0, 0.9, case["theta_max"], 5.0)
    t = np.arange(round(case["t_end"] * 1e4) + 1) * 1e-4
    cmd = np.full_like(t, 0.3) if case["cmd"] == "step" else 0.2 * np.sin(2 * np.pi * 250.0 * t)
    noise = np.random.default_rng(1).normal(0.0, 1e-5, len(t))
    args = (cmd, noise, 1.8e-5, 0.6, cp, sp, mp, 1e-6, 100, case["n_sub"])
    fast = np.empty((len(t), N_OUT))
    simulate_hf(*args[:7], foc_pack(EmaParams()), *args[7:], fast)  # hysteresis: fp.on = 0
    ref = reference_hf(*args)
    scale = np.max(np.abs(ref), axis=0)
    assert np.all(np.abs(fast - ref) <= 1e-9 * scale + 1e-300)
    assert np.max(np.abs(ref[:, 3])) > 10.0  # the motor did move (rad/s)
    if case["cmd"] == "sine":
        assert np.any(ref[1:, 3] > 1.0) and np.any(ref[1:, 3] < -1.0)  # speed reversals
    if case["theta_max"] < 0.1:
        assert np.sum(ref[:, 0] == case["theta_max"]) > 5  # rows at the stop
