"""Calibration of the LF monitor model against the HF twin: coefficients, files and the fits.

Calibrating is not identifying: these fits run once per actuator (or monitor change) and write
the files that identification reads.

- `coefficients`: `Coefficients`, the monitor's calibrated constants, and their search box;
- `files`: `Calibration`, the versioned calibration file, its loaders and `params_hash`;
"""

from __future__ import annotations

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

__all__ = [
    "ACTUATOR_SCALED",
    "BAND_SCALED",
    "COEFFICIENT_BOUNDS",
    "MONITOR_FILES",
    "NAMEPLATE_SCALED",
    "SURROGATE",
    "Calibration",
    "Coefficients",
    "actuator_params",
    "check_monitor",
    "coefficient_bounds",
    "default_calibration",
    "load_calibration",
    "params_hash",
]
