"""The interval calibration's entry point (`calibrate_uq`): its refusals, before any identification."""

import json

import pytest

from emaphm import InputError
from emaphm.calibration import UQ_CASE_SEED, calibrate_uq
from emaphm.identification.uncertainty import load_factors
from tests.helpers import run_cli


@pytest.mark.parametrize("cases", [5, 19, 20.0, "160"])
def test_calibrate_uq_refuses_too_few_cases_before_the_work(cases):
    with pytest.raises(InputError, match="cases must be a whole number >= 20"):
        calibrate_uq(cases=cases, seed=UQ_CASE_SEED)


class _Result:
    def __init__(self, k, fits):
        import numpy as np

        self.estimate = np.asarray(k, dtype=float)
        self.fit_nrmse = 0.01 if fits else 0.4
        self.wall_time_s = 0.0
        self.uncertainty = type("U", (), {"raw_std": np.full(8, 0.01)})() if fits else None


@pytest.fixture
def fake_identify(monkeypatch):
    """identify() replaced by a recorder: which source each case got; case 2 does not fit."""
    from emaphm.identification import api

    calls = []

    def identify(true_faults=None, reference=None, **options):
        calls.append({"true_faults": true_faults, "reference": reference, **options})
        k = true_faults if true_faults is not None else [0.0] * 8
        return _Result(k, fits=len(calls) != 3)

    monkeypatch.setattr(api, "identify", identify)
    return calls


def test_an_foc_drive_is_calibrated_on_drawn_drives_and_a_case_that_does_not_fit_is_left_out(fake_identify):
    from emaphm.calibration.fit_intervals import collect_cases
    from emaphm.params import EmaParams, InverterParams

    foc = EmaParams(inverter=InverterParams(control="foc"))
    data = collect_cases(12, 11, params=foc, drive_tolerance=0.1)
    # each case measured on its own drawn drive's twin, passed as a recording
    assert all(c["true_faults"] is None and c["reference"] is not None for c in fake_identify)
    currents = [c["reference"].i_q for c in fake_identify]
    assert not any((currents[0] == c).all() for c in currents[1:])
    assert [s["case"] for s in data["skipped"]] == [2] and data["truths"].shape == (11, 8)


def test_a_hysteresis_drive_is_calibrated_on_its_own_twin_and_too_many_misfits_refuse(fake_identify):
    from emaphm.calibration.fit_intervals import collect_cases

    data = collect_cases(12, 11, drive_tolerance=0.1)  # no PI to draw: the twin itself
    assert all(c["reference"] is None for c in fake_identify) and len(data["skipped"]) == 1
    fake_identify.clear()
    with pytest.raises(InputError, match="1 of 4 cases did not fit"):
        collect_cases(4, 11)  # 1 of 4 is more than the 10 % allowed


def test_the_last_stage_reaches_every_identification_and_the_record(fake_identify, tmp_path, capsys):
    # the packaged uq_calibration_no_last_stage.json can be remade: calibrate-uq --last-stage none
    factors = calibrate_uq(cases=20, seed=11, last_stage="none")
    assert {c["last_stage"] for c in fake_identify} == {"none"} and factors.record["last_stage"] == "none"
    fake_identify.clear()
    assert calibrate_uq(cases=20, seed=11).record["last_stage"] == "switching"  # "auto", default monitor
    with pytest.raises(InputError, match="unknown last stage"):
        calibrate_uq(cases=20, seed=11, last_stage="bogus")
    out = tmp_path / "uq.json"
    fake_identify.clear()
    code, _, _ = run_cli(["calibrate-uq", "--cases", "20", "--last-stage", "none", "--output", str(out)], capsys)
    assert code == 0 and {c["last_stage"] for c in fake_identify} == {"none"}
    assert json.loads(out.read_text())["last_stage"] == "none"  # as the packaged file has it
    assert load_factors(out, last_stage="none").record["last_stage"] == "none"


def test_the_start_reaches_every_identification_and_the_record(fake_identify, tmp_path, capsys):
    # the table's end points need factors of their own (issue 36): calibrate-uq --start table
    factors = calibrate_uq(cases=20, seed=11, start="table")
    assert {c["start"] for c in fake_identify} == {"table"} and factors.record["start"] == "table"
    fake_identify.clear()
    assert calibrate_uq(cases=20, seed=11).record["start"] == "auto"  # as identify's default
    with pytest.raises(InputError, match="unknown start"):
        calibrate_uq(cases=20, seed=11, start="sideways")
    out = tmp_path / "uq.json"
    fake_identify.clear()
    code, _, _ = run_cli(["calibrate-uq", "--cases", "20", "--start", "auto", "--output", str(out)], capsys)
    assert code == 0 and {c["start"] for c in fake_identify} == {"auto"}
    assert json.loads(out.read_text())["start"] == "auto"
    code, _, err = run_cli(["calibrate-uq", "--cases", "20", "--start", "sideways", "--output", str(tmp_path / "x.json")], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "sideways" in err
    assert not (tmp_path / "x.json").exists()
