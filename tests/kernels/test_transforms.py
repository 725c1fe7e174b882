import numpy as np

from emaphm.kernels.transforms import clarke, inverse_clarke, inverse_park, park, q_error


def test_clarke_park_round_trip():
    rng = np.random.default_rng(1)
    i_d, i_q = rng.normal(size=200), rng.normal(size=200)
    theta_e = rng.uniform(-20, 20, 200)
    i_a, i_b, i_c = inverse_clarke(*inverse_park(i_d, i_q, theta_e))
    d, q = park(*clarke(i_a, i_b, i_c), theta_e)
    # float64 round-off on O(1) values
    np.testing.assert_allclose(d, i_d, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q, i_q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(i_a + i_b + i_c, 0.0, atol=1e-12)


def test_balanced_set_gives_amplitude_on_q_axis():
    # i_x = -I sin(theta_e - gamma_x) is the i_d = 0 reference of DESIGN §3.3
    theta_e = np.linspace(0, 6 * np.pi, 500)
    amp = 0.37
    gam = np.array([0.0, 2 * np.pi / 3, -2 * np.pi / 3])
    i_a, i_b, i_c = (-amp * np.sin(theta_e - g) for g in gam)
    d, q = park(*clarke(i_a, i_b, i_c), theta_e)
    np.testing.assert_allclose(q, amp, atol=1e-12)
    np.testing.assert_allclose(d, 0.0, atol=1e-12)


def test_homopolar_current_is_invisible():
    # a common-mode current adds nothing to alpha/beta (amplitude-invariant Clarke)
    a, b = clarke(1.0 + 0.3, -0.5 + 0.3, -0.5 + 0.3)
    a0, b0 = clarke(1.0, -0.5, -0.5)
    assert abs(a - a0) < 1e-15 and abs(b - b0) < 1e-15


def test_q_error_is_clarke_then_park_to_the_bit():
    # the twin's measured i_q adds the phase currents' conversion error through Clarke and Park
    # (models/hf.py): the loop kernel gives the numbers of the two array transforms exactly,
    # angles of any size included
    rng = np.random.default_rng(11)
    n = 5000
    e_a, e_b, e_c = rng.normal(0.0, 1e-3, (3, n))
    theta = np.concatenate([rng.uniform(-3.0, 3.0, n // 2), rng.uniform(-2e3, 2e3, n - n // 2)])
    i_q = rng.normal(0.0, 5.0, n)
    out = np.empty(n)
    q_error(e_a, e_b, e_c, theta, i_q, out)
    alpha, beta = clarke(e_a, e_b, e_c)
    np.testing.assert_array_equal(out, i_q + park(alpha, beta, theta)[1])
    assert not np.array_equal(out, i_q)
