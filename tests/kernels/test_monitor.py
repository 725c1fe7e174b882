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
    NO_AUX,
    loop_error,
    phi_ecc,
    phi_sc,
    phi_t,
    shape_harmonics,
    shapes,
    simulate_lf,
    simulate_lf2,
    simulate_lf_many,
    unbalance,
    unbalance_2,
)
from emaphm.kernels.pmsm_abc import couplings, ecc_harmonics, stator_pack
from emaphm.kernels.transforms import phase_directions

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


def twin_torque_per_amp(N, zeta, phi_e):
    """Σ_x g_x·u_x over THETA: the twin's torque per unit i_q with i_x = i_q·u_x (k_e = 1), from its
    own coupling g_x = ∂ψ_x/∂θ (`pmsm_abc.couplings`): an independent reference for `phi_t`."""
    sp = stator_pack(48.0, 0.1, 4.0, (0.5,) * 3, (1e-3,) * 3, N, zeta, phi_e)
    s, c = np.sin(THETA), np.cos(THETA)
    g = couplings(s, c, sp)
    u = phase_directions(s, c)
    return sum(g_x * u_x for g_x, u_x in zip(g, u, strict=True))


@pytest.mark.parametrize(
    ("N", "zeta", "phi_e"),
    [
        ((0.5, 0.53, 0.93), 0.23, 0.5191 * 2 * np.pi),
        ((1.0, 0.6, 1.0), 0.3, 1.0),
        ((0.8, 0.95, 0.55), 0.1, 4.0),
    ],
)
def test_per_phase_torque_shape_is_the_twins_torque_per_amp(N, zeta, phi_e):
    # with k_E = 1 the k_FS part of φ_T is Σ_x N_x·u_x·(u_x + ζ·sin(2θ_e + φ_e − γ_x)), the twin's
    # torque per unit i_q from its eccentric flux linkage; the paper's φ_SC·φ_ECC is not, with
    # shorts in some phases and eccentricity together (a 1θ_e term no flux linkage gives)
    k_FT, k_FS = 0.01, 40.0
    s, c = np.sin(THETA), np.cos(THETA)
    f_ecc = phi_ecc(s, c, zeta * np.cos(phi_e), zeta * np.sin(phi_e))
    twin = twin_torque_per_amp(N, zeta, phi_e)
    ours = (phi_t(s, c, *N, k_FT, k_FS, f_ecc, ecc_harmonics(zeta, phi_e)) - k_FT * sum(N) * f_ecc) / (
        k_FT * k_FS
    )
    np.testing.assert_allclose(ours, twin, atol=1e-12)
    paper = (phi_sc(s, c, *N, k_FT, k_FS) * f_ecc - k_FT * sum(N) * f_ecc) / (k_FT * k_FS)
    assert np.max(np.abs(paper - twin)) > 0.1 * zeta * abs(unbalance(*N))
    # the twin's torque has a 3θ_e term ∝ ζ·|U| and no 1θ_e term beyond −(ζ/2)·Σ N_x·cos(θ_e + φ_e)
    assert abs(harmonic(twin, 1) + 0.5 * zeta * sum(N) * np.exp(1j * phi_e)) < 1e-12
    assert abs(harmonic(ours, 3)) == pytest.approx(0.5 * zeta * unbalance(*N), rel=1e-9)


@pytest.mark.parametrize("n", [1.0, 0.6])
def test_per_phase_torque_shape_is_the_papers_product_for_a_balanced_winding(n):
    s, c = np.sin(THETA), np.cos(THETA)
    zeta, phi_e, k_FT, k_FS = 0.25, 2.0, 0.0067, 97.0
    f_ecc = phi_ecc(s, c, zeta * np.cos(phi_e), zeta * np.sin(phi_e))
    ours = phi_t(s, c, n, n, n, k_FT, k_FS, f_ecc, ecc_harmonics(zeta, phi_e))
    np.testing.assert_allclose(ours, phi_sc(s, c, n, n, n, k_FT, k_FS) * f_ecc, rtol=1e-12)


