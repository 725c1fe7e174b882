"""Calibration of the LF monitor model against the HF twin: coefficients, files and the fits.

Calibrating is not identifying: these fits run once per actuator (or monitor change) and write
the files that identification reads.

- `coefficients`: `Coefficients`, the monitor's calibrated constants, and their search box;
- `files`: `Calibration`, the versioned calibration file, its loaders and `params_hash`;
- `scenarios`: the commands and the fitting and check scenarios (`CALIBRATION_COMMANDS`,
  `FIT_SCENARIOS`, `CHECK_SCENARIOS`, ...), the HF references and the LF NRMSE of each;
- `fit_monitor`: `calibrate`, the GA fit of the coefficients (``emaphm calibrate``);
- `fit_intervals`: `calibrate_uq`, the 90 % intervals' scale and floor (``emaphm calibrate-uq``);
- `fit_detection`: `calibrate_detection`, the detection thresholds (``data/detection.json``).

The fits load on first use (PEP 562): reading a calibration file needs neither pymoo nor the
twin, and the monitor model (`emaphm.models`) imports this package.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names
from .coefficients import (
    ACTUATOR_SCALED,
    BAND_SCALED,
    COEFFICIENT_BOUNDS,
    NAMEPLATE_SCALED,
    SURROGATE,
    Coefficients,
    coefficient_bounds,
)
from .files import (
    MONITOR_FILES,
    Calibration,
    actuator_params,
    check_monitor,
    default_calibration,
    load_calibration,
    params_hash,
)

# public name -> the submodule that defines it, imported on first use
_LAZY = {
    **dict.fromkeys(
        ("CALIBRATION_COMMANDS", "CHECK_SCENARIOS", "FIT_SCENARIOS", "PAPER_CHECK_SCENARIOS",
         "PAPER_FIT_SCENARIOS", "Scenario", "hf_references", "scenario_nrmse"),
        "scenarios",
    ),
    "calibrate": "fit_monitor",
    "calibrate_detection": "fit_detection",
    **dict.fromkeys(("UQ_ABSENT", "UQ_CASES", "UQ_CASE_SEED", "calibrate_uq", "collect_cases"), "fit_intervals"),
}  # fmt: skip

__all__ = [
    "ACTUATOR_SCALED",
    "BAND_SCALED",
    "CALIBRATION_COMMANDS",
    "CHECK_SCENARIOS",
    "COEFFICIENT_BOUNDS",
    "FIT_SCENARIOS",
    "MONITOR_FILES",
    "NAMEPLATE_SCALED",
    "PAPER_CHECK_SCENARIOS",
    "PAPER_FIT_SCENARIOS",
    "SURROGATE",
    "UQ_ABSENT",
    "UQ_CASES",
    "UQ_CASE_SEED",
    "Calibration",
    "Coefficients",
    "Scenario",
    "actuator_params",
    "calibrate",
    "calibrate_detection",
    "calibrate_uq",
    "check_monitor",
    "coefficient_bounds",
    "collect_cases",
    "default_calibration",
    "hf_references",
    "load_calibration",
    "params_hash",
    "scenario_nrmse",
]


__getattr__, __dir__ = lazy_names(__name__, _LAZY, globals())


if TYPE_CHECKING:  # what type checkers and IDEs see
    from .fit_detection import calibrate_detection
    from .fit_intervals import UQ_ABSENT, UQ_CASE_SEED, UQ_CASES, calibrate_uq, collect_cases
    from .fit_monitor import calibrate
    from .scenarios import (
        CALIBRATION_COMMANDS,
        CHECK_SCENARIOS,
        FIT_SCENARIOS,
        PAPER_CHECK_SCENARIOS,
        PAPER_FIT_SCENARIOS,
        Scenario,
        hf_references,
        scenario_nrmse,
    )
