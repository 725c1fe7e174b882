import math

import numpy as np
import pytest

from emaphm import EmaParams, InputError, apply_faults, as_fault_vector
from emaphm.faults import FAULT_NAMES, HEALTHY, N_MIN, TABLE1_REFERENCE, parse_faults


def test_names_and_reference_vectors():
    assert len(FAULT_NAMES) == 8 and len(set(FAULT_NAMES)) == 8
    assert as_fault_vector(TABLE1_REFERENCE)[1] == 0.5003
    assert not HEALTHY.flags.writeable


def test_healthy_maps_to_nominal():
    p = EmaParams()
    fp = apply_faults(HEALTHY, p)
    assert fp.F_S == p.transmission.F_S0 and fp.F_D == p.transmission.F_D0
    assert fp.B == p.transmission.B0 and fp.N == (1.0, 1.0, 1.0)
    assert fp.zeta == 0.0 and fp.K_P == p.controller.K_P0


def test_full_faults_map_to_design_extremes():
    p = EmaParams()
    fp = apply_faults(np.ones(8), p)
    assert fp.F_S == pytest.approx(3 * p.transmission.F_S0)  # k1 = 1: 3× nominal
    assert fp.B == pytest.approx(100 * p.transmission.B0)  # k2 = 1: 100× nominal
    assert fp.N == (N_MIN, N_MIN, N_MIN)  # turns clamped
    assert fp.phi_e == pytest.approx(2 * math.pi)
    assert fp.K_P == pytest.approx(1.5 * p.controller.K_P0)
    assert apply_faults(np.zeros(8), p).K_P == pytest.approx(0.5 * p.controller.K_P0)


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ([0.1] * 7, "8 values"),
        ([0.1] * 9, "8 values"),
        ([0, 0, float("nan"), 0, 0, 0, 0, 0.5], r"k3 \(short_a\) is nan"),
        ([0, 0, 0, 0, 0, 0, float("inf"), 0.5], "k7"),
        ([0, -0.01, 0, 0, 0, 0, 0, 0.5], r"k2 \(backlash\) = -0.01 is outside"),
        ([0, 0, 0, 0, 0, 0, 0, 1.01], "k8"),
        ("abc", "8 numbers|8 values"),
        ([[0.1] * 8], "8 values"),
    ],
)
def test_bad_vectors_are_rejected_with_a_reason(value, match):
    with pytest.raises(InputError, match=match):
        as_fault_vector(value)


def test_parse_cli_form():
    np.testing.assert_array_equal(parse_faults("0, 0.5,0,0,0,0,0,1"), [0, 0.5, 0, 0, 0, 0, 0, 1])
    with pytest.raises(InputError, match="value 2"):
        parse_faults("0,x,0,0,0,0,0,0")


def test_random_cases_follow_the_design_ranges_and_the_seed():
    from emaphm.faults import RANDOM_CASE_RANGES, random_faults

    K = random_faults(500, seed=3)
    low, high = np.array(RANDOM_CASE_RANGES).T
    assert np.all(K >= low) and np.all(K <= high)
    assert np.all(K.max(axis=0) > high - 0.05 * (high - low))  # the ranges are used, not a corner
    np.testing.assert_array_equal(K, random_faults(500, seed=3))
    assert not np.array_equal(K, random_faults(500, seed=4))