def test_monitor_structure_follows_the_monitor_name():
    # the default monitor takes φ_T from the eccentric flux linkage, the paper's keeps eqs. 1-2
    K = np.array([[0.1, 0.1, 0.5, 0.45, 0.05, 0.25, 0.5, 0.5]])
    default, paper = MonitorEma(), MonitorEma(monitor="paper")
    assert default.rows(K)[0, IDX["ecc_coupling"]] == 1.0
    assert paper.rows(K)[0, IDX["ecc_coupling"]] == 0.0
    # the same coefficients under both structures: the shorts and the eccentricity meet, so the
    # currents differ; a balanced, concentric machine runs the same either way
    rows = default.rows(np.vstack([K, [0.1, 0.1, 0.0, 0.0, 0.0, 0.0, 0.5, 0.5]]))
    other = rows.copy()
    other[:, IDX["ecc_coupling"]] = 0.0
    _, theta_cmd = default.sample_grid(0.3)
    a, b = np.empty((2, len(theta_cmd))), np.empty((2, len(theta_cmd)))
    simulate_lf_many(theta_cmd, rows, a)
    simulate_lf_many(theta_cmd, other, b)
    assert np.max(np.abs(a[0] - b[0])) > 1e-3
    np.testing.assert_allclose(a[1], b[1], atol=1e-9)


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


def test_interleaved_pairs_are_bit_identical_to_single_runs_of_any_two_rows():
    # the pair kernel steps two rows in one loop (issue 36); every row must still be simulate_lf's
    # to the bit, whatever the two rows' drives, monitor structures and steps per sample
    from emaphm.params import EmaParams, InverterParams

    K = np.random.default_rng(11).uniform(0, 1, (4, 8))
    hysteresis = MonitorEma().rows(K)
    foc = MonitorEma(EmaParams(inverter=InverterParams(control="foc")), allow_mismatch=True).rows(K)
    paper = MonitorEma(monitor="paper").rows(K)
    two_steps = hysteresis[3].copy()
    two_steps[IDX["n_lf"]] = 2.0
    _, theta_cmd = MonitorEma().sample_grid(0.3)
    no_aux = np.empty((0, N_AUX))

    def single(row):
        out = np.empty(len(theta_cmd))
        simulate_lf(theta_cmd, row, out, no_aux)
        return out

    pairs = [(hysteresis[0], foc[1]), (foc[2], paper[0]), (paper[1], hysteresis[2]), (two_steps, hysteresis[1]),
             (hysteresis[0], hysteresis[0])]  # fmt: skip
    for a, b in pairs:
        out_a, out_b = np.full(len(theta_cmd), np.nan), np.full(len(theta_cmd), np.nan)
        simulate_lf2(theta_cmd, a, b, out_a, out_b, NO_AUX)
        np.testing.assert_array_equal(out_a, single(a))
        np.testing.assert_array_equal(out_b, single(b))
    assert not np.array_equal(single(hysteresis[0]), single(foc[1]))  # the pairs mixed different runs


def test_index_constants_match_the_row_layout():
    # the kernel reads a row through hand-written constants (F_S, J, ..., N_LF); each must be the
    # position of its field in LF_FIELDS, or the LF model silently reads the wrong physics (A3)
    assert len(set(LF_FIELDS)) == len(LF_FIELDS) == N_FIELDS
    assert IDX == {name: j for j, name in enumerate(LF_FIELDS)}
    for j, name in enumerate(LF_FIELDS):
        assert getattr(lf_kernel, name.upper()) == j, name
    # and no other upper-case integer constant pretends to be a field index
    others = {"N_FIELDS", "N_AUX", "PAIR_MIN_ROWS", "ANGLE_RESYNC"}
    constants = {n for n, v in vars(lf_kernel).items() if n.isupper() and type(v) is int and n not in others}
    assert constants == {name.upper() for name in LF_FIELDS}


