"""A recording the monitor cannot explain gets the verdict "does not fit" and no faults."""

from __future__ import annotations

import json

import numpy as np
import pytest

import emaphm
from emaphm.identification.identify import FIT_NRMSE_LIMIT
from emaphm.results import SimResult
from tests.helpers import run_cli

BUDGET = {"pop_size": 16, "generations": 3, "local_polish": False}


@pytest.fixture(scope="module")
def measured():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=3)


def test_a_real_measurement_fits(measured):
    r = emaphm.identify(reference=measured, seed=1, **BUDGET)
    assert r.verdict == "fits" and r.fit_nrmse < FIT_NRMSE_LIMIT
    assert r.to_json()["fit_nrmse"] == pytest.approx(r.fit_nrmse)


@pytest.mark.parametrize(
    ("mistake", "change"),
    [
        ("current in mA", lambda s: {"i_q": 1000.0 * s["i_q"]}),
        ("current sign flipped", lambda s: {"i_q": -s["i_q"]}),
        ("command in degrees", lambda s: {"theta_cmd": np.degrees(s["theta_cmd"])}),
    ],
)
def test_a_unit_or_sign_mistake_does_not_fit_and_reports_no_fault(measured, mistake, change):
    signals = dict(measured.signals)
    wrong = SimResult(t=measured.t, signals={**signals, **change(signals)})
    r = emaphm.identify(reference=wrong, seed=1, **BUDGET)
    assert r.verdict == "does not fit", mistake
    assert r.detected == [] and any("cannot explain" in w for w in r.warnings)


def test_the_command_line_exits_3_on_does_not_fit(measured, tmp_path, capsys):
    signals = dict(measured.signals)
    path = tmp_path / "mA.h5"
    emaphm.write_trace(SimResult(t=measured.t, signals={**signals, "i_q": 1000.0 * signals["i_q"]}), path)
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
