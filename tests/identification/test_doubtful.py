"""The third verdict, "doubtful" (issue 34): faults reported, the reasons warned of, exit 4.

A result is doubtful when its fit is poorer than this actuator's monitor explains its own twin
(the limit measured by the interval calibration), when the search needed its second start, or
when a precondition of the diagnosis does not hold.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import emaphm
from emaphm.errors import Doubt
from emaphm.identification import limits
from emaphm.identification.uncertainty import load_factors
from emaphm.identification.verdict import fit_distribution, fit_doubts, fit_limit, verdict_of
from emaphm.results import SimResult
from tests.helpers import run_cli


def test_the_limit_is_a_quantile_of_the_measured_fits_with_a_margin():
    fits = np.linspace(0.01, 0.03, 201)  # p90 = 0.028, p99 = 0.0298
    d = fit_distribution(fits)
    assert d["cases"] == 201 and d["median"] == pytest.approx(0.02) and d["max"] == pytest.approx(0.03)
    assert (d["p90"], d["p99"]) == (pytest.approx(0.028), pytest.approx(0.0298))
    at = {0.9: 0.028, 0.99: 0.0298}[limits.DOUBTFUL_QUANTILE]
    assert d["doubtful_above"] == pytest.approx(limits.DOUBTFUL_MARGIN * at, rel=1e-4)
    # a few cases beyond the monitor (an FOC drive's unstable loops, fits of 40 %) barely move it
    polluted = fit_distribution(np.concatenate([fits, np.full(6, 0.4)]))
    assert polluted["p99"] > 0.3 and polluted["doubtful_above"] < 1.1 * d["doubtful_above"]
    # the limit follows the fits, not a constant: twice as poor a monitor, twice the limit
    assert fit_distribution(2 * fits)["doubtful_above"] == pytest.approx(2 * d["doubtful_above"], rel=1e-4)
    # non-finite fits are not fits; too few measured ones fall back to the monitor's trigger, and say so
    assert fit_distribution([np.nan, 0.02])["cases"] == 1
    limit, source = fit_limit({"data": {"fit_nrmse": list(fits)}}, "default")
    assert limit == d["doubtful_above"] and "201 twin cases" in source
    for record in (None, {}, {"data": {"fit_nrmse": [0.02] * 19}}):
        limit, source = fit_limit(record, "paper")
        assert limit == limits.SECOND_SEARCH_NRMSE["paper"] and "no twin fits measured" in source


def test_three_verdicts_and_their_reasons():
    assert verdict_of(0.02, []) == "fits"
    assert verdict_of(0.02, ["a reason"]) == "doubtful"
    assert verdict_of(0.8, ["a reason"]) == verdict_of(0.8, []) == "does not fit"
    assert verdict_of(None, []) == "fits"  # not measured
    # above the limit: one reason; at or below it none; a fit that does not explain has its own warning
    assert fit_doubts(0.019, 0.02, "s", None) == []
    (above,) = fit_doubts(0.021, 0.02, "its source", None)
    assert isinstance(above, Doubt) and "2.10 %" in above and "2.00 %" in above and "its source" in above
    assert fit_doubts(0.9, 0.02, "s", None) == []
    # a measured limit above FIT_NRMSE_WARN is capped by it
    assert fit_doubts(0.07, 0.2, "s", None) and fit_doubts(0.05, 0.2, "s", None) == []
    second = {"ran": True, "first_fit_nrmse": 0.041, "trigger": 0.03}
    (needed,) = fit_doubts(0.01, 0.02, "s", second)
    assert "second start" in needed and "4.10 %" in needed
    assert fit_doubts(0.01, 0.02, "s", {"ran": False}) == []


@pytest.fixture(scope="module")
def measured():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=3)


def _factors_with_fits(fits):
    """The packaged interval calibration with its measured fits replaced."""
    packaged = load_factors()
    record = {**packaged.record, "data": {**packaged.record.get("data", {}), "fit_nrmse": list(fits)}}
    return dataclasses.replace(packaged, record=record)


def test_a_strict_limit_starts_the_second_search_and_makes_the_result_doubtful(measured, monkeypatch):
    # an interval calibration whose twin fitted to 0.1 %: a real fit (a few %) is poorer than
    # that, so the second search runs from the actuator's limit (below the monitor's 3 %) and the
    # result is doubtful for both reasons; with a lenient one the monitor's own trigger stands
    monkeypatch.setattr(limits, "POLISH_BUDGET", (8, 3))
    budget = {"pop_size": 16, "generations": 2, "uncertainty": "none", "last_stage": "none"}
    strict = emaphm.identify(reference=measured, seed=1, uq_calibration=_factors_with_fits([0.001] * 40), **budget)
    assert strict.settings["doubtful_above"]["nrmse"] == pytest.approx(limits.DOUBTFUL_MARGIN * 0.001)
    second = strict.stage("second_search")
    assert second["ran"] and second["trigger"] == pytest.approx(limits.DOUBTFUL_MARGIN * 0.001)
    assert strict.verdict == "doubtful" and len(strict.doubts) == 2
    assert all(d in strict.warnings for d in strict.doubts)
    assert strict.to_json()["doubts"] == strict.doubts and strict.detected == strict.to_json()["detected"]
    lenient = emaphm.identify(reference=measured, seed=1, uq_calibration=_factors_with_fits([0.5] * 40), **budget)
    # the limit is capped at FIT_NRMSE_WARN and the second search keeps the monitor's trigger
    assert lenient.settings["doubtful_above"]["nrmse"] == pytest.approx(limits.DOUBTFUL_MARGIN * 0.5)
    assert lenient.stage("second_search")["ran"] == (lenient.stage("fit")["fit_nrmse"] > 0.03)


def test_the_command_line_says_doubtful_and_exits_4(measured, tmp_path, capsys):
    # a current sensor reading 1.2 x: a fit far poorer than the twin's, faults still reported
    signals = dict(measured.signals)
    path = tmp_path / "gain.h5"
    emaphm.write_trace(SimResult(t=measured.t, signals={**signals, "i_q": 1.2 * signals["i_q"]}), path)
    args = ["identify", "--reference", str(path), "--pop-size", "16", "--generations", "3", "--no-polish",
            "--uncertainty", "none"]  # fmt: skip
    code, out, err = run_cli([*args, "--json"], capsys)
    data = json.loads(out)
    assert code == 4 and data["verdict"] == "doubtful" and data["doubts"]
    assert all(f"emaphm: warning: {d}" in err.replace("\n", " ") or d[:60] in err for d in data["doubts"])
    code, out, _ = run_cli(args, capsys)
    assert code == 4 and "verdict: doubtful" in out and "detected:" in out and "doubtful above" in out
