"""The ProgPy adapter (issue 12): the fault-growth model, the UKF with a per-measurement R, the
closed-form crossing against ProgPy's own MonteCarlo predictor, ProgPy's metrics, and the core
without ProgPy."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from emaphm.campaign.store import ResultStore
from emaphm.prognostics import DegradationTrend
from tests.helpers import run_cli
from tests.test_prognostics import _rows

pytest.importorskip("progpy")

from emaphm.prognostics import progpy_model as pm


def _linear(seed=1, n=20, start=0.05, slope=0.015, sd=0.01):
    rng = np.random.default_rng(seed)
    t = np.arange(1.0, n + 1.0)
    return t, start + slope * t + rng.normal(0.0, sd, n), np.full(n, sd)


def test_the_ukf_on_a_linear_law_is_the_weighted_regression():
    # a linear law without process noise is a linear-Gaussian model: the UKF is exact there, and
    # its posterior must be the Bayesian regression's (the trend's) up to the priors
    t, k, sd = _linear()
    model, ukf = pm.track("friction", "linear", 0.45, t, k, sd)
    trend = DegradationTrend("linear").update(t, k, sd)
    mean, cov = trend.fit()
    level_now = mean[0] + mean[1] * t[-1]
    assert ukf.filter.x[0] == pytest.approx(level_now, abs=2e-3)
    assert ukf.filter.x[1] == pytest.approx(mean[1], rel=0.01)
    assert math.sqrt(ukf.filter.P[1, 1]) == pytest.approx(math.sqrt(cov[1, 1]), rel=0.1)
    ukf_rul, trend_rul = pm.predict_rul(model, ukf, n=4000, seed=3), trend.predict_rul(0.45, n=4000, seed=3)
    assert ukf_rul.median == pytest.approx(trend_rul.median, rel=0.02)
    assert ukf_rul.p95 - ukf_rul.p05 == pytest.approx(trend_rul.p95 - trend_rul.p05, rel=0.15)


def test_each_update_takes_its_own_measurement_variance():
    # ProgPy's UKF keeps R fixed unless it is set before each update: an outlier given a huge
    # variance must leave the estimate where it is without it, and one given the common variance
    # must move it
    t, k, sd = _linear(n=12)
    keep = np.arange(12) != 6
    _, clean = pm.track("friction", "linear", 0.45, t[keep], k[keep], sd[keep])  # flight 7 not measured
    with_outlier = [*k[:6], 0.9, *k[7:]]
    _, ignored = pm.track("friction", "linear", 0.45, t, with_outlier, [*sd[:6], 1e3, *sd[7:]])
    _, trusted = pm.track("friction", "linear", 0.45, t, with_outlier, sd)
    np.testing.assert_allclose(ignored.filter.x, clean.filter.x, atol=1e-5)
    assert abs(trusted.filter.x[0] - clean.filter.x[0]) > 0.02


def test_measurements_of_one_flight_are_pooled_by_precision():
    t, k, sd = _linear(n=10)
    _, once = pm.track("backlash", "linear", 0.25, t, k, sd)
    # each flight measured twice with sd * sqrt(2): the same information
    _, twice = pm.track(
        "backlash", "linear", 0.25, np.repeat(t, 2), np.repeat(k, 2), np.repeat(sd, 2) * math.sqrt(2)
    )
    np.testing.assert_allclose(twice.filter.x, once.filter.x, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(twice.filter.P, once.filter.P, rtol=1e-6)


@pytest.mark.parametrize("law", ["linear", "exponential"])
def test_the_closed_form_crossing_matches_progpys_montecarlo_predictor(law):
    t = np.arange(1.0, 21.0)
    if law == "linear":
        k, sd, threshold = 0.05 + 0.015 * t, np.full(20, 0.01), 0.45
    else:
        k = 0.02 * np.exp(0.08 * t)
        sd, threshold = 0.03 * k + 0.002, 0.2
    model, ukf = pm.track("short_b" if law == "exponential" else "friction", law, threshold, t, k, sd)
    closed = pm.predict_rul(model, ukf, n=400, seed=5)
    (event,) = model.events
    simulated = pm.montecarlo_toe(model, ukf, n=400, seed=5, dt=0.05)[event] - t[-1]
    # the same draws, simulated in steps of 0.05 flight: the medians agree to the step
    assert np.median(simulated) == pytest.approx(closed.median, abs=0.06)
    truth = (threshold - 0.05) / 0.015 - 20 if law == "linear" else math.log(threshold / 0.02) / 0.08 - 20
    assert closed.p05 <= truth <= closed.p95


def test_never_crossing_draws_are_inf_and_progpys_metrics_take_them():
    t = np.arange(1.0, 21.0)
    model, ukf = pm.track("friction", "linear", 0.45, t, np.full(20, 0.1), np.full(20, 0.01))
    est = pm.predict_rul(model, ukf, n=1000)
    assert 0.3 < est.never < 0.7 and not math.isfinite(est.p95)
    toe = pm.montecarlo_toe(model, ukf, n=50, horizon=30.0, dt=1.0)["friction_failure"]
    assert np.isinf(toe).mean() > 0.9  # ProgPy's None, made inf
    profile = pm.toe_profile({20.0: {"friction_failure": toe}, 21.0: {"friction_failure": toe}}, never=1e4)
    metrics = pm.progpy_metrics(profile, {"friction_failure": 60.0}, lambda_value=20.0, onset=1.0)
    assert metrics["friction_failure"]["alpha_lambda"] is False  # computed, not a TypeError


def test_progpys_metrics_on_a_perfect_and_a_biased_profile():
    truth, onset = 41.0, 1.0
    rng = np.random.default_rng(0)
    spread = rng.normal(0.0, 0.5, 500)
    perfect = pm.toe_profile({float(f): {"e": truth + spread} for f in range(5, 40, 5)}, never=1e4)
    m = pm.progpy_metrics(perfect, {"e": truth}, lambda_value=21.0, onset=onset)["e"]
    assert m["alpha_lambda"] is True and m["prognostic_horizon"] == pytest.approx(truth - 5.0)
    assert m["cra"] > 0.95
    late = pm.toe_profile({float(f): {"e": truth + 15 + spread} for f in range(5, 40, 5)}, never=1e4)
    m = pm.progpy_metrics(late, {"e": truth}, lambda_value=21.0, onset=onset)["e"]
    # ProgPy's relative accuracy is of the time of event (from flight 0), not of the RUL
    assert m["alpha_lambda"] is False and m["cra"] == pytest.approx(1 - 15 / truth, abs=0.01)
    assert m["prognostic_horizon"] is None  # 15 flights late is never within 0.2 * 40 = 8


def test_the_model_refuses_what_it_cannot_represent():
    from emaphm.errors import InputError

    with pytest.raises(InputError, match="unknown law"):
        pm.FaultGrowth({"friction": ("quadratic", 0.45)})
    with pytest.raises(InputError, match="> 0"):
        pm.FaultGrowth({"friction": ("linear", 0.0)})
    m = pm.FaultGrowth({"friction": ("linear", 0.45), "short_a": ("exponential", 0.2)})
    assert m.states == ["friction", "friction_rate", "short_a_log", "short_a_rate"]
    assert m.outputs == ["friction", "short_a_log"]  # the exponential law is observed in log space
    with pytest.raises(InputError, match="rate_walk"):
        pm.FaultGrowth({"friction": ("linear", 0.45)}, rate_walk=float("nan"))
    with pytest.raises(InputError, match="whole numbers"):
        pm.track("friction", "linear", 0.45, [0.2, 0.9, 1.0], [0.1, 0.2, 0.3], [0.01] * 3)
    x = m.StateContainer(
        {"friction": 0.3, "friction_rate": 0.01, "short_a_log": math.log(0.1), "short_a_rate": 0.1}
    )
    nxt = m.next_state(x, m.InputContainer({}), 5.0)
    assert nxt["friction"] == pytest.approx(0.35) and math.exp(nxt["short_a_log"]) == pytest.approx(
        0.1 * math.e**0.5
    )
    assert m.event_state(x)["friction_failure"] == pytest.approx(1 - 0.3 / 0.45)
    assert m.threshold_met(m.StateContainer({**x, "friction": 0.46}))["friction_failure"]


def test_cli_rul_with_the_ukf(tmp_path, capsys):
    flights = np.arange(1, 21)
    ResultStore(tmp_path / "s").write(
        "results", _rows("A1", flights, 0.05 + 0.01 * flights, 0.005, detected_from=1)
    )
    args = ["rul", str(tmp_path / "s"), "--actuator", "A1", "--threshold", "friction=0.45", "--json"]
    code, out, _ = run_cli([*args, "--estimator", "ukf"], capsys)
    ukf = json.loads(out)
    code_t, out_t, _ = run_cli(args, capsys)
    trend = json.loads(out_t)
    assert code == code_t == 0 and ukf["estimator"] == "ukf" and trend["estimator"] == "trend"
    assert ukf["faults"]["friction"]["rul_median"] == pytest.approx(20.0, abs=0.5)
    assert ukf["faults"]["friction"]["rul_median"] == pytest.approx(
        trend["faults"]["friction"]["rul_median"], abs=0.3
    )
    code, _, err = run_cli([*args, "--estimator", "kalman"], capsys)
    assert code == 2 and "unknown estimator" in err


@pytest.mark.parametrize("gap", [5, 10, 25])
def test_an_exponential_fault_measured_flights_apart(gap):
    # the short grows 0.6 % per flight from 0.01, measured 20 times every `gap` flights, noise-free
    # with a 5 % deviation: the UKF observes ln d, so the spacing cannot break its sigma points (a
    # review found a posterior d of 3e5 at a gap of 10 when d itself was observed)
    t = 1.0 + gap * np.arange(20)
    k = 0.01 * np.exp(0.006 * (t - 1))
    model, ukf = pm.track("short_a", "exponential", 0.2, t, k, 0.05 * k)
    est = pm.predict_rul(model, ukf, n=4000, seed=1)
    truth = math.log(20.0) / 0.006 + 1 - t[-1]  # 24 flights after the last at a gap of 25
    assert est.median == pytest.approx(truth, rel=0.03) and est.p05 <= truth <= est.p95
    trend = DegradationTrend("exponential").update(t, k, 0.05 * k).predict_rul(0.2, n=4000, seed=1)
    assert est.median == pytest.approx(trend.median, rel=0.03)


def test_a_fault_already_past_its_threshold_has_failed_in_both_estimators():
    t = np.arange(1.0, 21.0)
    flat = np.full(20, 0.5)  # above 0.45 all along, no growth: failed, not "never"
    model, ukf = pm.track("friction", "linear", 0.45, t, flat, np.full(20, 0.01))
    assert pm.predict_rul(model, ukf).p95 == 0.0
    assert DegradationTrend().update(t, flat, np.full(20, 0.01)).predict_rul(0.45).p95 == 0.0


def test_a_rate_walk_follows_a_rate_that_changes():
    # friction grows 0.01 per flight for 20 flights, then 0.03: a walking rate catches up, a
    # constant one averages the two
    t = np.arange(1.0, 41.0)
    k = np.where(t <= 20, 0.01 * t, 0.2 + 0.03 * (t - 20))
    _, still = pm.track("friction", "linear", 0.9, t, k, np.full(40, 0.005))
    _, walking = pm.track("friction", "linear", 0.9, t, k, np.full(40, 0.005), rate_walk=0.003)
    assert abs(walking.filter.x[1] - 0.03) < 0.003 < abs(still.filter.x[1] - 0.03)
    # the walk is per flight: the last gap of 10 flights adds 9 x 0.01^2 more rate variance than
    # a gap of 1 (the last measurement carries nothing)
    kw = {"rate_walk": 0.01}
    _, one = pm.track("friction", "linear", 0.9, [1, 2, 3], [0.1, 0.11, 0.12], [0.01, 0.01, 1e3], **kw)
    _, ten = pm.track("friction", "linear", 0.9, [1, 2, 12], [0.1, 0.11, 0.12], [0.01, 0.01, 1e3], **kw)
    assert ten.filter.P[1, 1] - one.filter.P[1, 1] == pytest.approx(9 * 0.01**2, rel=0.05)