def test_the_carried_angle_follows_libm_to_rounding():
    # `advance_angle` rotates sin θ_e and cos θ_e through each step's turn instead of calling libm:
    # over a whole resync period of random turns up to ROTATION_MAX (either sign, from any angle,
    # p = 4 as the actuator's) it stays within a few ulp of libm's values of the angle reached,
    # and on the unit circle; a turn beyond ROTATION_MAX and the ANGLE_RESYNC-th step are libm's own
    rng = np.random.default_rng(3)
    p, worst = 4.0, 0.0
    for _ in range(200):
        theta = rng.uniform(-50.0, 50.0)
        s, c, n = np.sin(p * theta), np.cos(p * theta), 0
        for _ in range(lf_kernel.ANGLE_RESYNC - 1):
            new = theta + rng.uniform(-1.0, 1.0) * lf_kernel.ROTATION_MAX / p
            s, c, n = lf_kernel.advance_angle(s, c, n, p, theta, new)
            theta = new
            worst = max(worst, abs(s - np.sin(p * theta)), abs(c - np.cos(p * theta)), abs(s * s + c * c - 1.0))
        assert n == lf_kernel.ANGLE_RESYNC - 1
        s, c, n = lf_kernel.advance_angle(s, c, n, p, theta, theta + 1e-4)
        assert (s, c, n) == (np.sin(p * (theta + 1e-4)), np.cos(p * (theta + 1e-4)), 0)
    assert 0.0 < worst < 1e-14
    big = 1.01 * lf_kernel.ROTATION_MAX / p
    assert lf_kernel.advance_angle(0.3, 0.9, 3, p, 1.0, 1.0 + big) == (np.sin(p * (1.0 + big)), np.cos(p * (1.0 + big)), 0)


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


@pytest.mark.parametrize("seed", range(6))
def test_the_steps_trig_polynomials_are_the_shape_functions(seed):
    """The step evaluates φ_SC, φ_T and c₂ from run constants (`shape_harmonics`, `shapes`): the
    same functions as eqs. 1-2, `phi_t` and `unbalance_2` at every angle, to rounding, with either
    coupling."""
    rng = np.random.default_rng(seed)
    N = rng.uniform(0.4, 1.0, 3) if seed else np.ones(3)
    k_FT, k_FS, kz, phi_e = rng.uniform(0.005, 2.0), rng.uniform(0.0, 100.0), rng.uniform(0.0, 0.5), rng.uniform(-3.2, 3.2)
    hz = shape_harmonics(*N, k_FT, k_FS, kz, phi_e)
    kz_cos, kz_sin = kz * np.cos(phi_e), kz * np.sin(phi_e)
    for t in THETA[::7]:
        s, c = np.sin(t), np.cos(t)
        f_ecc = phi_ecc(s, c, kz_cos, kz_sin)
        scale = k_FT * (1.0 + k_FS)
        f_sc, f_t, c2 = shapes(s, c, hz, True, kz_cos, kz_sin)
        assert f_sc == pytest.approx(phi_sc(s, c, *N, k_FT, k_FS), abs=1e-13 * scale)
        assert f_t == pytest.approx(phi_t(s, c, *N, k_FT, k_FS, f_ecc, ecc_harmonics(kz, phi_e)), abs=1e-13 * scale)
        assert c2 == pytest.approx(unbalance_2(s, c, *N), abs=1e-14)
        _, paper, _ = shapes(s, c, hz, False, kz_cos, kz_sin)
        assert paper == pytest.approx(phi_sc(s, c, *N, k_FT, k_FS) * f_ecc, abs=1e-13 * scale)


def test_the_saturated_tanh_is_libms_to_the_bit():
    import math

    x = np.concatenate([np.linspace(-40.0, 40.0, 8001), [21.999999, 22.0, 22.000001, -22.0, 1e300, -1e300, np.inf, -np.inf]])
    for v in x:
        assert lf_kernel.saturated_tanh(v) == math.tanh(v)
    assert np.isnan(lf_kernel.saturated_tanh(np.nan))
