import numpy as np

from emaphm.kernels.transforms import clarke, inverse_clarke, inverse_park, park


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
