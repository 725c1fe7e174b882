"""Stator and inverter kernel against analytic RL solutions (independent references)."""

import numpy as np
import pytest

from emaphm.kernels.pmsm_abc import stator_pack, stator_step

R_s, L_s, V_dc, k_e = 0.5, 1.5e-3, 48.0, 0.1


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


# ---- the fast loop of hf_twin against the reference kernels -----------------------------------


def test_euler_map_is_one_euler_substep_of_stator_derivatives():
    # i + D·i + V·s + β equals i + h·di/dt from the neutral formula, and every column of the map
    # sums to zero (the isolated neutral: Σ_x di_x/dt = 0)
    from emaphm.kernels.pmsm_abc import euler_map, stator_derivatives
    from emaphm.kernels.transforms import phase_directions

    sp = stator_pack(V_dc, 0.1, 4, [0.5 * R_s, 0.8 * R_s, R_s], [0.25 * L_s, 0.64 * L_s, L_s],
                     [0.5 * k_e, 0.8 * k_e, k_e], 0.3, 1.1)  # fmt: skip
    h = 1e-6 / 3
    D, V, S, C = euler_map(sp, h)
    D, V, S, C = np.array(D), np.array(V), np.array(S), np.array(C)
    for M in (D, V, S[:, None], C[:, None]):
        assert np.max(np.abs(M.sum(axis=0))) <= 1e-15 * np.max(np.abs(M))
    rng = np.random.default_rng(3)
    for _ in range(20):
        i = rng.normal(0.0, 2.0, 3)
        i -= i.mean()
        s = rng.choice([-1.0, 1.0], 3)
        th, om = rng.uniform(-10.0, 10.0), rng.uniform(-80.0, 80.0)
        u = np.array(phase_directions(np.sin(th), np.cos(th)))
        ecc = 1.0 - sp.zeta * np.cos(th + sp.phi_e)
        e = np.array([sp.k_e_a, sp.k_e_b, sp.k_e_c]) * ecc * om * u
        d = np.array(stator_derivatives(*i, *(s * V_dc / 2), *e, sp))
        step = D @ i + V @ s + om * ecc * (S * np.sin(th) + C * np.cos(th))
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
        # the end-stop is reached after ≈ 2 ms and then pressed into
        dict(N=(0.7, 1.0, 1.0), zeta=0.1, n_sub=2, cmd="step", theta_max=2e-4, t_end=4e-3),
    ],
    ids=["healthy", "unequal-ecc", "end-stop"],
)
def test_fast_loop_matches_stator_step_and_mechanics_step(case):
    # hf_twin.simulate_hf reorders the same equations for speed (rotation of sin/cos θ_e, the
    # linear Euler map, i_c = −(i_a + i_b)); thousands of steps with hundreds of comparator
    # switches must agree with the reference kernels to rounding
    from emaphm.kernels.controller import ControllerPack
    from emaphm.kernels.hf_twin import N_OUT, simulate_hf
    from emaphm.kernels.mechanics import MechanicsPack

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
    simulate_hf(*args, fast)
    ref = reference_hf(*args)
    scale = np.max(np.abs(ref), axis=0)
    assert np.all(np.abs(fast - ref) <= 1e-9 * scale + 1e-300)
    assert np.max(np.abs(ref[:, 3])) > 10.0  # the motor did move (rad/s)
    if case["cmd"] == "sine":
        assert np.any(ref[1:, 3] > 1.0) and np.any(ref[1:, 3] < -1.0)  # speed reversals
    if case["theta_max"] < 0.1:
        assert np.sum(ref[:, 0] == case["theta_max"]) > 5  # rows at the stop
