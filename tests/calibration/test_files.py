"""The packaged calibration loader hands out no shared mutable state (review L8)."""

import copy
import dataclasses

import pytest

from emaphm import EmaParams, MonitorEma
from emaphm.calibration import default_calibration


@pytest.mark.parametrize("monitor", ["default", "paper"])
def test_changing_a_loaded_calibration_does_not_change_the_next_load(monitor):
    first = default_calibration(monitor)
    pristine = copy.deepcopy(first.to_json())
    first.record["settings"]["params"]["motor"]["R_s"] = 99.0
    first.record["fit_scenarios"].clear()
    first.record["created"] = "never"
    with pytest.raises(dataclasses.FrozenInstanceError):
        first.coefficients.k_FS = 0.0  # type: ignore[misc]
    again = default_calibration(monitor)
    assert again.to_json() == pristine
    again.check_params(EmaParams())  # still made for the nominal actuator


def test_a_simulation_record_is_not_a_window_into_the_packaged_calibration():
    # a SimResult's metadata holds the calibration's record: changing it leaves the package's alone
    result = MonitorEma().simulate(duration=0.01)
    result.metadata["calibration"]["settings"]["params"]["motor"]["R_s"] = 99.0
    assert default_calibration().params["motor"]["R_s"] == EmaParams().motor.R_s


def test_the_interval_calibration_handed_out_is_a_copy_too():
    from emaphm.identification.uncertainty import load_factors

    first = load_factors()
    pristine = copy.deepcopy(first.record)
    nested = next(v for v in first.record.values() if isinstance(v, dict) and v)
    nested.clear()
    first.record["created"] = "never"
    assert load_factors().record == pristine and pristine["created"] != "never"
