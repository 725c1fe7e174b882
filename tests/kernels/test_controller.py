import math

from emaphm.kernels.controller import ControllerPack, pid_step

cp = ControllerPack(60.0, 200.0, 3.5, 1e-3, 10.0, 1e-4, 200.0)


def test_proportional_action_and_sign():
    i_q_ref, integral, _omega_f = pid_step(0.01, 0.0, 0.0, 0.0, 0.0, cp)
    assert math.isclose(i_q_ref, 60.0 * 0.01)
    assert math.isclose(integral, 0.01 * 1e-4)


def test_derivative_on_filtered_measured_speed_opposes_motion():
    omega_f = 0.0
    for _ in range(200):  # 20 ms = 20 tau_D: the filter has settled
        i_q_ref, _, omega_f = pid_step(0.0, 0.0, 100.0, 0.0, omega_f, cp)
    assert math.isclose(omega_f, 100.0, rel_tol=1e-6)
    assert math.isclose(i_q_ref, -3.5 * 100.0 / 200.0, rel_tol=1e-6)


def test_speed_filter_time_constant():
    _, _, omega_f = pid_step(0.0, 0.0, 1.0, 0.0, 0.0, cp)
    assert math.isclose(omega_f, 1 - math.exp(-0.1), rel_tol=1e-12)  # one sample = 0.1 tau_D


def test_saturation_and_conditional_integration():
    i_q_ref, integral, _ = pid_step(1.0, 0.0, 0.0, 0.5, 0.0, cp)
    assert i_q_ref == 10.0 and integral == 0.5  # saturated, error pushes further: hold
    i_q_ref, integral, _ = pid_step(-0.01, 0.0, 0.0, 0.5, 0.0, cp)
    assert i_q_ref == 10.0 and integral < 0.5  # error pulls out of saturation: integrate
