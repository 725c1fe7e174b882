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
