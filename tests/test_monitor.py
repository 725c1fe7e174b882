"""The calibrated LF monitor model against the HF twin, and its calibration file."""

import json

import numpy as np
import pytest

import emaphm
from emaphm import InputError, MonitorEma
from emaphm.calibration import Calibration, Coefficients, default_calibration, load_calibration
from emaphm.identification import Comparison
from emaphm.identification.calibrate import CHECK_SCENARIOS, FIT_SCENARIOS, calibrate
from tests.helpers import faults

# DESIGN §4 target for the calibrated LF model against the HF twin (filtered i_q, noise off), on
# scenarios the calibration never saw. Measured live: 1.31-2.97 % (Table 1 vector the highest;
# docs/theory/monitor-model.md §4)
NRMSE_TARGET = 0.05


def test_held_out_scenarios_are_not_fitted():
    fitted = {s.faults for s in FIT_SCENARIOS}
    assert len(CHECK_SCENARIOS) >= 8 and not any(s.faults in fitted for s in CHECK_SCENARIOS)


@pytest.mark.parametrize("scenario", CHECK_SCENARIOS, ids=lambda s: s.name)
def test_calibrated_lf_matches_hf_on_held_out_scenarios(scenario):
    hf = emaphm.simulate(scenario.faults, noise=False)
    lf = emaphm.simulate(scenario.faults, model="lf", noise=False)
    np.testing.assert_array_equal(lf.t, hf.t)
    ref = Comparison.from_signal(hf.t, hf.i_q, 1e4)
    assert ref.nrmse(lf.i_q) < NRMSE_TARGET


def test_uncalibrated_lf_is_worse_on_shorts():
    # the calibration is what makes the short-circuit shape function fit (k_FS: 1 -> ~80);
    # measured NRMSE 2.5 % calibrated against 4.7 % with the first-guess coefficients
    k = faults(k3=0.3)
    hf = emaphm.simulate(k, noise=False)
    ref = Comparison.from_signal(hf.t, hf.i_q, 1e4)
    calibrated = ref.nrmse(MonitorEma().simulate(k).i_q)
    first_guess = ref.nrmse(MonitorEma(calibration=Calibration(Coefficients())).simulate(k).i_q)
    assert calibrated < 0.85 * first_guess


def test_lf_result_has_the_hf_signal_names():
    r = emaphm.simulate(faults(k1=0.2), model="lf", noise=False, duration=0.1)
    for name in ("t", "theta_cmd", "theta_u", "i_q"):
        assert r[name].shape == r.t.shape
    assert r.metadata["model"] == "lf"
    assert r.metadata["calibration"]["coefficients"]["k_FS"] == default_calibration().coefficients.k_FS
    assert np.max(np.abs(r.i_q)) > 0.05


def test_lf_noise_is_seeded():
    a = emaphm.simulate(emaphm.HEALTHY, model="lf", noise=True, seed=1, duration=0.1)
    b = emaphm.simulate(emaphm.HEALTHY, model="lf", noise=True, seed=1, duration=0.1)
    c = emaphm.simulate(emaphm.HEALTHY, model="lf", noise=True, seed=2, duration=0.1)
    np.testing.assert_array_equal(a.i_q, b.i_q)
    assert not np.array_equal(a.i_q, c.i_q)


def test_fault_matrix_validation():
    with pytest.raises(InputError, match="row 1"):
        MonitorEma().simulate_many([[0.0] * 8, [0.0] * 7 + [2.0]])
    with pytest.raises(InputError, match="shape"):
        MonitorEma().simulate_many(np.zeros((3, 7)))


# ---- the calibration file ---------------------------------------------------------------------


def test_packaged_calibration_is_complete():
    # schema only: the LF-vs-HF figures are checked live above, not read from this file
    cal = default_calibration()
    for key in ("seed", "package_version", "fit_scenarios", "check_scenarios", "settings"):
        assert key in cal.record
    assert [s["name"] for s in cal.record["fit_scenarios"]] == [s.name for s in FIT_SCENARIOS]
    assert [s["name"] for s in cal.record["check_scenarios"]] == [s.name for s in CHECK_SCENARIOS]
    assert all(isinstance(s["nrmse"], float) for s in cal.record["check_scenarios"])


def test_calibration_round_trip(tmp_path):
    cal = Calibration(Coefficients(k_FS=12.5, tau_i=5e-5), 2, {"seed": 3, "note": "x"})
    back = load_calibration(cal.save(tmp_path / "c.json"))
    assert back == cal


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ("{not json", "corrupt"),
        ('{"format": "other"}', "not an emaphm"),
        ('{"format": "emaphm-lf-calibration", "format_version": 99}', "format version"),
    ],
)
def test_bad_calibration_files(tmp_path, content, match):
    (tmp_path / "c.json").write_text(content)
    with pytest.raises(InputError, match=match):
        load_calibration(tmp_path / "c.json")


def test_calibration_with_bad_coefficients(tmp_path):
    data = Calibration().to_json()
    data["coefficients"]["k_t_eq"] = 5.0
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="k_t_eq"):
        load_calibration(tmp_path / "c.json")
    del data["coefficients"]["k_E"]
    (tmp_path / "c.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="coefficients must be"):
        load_calibration(tmp_path / "c.json")


def test_missing_calibration_file(tmp_path):
    with pytest.raises(InputError, match="no such calibration file"):
        load_calibration(tmp_path / "none.json")


def test_small_calibration_is_seeded_and_recorded():
    a = calibrate(seed=4, pop_size=6, generations=2, fit=FIT_SCENARIOS[:2], check=CHECK_SCENARIOS[:1])
    b = calibrate(seed=4, pop_size=6, generations=2, fit=FIT_SCENARIOS[:2], check=CHECK_SCENARIOS[:1])
    assert a.coefficients == b.coefficients
    assert a.record["seed"] == 4 and a.record["settings"]["evaluations"] == 12
    assert [s["name"] for s in a.record["check_scenarios"]] == [CHECK_SCENARIOS[0].name]
    assert a.record["ga_history"][-1] <= a.record["ga_history"][0]
