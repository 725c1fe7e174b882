"""The monitor's FOC current loop (`kernels.monitor.foc_loop_step`) against independent references.

1. On a locked rotor with unit shape functions the loop is linear and time-invariant: its
   response to a step of i_ref must be the step response of the closed loop built as a transfer
   function in z (scipy.signal), C(z)·z^-d·P(z)/(1 + C(z)·z^-d·P(z)) with the PI
   C(z) = K_p + K_i·h/(z − 1), the delay z^-d and the Euler-discretised plant
   P(z) = g/(z − 1 + g·R), g = h/L.
2. Against the FOC twin: the monitor with its FOC loop explains a healthy FOC actuator's current
   better than the hysteresis-loop monitor does (the calibration only refines this).
"""

import numpy as np
import pytest
from scipy import signal

from emaphm.kernels.monitor import IDX, N_FIELDS, foc_loop_step, foc_pack

L, R, H = 1.5e-3, 0.5, 50e-6


def row(K_p, K_i, delay, n_u=1, V_lim=1e6):
    prm = np.zeros(N_FIELDS)
    for name, value in dict(L_eq=L, R_eq=R, k_e_eq=0.1, K_p_i=K_p, K_i_i=K_i, delay=delay, n_u=n_u,
                            k_e_ff=0.0, V_lim=V_lim, foc=1.0).items():  # fmt: skip
        prm[IDX[name]] = value
    return prm


def loop_steps(prm, n, i_ref=1.0):
    """The loop's current after each update (n_u = 1: one update per call)."""
    i = I = v1 = v2 = 0.0
    out = np.empty(n)
    for j in range(n):
        i, I, v1, v2, _ = foc_loop_step(i, I, v1, v2, i_ref, 0.0, 1.0, 1.0, H, foc_pack(prm))
        out[j] = i
    return out


def transfer_step(K_p, K_i, delay, n):
    g = H / L
    C = np.polyadd(np.polymul([K_p], [1.0, -1.0]), [K_i * H])  # C(z) = (K_p·(z − 1) + K_i·h)/(z − 1)
    num = np.polymul(C, [g])
    den_open = np.polymul(np.polymul([1.0, -1.0], [1.0, -1.0 + g * R]), [1.0] + [0.0] * delay)
    den = np.polyadd(den_open, num)
    _, (y,) = signal.dstep(signal.dlti(num, den, dt=H), n=n + 1)
    return y[1:, 0]


@pytest.mark.parametrize("delay", [0, 1, 2])
@pytest.mark.parametrize("K_p, K_i", [(9.42, 3141.6), (9.42, 14797.0), (4.0, 500.0)])
def test_a_step_follows_the_closed_loop_transfer_function(K_p, K_i, delay):
    n = 200
    loop = loop_steps(row(K_p, K_i, delay), n)
    np.testing.assert_allclose(loop, transfer_step(K_p, K_i, delay, n), rtol=1e-9, atol=1e-12)


def test_wrong_gains_or_delay_do_not_match_the_transfer_function():
    # the comparison above can fail: 20 % off in K_p, or one update of delay more, is seen
    loop = loop_steps(row(9.42, 3141.6, 1), 100)
    assert np.max(np.abs(loop - transfer_step(1.2 * 9.42, 3141.6, 1, 100))) > 0.02
    assert np.max(np.abs(loop - transfer_step(9.42, 3141.6, 2, 100))) > 0.02


def test_pole_zero_cancellation_gives_the_first_order_bandwidth():
    # K_p = L·ω_c, K_i = R·ω_c: without delay the PI's zero cancels the plant's pole and the loop is
    # first order: i_n = 1 − (1 − ω_c·h)^n (the Euler image of 1 − e^(−ω_c·t)), to rounding
    w_c = 2 * np.pi * 1e3
    i = loop_steps(row(L * w_c, R * w_c, 0), 200)
    n = np.arange(1, 201)
    np.testing.assert_allclose(i, 1 - (1 - w_c * H) ** n, atol=1e-12)
    t63 = np.interp(1 - np.exp(-1), i, H * n)
    assert t63 == pytest.approx(1 / w_c, rel=0.2)  # near the continuous loop's 1/ω_c
    assert i[-1] == pytest.approx(1.0, abs=1e-6)  # the integrator leaves no error


