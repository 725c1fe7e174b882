"""Prognostics (issue 12): the trend model against known laws, and the RUL of a store's actuator."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from emaphm.campaign.store import RESULT_COLUMNS, ResultStore
from emaphm.errors import InputError
from emaphm.prognostics import DegradationTrend, parse_thresholds, rul_report
from tests.helpers import run_cli


def _history(rng, t, start, slope, sd):
    return start + slope * t + rng.normal(0.0, sd, len(t))


def test_a_linear_trend_predicts_the_crossing_and_its_range_covers_it():
    # 300 histories k = 0.05 + g·t + noise (sd 0.01), observed at flights 1..20, threshold 0.45:
    # the true RUL from flight 20 is (0.45 - 0.05)/g - 20
    rng = np.random.default_rng(1)
    inside, errors = 0, []
    for i in range(300):
        g = rng.uniform(0.01, 0.02)
        t = np.arange(1.0, 21.0)
        trend = DegradationTrend("linear").update(t, _history(rng, t, 0.05, g, 0.01), np.full(20, 0.01))
        est = trend.predict_rul(0.45, seed=i)
        truth = (0.45 - 0.05) / g - 20.0
        inside += est.p05 <= truth <= est.p95
        errors.append(est.median / truth - 1.0)
    assert 0.84 <= inside / 300 <= 0.96  # a 90 % range covers the truth ~90 % of the time
    assert abs(np.median(errors)) < 0.03


def test_each_measurement_weighs_by_its_own_variance():
    t = np.arange(1.0, 11.0)
    k = 0.1 + 0.01 * t
    with_outlier = DegradationTrend().update([*t, 11.0], [*k, 0.9], [*np.full(10, 0.005), 1e3])
    without = DegradationTrend().update(t, k, np.full(10, 0.005))
    np.testing.assert_allclose(with_outlier.fit()[0], without.fit()[0], rtol=1e-6, atol=1e-9)
    same_weight = DegradationTrend().update([*t, 11.0], [*k, 0.9], np.full(11, 0.005))
    assert same_weight.fit()[0][1] > 1.5 * without.fit()[0][1]  # an equally trusted outlier does move it


def test_an_exponential_trend_and_one_that_never_crosses():
    t = np.arange(1.0, 31.0)
    k = 0.01 * np.exp(0.05 * t)
    est = DegradationTrend("exponential").update(t, k, 0.02 * k).predict_rul(0.2)
    assert est.median == pytest.approx(math.log(20.0) / 0.05 - 30.0, rel=0.02)  # 29.9 flights
    flat = DegradationTrend().update(t, np.full(30, 0.1), np.full(30, 0.01)).predict_rul(0.45)
    assert flat.never > 0.3 and flat.to_json()["rul_p95"] is None  # never crossing: "beyond", not a number
    healthy_gain = DegradationTrend("linear", healthy=0.5).update(t, 0.5 - 0.004 * t, np.full(30, 0.002))
    assert healthy_gain.predict_rul(0.3).median == pytest.approx(0.3 / 0.004 - 30.0, rel=0.02)  # drift down


def _rows(actuator, flights, friction, sd, detected_from, flags=None):
    rows = []
    for n, k1 in zip(flights, friction, strict=True):
        row = {c: None for c in RESULT_COLUMNS}
        row.update(
            job_key=f"{actuator}-{n}", campaign="c", actuator=actuator, flight=int(n), seed=1, identify_seed=1,
            verdict="fits", k1=float(k1), std_k1=sd, k2=0.0, std_k2=0.01, k8=0.5, std_k8=0.01,
            **{f"k{i}": 0.0 for i in (3, 4, 5, 6, 7)}, **{f"std_k{i}": 0.01 for i in (3, 4, 5, 6, 7)},
            fault_verdicts=json.dumps({"friction": "present" if n >= detected_from else "absent", "backlash": "absent"}),
            uq_flags=json.dumps(flags(n) if flags else [[] for _ in range(8)]),
        )  # fmt: skip
        rows.append(row)
    return rows


def test_the_rul_of_a_stored_actuator(tmp_path):
    flights = np.arange(1, 21)
    friction = 0.05 + 0.01 * flights
    # flight 7 could not size friction: it must not enter the trend
    flags = lambda n: [["non_identifiable"] if (n == 7) else [], *([[]] * 7)]  # noqa: E731
    rows = _rows("A1", flights, friction, 0.005, detected_from=4, flags=flags)
    rows[6]["k1"] = 0.95  # what flight 7 would have said
    ResultStore(tmp_path).write("results", rows)
    report = rul_report(tmp_path, "A1", thresholds={"friction": 0.45})
    f = report["faults"]["friction"]
    assert f["status"] == "tracked" and f["tracked_from"] == 4 and f["measurements"] == 16
    assert f["placeholder"] is False and f["rul_median"] == pytest.approx(40 - 20, abs=1.0)
    assert report["faults"]["backlash"]["status"] == "not detected"
    assert report["faults"]["short_a"]["placeholder"] is True
    assert report["first_failure"]["most_likely_fault"] == "friction"
    at10 = rul_report(tmp_path, "A1", at_flight=10, thresholds={"friction": 0.45})
    assert at10["at_flight"] == 10 and at10["faults"]["friction"]["rul_median"] == pytest.approx(30, abs=3)


def test_cli_rul_json_plot_and_refusals(tmp_path, capsys):
    ResultStore(tmp_path / "s").write("results", _rows("A1", np.arange(1, 21), 0.05 + 0.01 * np.arange(1, 21),
                                                       0.005, detected_from=1))  # fmt: skip
    args = ["rul", str(tmp_path / "s"), "--actuator", "A1", "--threshold", "friction=0.45"]
    code, out, _ = run_cli([*args, "--json", "--plot", str(tmp_path / "rul.png")], capsys)
    data = json.loads(out)
    assert code == 0 and set(data) >= {"actuator", "at_flight", "faults", "first_failure"}
    assert set(data["faults"]["friction"]) >= {"rul_median", "rul_p05", "rul_p95", "threshold", "law"}
    assert (tmp_path / "rul.png").stat().st_size > 10_000
    code, out, _ = run_cli(args, capsys)
    assert code == 0 and "first failure" in out and "placeholder" in out
    for bad, match in ((["--threshold", "frict=0.4"], "unknown fault"), (["--threshold", "friction=2"], "(0, 1]"),
                       (["--actuator", "nobody"], "no results for actuator")):  # fmt: skip
        code, out, err = run_cli([*args[:4], *bad] if bad[0] == "--threshold" else ["rul", str(tmp_path / "s"), *bad],
                                 capsys)  # fmt: skip
        assert code == 2 and match in err and err.count("\n") == 1


def test_thresholds_from_the_actuator_file(tmp_path):
    from emaphm.actuator import load_params, load_thresholds

    (tmp_path / "a.toml").write_text("[motor]\nR_s = 0.6\n[thresholds]\nfriction = 0.45\nbacklash = 0.2\n")
    assert load_thresholds(tmp_path / "a.toml") == {"friction": 0.45, "backlash": 0.2}
    assert load_params(tmp_path / "a.toml").motor.R_s == 0.6
    (tmp_path / "b.toml").write_text("[thresholds]\nfricton = 0.45\n")
    with pytest.raises(InputError, match="unknown fault 'fricton'"):
        load_thresholds(tmp_path / "b.toml")
    assert parse_thresholds(["kp_drift=0.25"]) == {"kp_drift": 0.25}


def test_correlated_estimates_make_correlated_trends_for_the_first_failure(tmp_path):
    # friction and backlash measured alike (the same values and deviations), so that they cross
    # their equal thresholds together; their estimates come with a correlation in each
    # identification (the store's corr). Drawn independently, the earlier of two equal crossings
    # lies ~0.56 sd before either's median; correlated at 0.95, ~0.13 sd (E[min] of two normals)
    flights = np.arange(1, 21)
    k = 0.05 + 0.01 * flights

    def store(rho, folder):
        rows = _rows("A1", flights, k, 0.01, detected_from=1)
        for r, n in zip(rows, flights, strict=True):
            r.update(k2=0.05 + 0.01 * n, std_k2=0.01,
                     fault_verdicts=json.dumps({"friction": "present", "backlash": "present"}))  # fmt: skip
            corr = np.eye(8)
            corr[0, 1] = corr[1, 0] = 0.0 if rho is None else rho
            r["corr"] = json.dumps(corr.tolist()) if rho is not None else None
        ResultStore(tmp_path / folder).write("results", rows)
        return rul_report(tmp_path / folder, "A1", thresholds={"friction": 0.45, "backlash": 0.45})

    independent, correlated, unknown = store(0.0, "a"), store(0.95, "b"), store(None, "c")
    assert correlated["first_failure"]["correlations"] == {"friction/backlash": 0.95}
    assert unknown["first_failure"]["correlations"] == {"friction/backlash": 0.0}  # none recorded
    gaps = []
    for report in (independent, correlated):
        f = report["faults"]["friction"]
        assert f["rul_median"] == pytest.approx(report["faults"]["backlash"]["rul_median"], abs=0.05)
        sd = (f["rul_p95"] - f["rul_p05"]) / 3.29
        gaps.append((f["rul_median"] - report["first_failure"]["rul_median"]) / sd)
    assert 0.4 < gaps[0] < 0.75 and 0.0 <= gaps[1] < 0.2


def test_the_most_likely_fault_counts_only_the_draws_in_which_one_fails():
    # review M6: 25 % of draws never failing were counted as failures of the first fault listed
    from emaphm.prognostics.rul import most_likely_fault

    inf = np.inf
    friction = np.array([inf] * 25 + [10.0] * 32 + [50.0] * 43)
    backlash = np.array([inf] * 25 + [20.0] * 32 + [30.0] * 43)
    assert most_likely_fault(["friction", "backlash"], np.vstack([friction, backlash])) == "backlash"
    never = np.full((2, 100), inf)
    never[0, :10] = 5.0
    assert most_likely_fault(["friction", "backlash"], never) is None  # most draws never fail


def test_doubtful_diagnoses_are_left_out_of_the_trend_unless_asked_and_counted(tmp_path, capsys):
    # issue 34: a doubtful diagnosis (its fit poorer than the actuator's usual, a precondition not
    # met) must not move the RUL unless asked for; how many were left out is said
    flights = np.arange(1, 21)
    rows = _rows("A1", flights, 0.05 + 0.01 * flights, 0.005, detected_from=1)
    for n in (15, 16, 17):  # three doubtful diagnoses that say the friction jumped
        rows[n - 1].update(verdict="doubtful", k1=0.9)
    ResultStore(tmp_path).write("results", rows)
    sure = rul_report(tmp_path, "A1", thresholds={"friction": 0.45})
    f = sure["faults"]["friction"]
    assert sure["doubtful_left_out"] == 3 and sure["include_doubtful"] is False and f["measurements"] == 17
    assert f["rul_median"] == pytest.approx(20, abs=1.0) and sure["at_flight"] == 20
    every = rul_report(tmp_path, "A1", thresholds={"friction": 0.45}, include_doubtful=True)
    assert every["doubtful_left_out"] == 0 and every["faults"]["friction"]["measurements"] == 20
    assert every["faults"]["friction"]["rul_median"] < f["rul_median"] - 3  # the jump pulls the crossing in
    args = ["rul", str(tmp_path), "--actuator", "A1", "--threshold", "friction=0.45"]
    code, out, _ = run_cli(args, capsys)
    assert code == 0 and "3 doubtful diagnoses left out" in out and "--include-doubtful" in out
    code, out, _ = run_cli([*args, "--include-doubtful", "--json"], capsys)
    assert code == 0 and json.loads(out)["doubtful_left_out"] == 0
    # nothing sure left: refused in one line, naming the way out
    ResultStore(tmp_path / "d").write("results", [{**r, "verdict": "doubtful"} for r in _rows("B", flights[:3], [0.1] * 3, 0.005, 1)])
    code, _, err = run_cli(["rul", str(tmp_path / "d"), "--actuator", "B"], capsys)
    assert code == 2 and "all 3 diagnoses" in err and "--include-doubtful" in err and err.count("\n") == 1
