"""A recording the monitor cannot explain gets the verdict "does not fit" and no faults."""

from __future__ import annotations

import json

import numpy as np
import pytest

import emaphm
from emaphm.identification.limits import FIT_NRMSE_LIMIT, FIT_NRMSE_WARN
from emaphm.results import SimResult
from tests.helpers import run_cli

BUDGET = {"pop_size": 16, "generations": 3, "polish": False}


@pytest.fixture(scope="module")
def measured():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=3)


def test_a_real_measurement_is_explained(measured):
    # a 16 x 3 search without polish explains it, poorly: its faults are reported, as doubtful
    r = emaphm.identify(reference=measured, seed=1, **BUDGET)
    assert r.fits and r.fit_nrmse < FIT_NRMSE_LIMIT and r.verdict == "doubtful"
    assert r.to_json()["fit_nrmse"] == pytest.approx(r.fit_nrmse)


@pytest.mark.parametrize(
    ("mistake", "change", "match"),
    [
        ("current in mA", lambda s: {"i_q": 1000.0 * s["i_q"]}, "is the current in mA"),
        ("command in degrees", lambda s: {"theta_cmd": np.degrees(s["theta_cmd"])}, "is it in degrees"),
        ("position in degrees", lambda s: {"theta_u": np.degrees(s["theta_u"])}, "is it in degrees"),
        ("one corrupt sample", lambda s: {"i_q": np.where(np.arange(len(s["i_q"])) == 500, 1e30, s["i_q"])},
         "a corrupt sample"),
        ("an all-zero current", lambda s: {"i_q": np.zeros_like(s["i_q"])}, "is constant"),
    ],
)  # fmt: skip
def test_a_unit_mistake_is_refused_before_the_search(measured, mistake, change, match):
    # newcomer.md §3-4: each of these gave a confident list of faults at exit 0 before issue 10
    signals = dict(measured.signals)
    wrong = SimResult(t=measured.t, signals={**signals, **change(signals)})
    with pytest.raises(emaphm.InputError, match=match):
        emaphm.identify(reference=wrong, seed=1, **BUDGET)


def test_a_sign_mistake_does_not_fit_and_reports_no_fault(measured):
    signals = dict(measured.signals)
    wrong = SimResult(t=measured.t, signals={**signals, "i_q": -signals["i_q"]})
    r = emaphm.identify(reference=wrong, seed=1, **BUDGET)
    assert r.verdict == "does not fit"
    assert r.detected == [] and any("cannot explain" in w for w in r.warnings)


def test_the_command_line_exits_3_on_does_not_fit_and_2_on_a_unit_mistake(measured, tmp_path, capsys):
    signals = dict(measured.signals)
    emaphm.write_trace(
        SimResult(t=measured.t, signals={**signals, "i_q": 1000.0 * signals["i_q"]}), tmp_path / "mA.h5"
    )
    code, out, err = run_cli(["identify", "--reference", str(tmp_path / "mA.h5")], capsys)
    assert code == 2 and out == "" and "is the current in mA" in err and err.count("\n") == 1
    path = tmp_path / "flipped.h5"
    emaphm.write_trace(SimResult(t=measured.t, signals={**signals, "i_q": -signals["i_q"]}), path)
    args = ["identify", "--reference", str(path), "--pop-size", "16", "--generations", "3", "--no-polish"]
    code, out, err = run_cli([*args, "--json"], capsys)
    assert code == 3 and json.loads(out)["verdict"] == "does not fit" and json.loads(out)["detected"] == []
    assert "cannot explain" in err
    code, out, _ = run_cli(args, capsys)
    assert code == 3 and "verdict: does not fit" in out and "detected:" not in out


def test_a_recording_too_short_for_a_diagnosis_is_refused(measured):
    # 300 samples (30 ms) fit the monitor to a few % NRMSE and "detected" every fault
    n = 300
    short = SimResult(t=measured.t[:n], signals={k: v[:n] for k, v in measured.signals.items()})
    with pytest.raises(emaphm.InputError, match=r"at least 0\.2 s"):
        emaphm.identify(reference=short, seed=1)


def test_a_current_gain_error_fits_poorly_and_is_warned_about(measured, monkeypatch):
    from emaphm.identification import limits

    # a small search with a short polish fits the true recording to about 2 % and the one with a
    # 1.2x current sensor gain to about 10 %: only the second is doubtful, and says why
    monkeypatch.setattr(limits, "POLISH_BUDGET", (16, 10))
    budget = {"pop_size": 16, "generations": 3, "second_search": False, "uncertainty": "none"}
    signals = dict(measured.signals)
    found = {}
    for gain in (1.0, 1.2):
        recording = SimResult(t=measured.t, signals={**signals, "i_q": gain * signals["i_q"]})
        r = emaphm.identify(reference=recording, seed=1, **budget)
        found[gain] = (r.verdict, r.fit_nrmse, [d for d in r.doubts if "explained less well" in d and d in r.warnings])
    assert (found[1.0][0], found[1.2][0]) == ("fits", "doubtful")
    assert found[1.0][1] < FIT_NRMSE_WARN < found[1.2][1]
    assert found[1.0][2] == [] and len(found[1.2][2]) == 1
