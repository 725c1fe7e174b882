"""Borello friction, backlash and end-stops against their analytic behaviour."""

import numpy as np
import pytest

from emaphm.kernels.mechanics import MechanicsPack, backlash, friction_step, mechanics_step

J, F_S, F_D, dt = 5.125e-5, 0.02, 0.014, 1e-6


def run_friction(omega0, T_act, n):
    omega = omega0
    out = np.empty(n)
    for j in range(n):
        omega = friction_step(omega, T_act, dt, J, 0.0, F_S, F_D)
        out[j] = omega
    return out


def test_stuck_shaft_holds_below_breakaway():
    for T in (0.0, 0.5 * F_S, F_S, -F_S):
        assert np.all(run_friction(0.0, T, 1000) == 0.0)


def test_shaft_breaks_away_above_breakaway_with_dynamic_friction():
    T = 1.05 * F_S
    omega = run_friction(0.0, T, 1000)
    t = dt * np.arange(1, 1001)
    # once moving, dynamic friction opposes: omega = (T - F_D)/J * t
    np.testing.assert_allclose(omega, (T - F_D) / J * t, rtol=1e-9)
    assert np.all(run_friction(0.0, -T, 10) < 0)


def test_sliding_shaft_stops_exactly_and_sticks():
    omega0 = 2.0
    omega = run_friction(omega0, 0.5 * F_S, 40000)
    assert omega[-1] == 0.0
    stop = int(np.argmax(omega == 0.0))
    # deceleration (F_D - T)/J, stop time J*omega0/(F_D - T), to within one step
    t_stop = J * omega0 / (F_D - 0.5 * F_S)
    assert abs((stop + 1) * dt - t_stop) <= dt
    assert np.all(omega[stop:] == 0.0)  # stuck: 0.5 F_S < F_S holds it
    assert np.all(omega[:stop] > 0.0)  # never reverses through zero


def test_stick_slip_reverses_through_a_stop():
    # a reversing torque larger than breakaway: slide, stop exactly, break away the other way
    omega = run_friction(1.0, -2 * F_S, 5000)
    zero = np.flatnonzero(omega == 0.0)
    assert zero.size >= 1 and omega[0] > 0 and omega[-1] < 0


def test_backlash_user_side_still_inside_the_gap():
    B = 2e-3
    theta_u = 0.0
    for theta_g in np.linspace(-B / 2, B / 2, 101):  # gear output sweeps the whole gap
        theta_u = backlash(theta_g, theta_u, B)
        assert theta_u == 0.0
    # beyond the gap the flank drags the user along, B/2 behind
    assert backlash(B / 2 + 1e-4, 0.0, B) == pytest.approx(1e-4, abs=1e-15)
    assert backlash(-B / 2 - 1e-4, 0.0, B) == pytest.approx(-1e-4, abs=1e-15)
    # and on reversal it waits for the whole gap B before following
    assert backlash(1e-4 + B / 2 - B, 1e-4, B) == 1e-4


def test_end_stop_clamps_user_and_motor():
    mp = MechanicsPack(J, 0.0, F_S, F_D, 2e-4, 200.0, 0.9, 0.5, 0.0)
    theta_m, omega_m, theta_u = 200.0 * 0.499, 50.0, 0.499
    for _ in range(20000):  # a large torque drives into the stop
        theta_m, omega_m, theta_u = mechanics_step(theta_m, omega_m, theta_u, 0.5, dt, mp)
        assert theta_u <= 0.5
    assert theta_u == 0.5 and omega_m == 0.0
    assert theta_m == 200.0 * (0.5 + 1e-4)
    # pulling away leaves the stop
    for _ in range(1000):
        theta_m, omega_m, theta_u = mechanics_step(theta_m, omega_m, theta_u, -0.5, dt, mp)
    assert omega_m < 0.0 and theta_m < 200.0 * (0.5 + 1e-4)


def test_a_ripple_breaks_the_shaft_away_at_its_peak():
    # a mean torque below breakaway with a ripple whose peak exceeds it: the LF monitor's case
    T, ripple = 0.9 * F_S, 0.15 * F_S
    assert np.all(run_friction(0.0, T, 100) == 0.0)  # without the ripple it holds
    omega = friction_step(0.0, T, dt, J, 0.0, F_S, F_D, ripple)
    assert omega == pytest.approx(dt * (T - F_D) / J, rel=1e-12)  # slides against F_D
    assert friction_step(0.0, -T, dt, J, 0.0, F_S, F_D, ripple) < 0.0
    # a peak short of breakaway holds, and so does one whose mean cannot beat F_D
    assert friction_step(0.0, T, dt, J, 0.0, F_S, F_D, 0.05 * F_S) == 0.0
    assert friction_step(0.0, 0.5 * F_D, dt, J, 0.0, F_S, F_D, F_S) == 0.0
    # the ripple decides a breakaway only: a sliding shaft decelerates as without it
    assert friction_step(1.0, T, dt, J, 0.0, F_S, F_D, ripple) == friction_step(1.0, T, dt, J, 0.0, F_S, F_D)
