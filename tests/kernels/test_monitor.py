"""Shape functions (paper eqs. 1 and 2) and the LF population kernel."""

import numpy as np
import pytest

from emaphm import MonitorEma
from emaphm.kernels import monitor as lf_kernel
from emaphm.kernels.monitor import (
    IDX,
    LF_FIELDS,
    N_AUX,
    N_FIELDS,
    loop_error,
    phi_ecc,
    phi_sc,
    simulate_lf,
    simulate_lf_many,
    unbalance,
    unbalance_2,
)

THETA = np.linspace(0, 2 * np.pi, 720, endpoint=False)


def harmonic(y, order):
    """Complex amplitude of the order·θ term of y(θ) over one electrical turn."""
    return 2 * np.mean(y * np.exp(-1j * order * THETA))


@pytest.mark.parametrize(("k_FT", "k_FS"), [(1.0, 0.0), (0.2, 1.0), (0.0078, 83.0), (3.0, 0.4)])
def test_healthy_short_circuit_shape_is_constant(k_FT, k_FS):
    # sin²θ + sin²(θ + π/3) + sin²(θ − π/3) = 3/2
    y = phi_sc(np.sin(THETA), np.cos(THETA), 1.0, 1.0, 1.0, k_FT, k_FS)
    np.testing.assert_allclose(y, k_FT * (3 + 1.5 * k_FS), rtol=1e-13)


def test_one_phase_short_gives_a_2theta_term_at_that_phase():
    s, c = np.sin(THETA), np.cos(THETA)
    terms = []
    for N in ([0.7, 1, 1], [1, 0.7, 1], [1, 1, 0.7]):
        y = phi_sc(s, c, *N, 0.1, 2.0)
        assert abs(harmonic(y, 1)) < 1e-12 and abs(harmonic(y, 3)) < 1e-12  # only DC and 2θ
        terms.append(harmonic(y, 2))
    amps = np.abs(terms)
    np.testing.assert_allclose(amps, amps[0], rtol=1e-10)  # same size in every phase
    # sin²(θ + π) = (1 − cos 2θ)/2, so removing turns from A leaves +cos 2θ (0°); the sin² terms of
    # B and C are those of A shifted by 2π/3 in 2θ: cos(2θ + 2π/3), cos(2θ − 2π/3)
    assert np.degrees(np.angle(terms[0])) == pytest.approx(0.0, abs=1e-9)
    assert np.degrees(np.angle(terms[1] / terms[0])) == pytest.approx(120.0)
    assert np.degrees(np.angle(terms[2] / terms[1])) == pytest.approx(120.0)


@pytest.mark.parametrize("phi_e", [0.0, 1.0, 4.0])
def test_eccentricity_gives_a_1theta_term_at_its_phase(phi_e):
    y = phi_ecc(np.sin(THETA), np.cos(THETA), 0.3 * np.cos(phi_e), 0.3 * np.sin(phi_e))  # k_E·ζ = 0.3
    h1 = harmonic(y, 1)
    assert abs(h1) == pytest.approx(0.3)
    assert np.angle(-h1) == pytest.approx(np.angle(np.exp(1j * phi_e)))  # −0.3·cos(θ + φ_e)
    assert np.mean(y) == pytest.approx(1.0) and abs(harmonic(y, 2)) < 1e-12


def test_population_kernel_is_bit_identical_to_single_runs():
    m = MonitorEma()
    K = np.random.default_rng(5).uniform(0, 1, (9, 8))
    rows = m.rows(K)
    _, theta_cmd = m.sample_grid(0.3)
    many = np.empty((9, len(theta_cmd)))
    simulate_lf_many(theta_cmd, rows, many)
    single = np.empty(len(theta_cmd))
    for r in range(9):
        simulate_lf(theta_cmd, rows[r], single, np.empty((0, N_AUX)))
        np.testing.assert_array_equal(single, many[r])
    assert not np.array_equal(many[0], many[1])


def test_index_constants_match_the_row_layout():
    # the kernel reads a row through hand-written constants (F_S, J, ..., N_LF); each must be the
    # position of its field in LF_FIELDS, or the LF model silently reads the wrong physics (A3)
    assert len(set(LF_FIELDS)) == len(LF_FIELDS) == N_FIELDS
    assert IDX == {name: j for j, name in enumerate(LF_FIELDS)}
    for j, name in enumerate(LF_FIELDS):
        assert getattr(lf_kernel, name.upper()) == j, name
    # and no other upper-case integer constant pretends to be a field index
    others = {"N_FIELDS", "N_AUX"}
    constants = {n for n, v in vars(lf_kernel).items() if n.isupper() and type(v) is int and n not in others}
    assert constants == {name.upper() for name in LF_FIELDS}


@pytest.mark.parametrize(
    "N", [(1.0, 1.0, 1.0), (0.7, 1.0, 1.0), (1.0, 0.55, 0.9), (0.6, 0.6, 0.6), (0.8, 0.5, 0.95)]
)
def test_unbalance_is_the_amplitude_of_the_2theta_pattern(N):
    # c2(θ) = Σ (1 − N_x)·cos(2θ − 2γ_x) is a pure 2θ term whose amplitude is |U|, 0 when balanced
    c2 = np.array([unbalance_2(np.sin(t), np.cos(t), *N) for t in THETA])
    assert abs(harmonic(c2, 2)) == pytest.approx(unbalance(*N), abs=1e-12)
    assert np.max(np.abs(c2)) == pytest.approx(unbalance(*N), abs=1e-4)
    assert abs(np.mean(c2)) < 1e-12
    if N[0] == N[1] == N[2]:
        assert unbalance(*N) == pytest.approx(0.0, abs=1e-12)


def test_the_loop_surrogate_carries_no_current_at_rest_and_opposes_the_voltage():
    args = dict(k_H=0.01, delta_2=-0.01, R_eq=0.5, k_e_eq=0.1, V_H=0.002)
    assert loop_error(0.0, 0.0, 0.3, 0.005, **args) == 0.0  # no demand, no motion: no current
    # the offset takes current off in the direction of the q-axis voltage R·i + k_e·ω
    assert 0.0 < loop_error(0.2, 0.0, 0.0, 0.005, **args) < 0.2
    assert -0.2 < loop_error(-0.2, 0.0, 0.0, 0.005, **args) < 0.0
    assert loop_error(0.0, 5.0, 0.0, 0.005, **args) == pytest.approx(-0.005)
    assert loop_error(0.0, -5.0, 0.0, 0.005, **args) == pytest.approx(0.005)
