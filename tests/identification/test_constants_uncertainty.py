"""The actuator's constants widen the fault intervals for what they can move (issue 33, item 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import emaphm
from emaphm.actuator import load_params
from emaphm.calibration import default_calibration
from emaphm.constants import CONSTANTS, TOLERANCES, apply, load_tolerances, tolerance_covariance
from emaphm.errors import InputError
from emaphm.faults import FAULT_NAMES


def test_tolerances_default_to_two_percent_and_read_from_the_actuator_file(tmp_path):
    assert load_tolerances(None) == TOLERANCES and TOLERANCES["psi_m"] == TOLERANCES["J"] == 0.02
    path = tmp_path / "a.toml"
    path.write_text('[motor]\nR_s = 0.5\n\n[tolerances]\npsi_m = 0.05\ncurrent_gain = 0.1\n')
    assert load_params(path).motor.R_s == 0.5  # the table is not a parameter block
    got = load_tolerances(path)
    assert (got["psi_m"], got["current_gain"], got["J"]) == (0.05, 0.1, 0.02)
    for text, match in (("[tolerances]\nflux = 0.1\n", "not one of"), ("[tolerances]\nJ = 0.7\n", r"\[0, 0.5\)")):
        path.write_text(text)
        with pytest.raises(InputError, match=match):
            load_tolerances(path)


def test_a_tolerance_moves_what_its_quantity_scales_together():
    cov = tolerance_covariance({"psi_m": 0.02, "J": 0.0, "friction": 0.04, "current_gain": 0.0, "K_P": 0.0})
    i = {c: CONSTANTS.index(c) for c in CONSTANTS}
    sigma = math.log1p(0.02) / math.sqrt(3)  # a uniform band ±2 %
    assert cov[i["k_t_eq"], i["k_t_eq"]] == pytest.approx(sigma**2) == cov[i["k_t_eq"], i["k_e_eq"]]  # one ψ_m
    assert cov[i["F_S0"], i["F_D0"]] == pytest.approx((math.log1p(0.04) / math.sqrt(3)) ** 2)
    assert cov[i["J_eq"], i["J_eq"]] == 0.0 and cov[i["i_gain"], i["i_gain"]] == 0.0


def test_apply_scales_the_nameplate_and_the_calibration_but_not_the_sensor():
    params, cal = emaphm.EmaParams(), default_calibration()
    p, c = apply(params, cal, {"k_t_eq": 1.1, "J_eq": 0.9, "F_D0": 1.2, "K_P0": 1.05, "i_gain": 2.0})
    assert c.coefficients.k_t_eq == pytest.approx(1.1 * cal.coefficients.k_t_eq)
    assert c.coefficients.J_eq == pytest.approx(0.9 * cal.coefficients.J_eq)
    assert p.transmission.J_m == pytest.approx(0.9 * params.transmission.J_m)
    assert p.transmission.F_D0 == pytest.approx(1.2 * params.transmission.F_D0)
    assert p.controller.K_P0 == pytest.approx(1.05 * params.controller.K_P0)
    assert p.motor == params.motor and c.coefficients.k_e_eq == cal.coefficients.k_e_eq


@pytest.fixture(scope="module")
def twin():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=3)


def _added(twin, tmp_path, table):
    path = tmp_path / "act.toml"
    path.write_text(table)
    # a uniform start: the estimate these intervals are taken at is the tiny search's, not the table's
    r = emaphm.identify(reference=twin, seed=1, params=path, pop_size=16, generations=3, polish=False,
                        last_stage="none", start="random")  # fmt: skip
    return np.array(r.uncertainty.details["constants_std"]), r


def test_a_flux_tolerance_widens_the_shorts_and_twice_the_tolerance_twice_as_much(twin, tmp_path):
    # a uniform change of the magnet flux looks like equal shorts in all three phases (off-twin.md)
    none, r0 = _added(twin, tmp_path, "[tolerances]\npsi_m = 0\nJ = 0\nfriction = 0\n")
    assert np.all(none == 0.0)
    flux, r1 = _added(twin, tmp_path, "[tolerances]\npsi_m = 0.02\nJ = 0\nfriction = 0\n")
    double, _ = _added(twin, tmp_path, "[tolerances]\npsi_m = 0.04\nJ = 0\nfriction = 0\n")
    shorts = [FAULT_NAMES.index(n) for n in ("short_a", "short_b", "short_c")]
    backlash = FAULT_NAMES.index("backlash")
    assert min(flux[shorts]) > 2 * flux[backlash] and min(flux[shorts]) > 0.005
    # linear in the tolerance (the covariance is σ²·S·Sᵀ), within the log's curvature
    assert double[shorts] == pytest.approx(2 * flux[shorts] * math.log1p(0.04) / (2 * math.log1p(0.02)), rel=1e-4)  # (rounded to 1e-6)
    # and the intervals grow by it in quadrature, the estimate untouched
    assert np.array_equal(r0.estimate, r1.estimate)
    assert np.all(np.array(r1.uncertainty.ci90_high) >= np.array(r0.uncertainty.ci90_high) - 1e-12)
    assert "tolerances of" in r1.uncertainty.details["constants_from"]


def test_the_template_shows_the_tolerances_table_at_its_defaults(tmp_path):
    from emaphm.actuator import params_template

    lines = [line[2:] if line.startswith("# ") and ("=" in line or "[tolerances]" in line) else line
             for line in params_template().splitlines()]  # fmt: skip
    start = lines.index("[tolerances]")
    path = tmp_path / "a.toml"
    path.write_text("\n".join(lines[start:]) + "\n")
    assert load_tolerances(path) == TOLERANCES and "[tolerances]" not in params_template().replace("# [tolerances]", "")