def test_the_voltage_limit_holds_the_integrator():
    prm = row(9.42, 3141.6, 1, V_lim=1.0)
    i = I = v1 = v2 = 0.0
    i, I, v1, v2, _ = foc_loop_step(i, I, v1, v2, 5.0, 0.0, 1.0, 1.0, H, foc_pack(prm))
    assert v1 == 1.0 and I == 0.0  # limited: the demanded 47 V held at 1 V, nothing integrated


@pytest.mark.slow
def test_the_foc_monitor_explains_an_foc_twin_better_than_the_hysteresis_monitor():
    from emaphm.identification.signals import lowpass
    from emaphm.models.hf import HighFidelityEma
    from emaphm.models.lf import MonitorEma
    from emaphm.params import EmaParams, InverterParams

    foc, hysteresis = EmaParams(inverter=InverterParams(control="foc")), EmaParams()
    k = np.array([0.2, 0.3, 0.25, 0.1, 0.0, 0.2, 0.4, 0.5])
    twin = lowpass(HighFidelityEma(foc).simulate(k, noise=False).i_q, 1e4)

    def nrmse(params):
        lf = lowpass(MonitorEma(params, allow_mismatch=True).simulate(k).i_q, 1e4)
        return np.linalg.norm(lf - twin) / np.linalg.norm(twin - twin.mean())

    with_foc, with_hysteresis = nrmse(foc), nrmse(hysteresis)
    assert with_foc < 0.05
    assert with_hysteresis > 1.5 * with_foc


def test_the_monitor_rows_carry_the_actuator_files_drive():
    from emaphm.models.lf import drive_fields
    from emaphm.params import EmaParams, InverterParams

    assert drive_fields(EmaParams(), 1)["foc"] == 0.0  # hysteresis: the lag τ_i
    inv = InverterParams(control="foc", f_pwm=16e3, update="double", computation_delay=2,
                         emf_feedforward=False, modulation="sine", voltage_limit=0.9, K_p_i=5.0)  # fmt: skip
    f = drive_fields(EmaParams(inverter=inv), 1)
    # 100 µs LF step over a 31.25 µs update period: 3 PI updates per step (the nearest whole number)
    assert f == {"foc": 1.0, "K_p_i": 5.0, "K_i_i": inv.K_i_i, "n_u": 3.0, "delay": 2.0, "k_e_ff": 0.0,
                 "V_lim": pytest.approx(0.9 * 48.0 / 2)}  # fmt: skip
    assert drive_fields(EmaParams(inverter=InverterParams(control="foc")), 2)["n_u"] == 1.0  # 50 µs steps
    assert drive_fields(EmaParams(inverter=InverterParams(control="foc")), 1)["k_e_ff"] == pytest.approx(0.1)


def test_the_last_stages_switching_model_is_the_actuators_foc_drive_at_other_steps():
    # issue 32, item 4: for an FOC actuator the last stage's switching model runs the FOC drive
    import dataclasses

    from emaphm.commands import Chirp
    from emaphm.identification.last_stage import SwitchingModel
    from emaphm.models.hf import HighFidelityEma
    from emaphm.params import EmaParams, InverterParams

    foc = EmaParams(inverter=InverterParams(control="foc", K_p_i=7.0))
    model = SwitchingModel(foc, Chirp())
    assert all(m.params.inverter == foc.inverter for m in model.models)
    assert sorted(m.params.integration.dt for m in model.models) == pytest.approx([1.25e-6, 2e-6, 2.5e-6])
    k = np.array([0.1, 0.1, 0.0, 0.2, 0.0, 0.1, 0.3, 0.5])
    current = model.current(k, duration=0.05)
    twin = HighFidelityEma(dataclasses.replace(foc, integration=dataclasses.replace(foc.integration, dt=2e-6)))
    hysteresis = HighFidelityEma(dataclasses.replace(EmaParams(), integration=foc.integration))
    i_foc = twin.simulate(k, noise=False, duration=0.05).i_q
    i_hys = hysteresis.simulate(k, noise=False, duration=0.05).i_q
    # the mean over its steps is near its FOC drive's current, farther from a hysteresis drive's
    assert np.linalg.norm(current - i_foc) < 0.5 * np.linalg.norm(current - i_hys)
