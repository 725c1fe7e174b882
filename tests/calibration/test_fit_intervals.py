"""The interval calibration's entry point (`calibrate_uq`): its refusals, before any identification."""

import pytest

from emaphm import InputError
from emaphm.calibration import UQ_CASE_SEED, calibrate_uq


@pytest.mark.parametrize("cases", [5, 19, 20.0, "160"])
def test_calibrate_uq_refuses_too_few_cases_before_the_work(cases):
    with pytest.raises(InputError, match="cases must be a whole number >= 20"):
        calibrate_uq(cases=cases, seed=UQ_CASE_SEED)
