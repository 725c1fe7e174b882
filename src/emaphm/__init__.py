"""emaphm: model-based prognostics and health management of PMSM-driven electromechanical actuators.

The public API:

- `simulate` runs the high-fidelity twin (DESIGN §3) or the monitor model for a fault vector and
  returns a `SimResult`;
- `HighFidelityEma` is the twin itself, `MonitorEma` the calibrated low-fidelity monitor model
  (DESIGN §4); `EmaParams` and its groups hold the parameters;
- `FAULT_NAMES`, `HEALTHY`, `TABLE1_REFERENCE`, `as_fault_vector`, `apply_faults` define the
  fault vector k1..k8 (DESIGN §2);
- `Chirp`, `ChirpHold`, `Steps`, `Step`, `Ramp`, `Sine` are position commands;
- `read_trace` / `write_trace` store traces as HDF5 or CSV;
- `identify` / `FaultIdentifier` find the fault vector from a measured current (DESIGN §5), run
  as `IdentifySettings` say, and
  `percent_error` scores it (paper eq. 4, the reading that reproduces Table 1);
- `Uncertainty` holds the 90 % intervals of a result, `verdicts` turns them into each fault's verdict;
- `calibrate` fits the monitor model to the twin, `load_calibration` reads such a file;
  `calibrate_uq` fits the intervals' scale and floor, `calibrate_detection` the detection thresholds;
- `load_params` reads an actuator file into `EmaParams`;
- `ChannelMap`, `load_measurement`, `to_reference` turn a rig's recording into a reference trace;
- `run_campaign` runs a fleet campaign into a results store, `rul_report` reads the remaining useful
  life from it, `derive_thresholds` finds each fault's failure threshold from the requirements.

The subpackages `identification`, `calibration`, `measured`, `campaign`, `prognostics` and `models`
list more in their own ``__all__`` (docs/conventions.md says what is public).

The names are imported on first use (PEP 562), so ``import emaphm`` and ``emaphm --version``
stay fast: numba kernels, scipy and pymoo load only when a name that needs them is used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._lazy import lazy_names
from ._version import __version__
from .errors import InputError, SimulationError

# public name -> module that defines it
_LAZY = {
    "Chirp": "commands", "ChirpHold": "commands", "Steps": "commands", "Ramp": "commands", "Sine": "commands", "Step": "commands",
    "make_command": "commands",
    "FAULT_NAMES": "faults", "HEALTHY": "faults", "TABLE1_REFERENCE": "faults",
    "apply_faults": "faults", "as_fault_vector": "faults",
    "FaultIdentifier": "identification.identifier", "IdentificationResult": "identification.result",
    "identify": "identification.api", "IdentifySettings": "identification.settings",
    "percent_error": "identification.metrics", "absolute_errors": "identification.metrics",
    "detect": "identification.detection",
    "Uncertainty": "identification.uncertainty", "verdicts": "identification.uncertainty",
    "calibrate": "calibration.fit_monitor", "calibrate_uq": "calibration.fit_intervals",
    "calibrate_detection": "calibration.fit_detection",
    "Calibration": "calibration", "load_calibration": "calibration",
    "load_params": "actuator",
    "ChannelMap": "measured", "load_measurement": "measured", "to_reference": "measured",
    "run_campaign": "campaign",
    "derive_thresholds": "prognostics", "rul_report": "prognostics",
    "read_trace": "io", "write_trace": "io",
    "HighFidelityEma": "models", "MonitorEma": "models", "simulate": "models",
    "ControllerParams": "params", "EmaParams": "params", "IntegrationParams": "params",
    "InverterParams": "params", "MotorParams": "params", "SensorParams": "params",
    "TransmissionParams": "params",
    "SimResult": "results",
}  # fmt: skip

__all__ = [
    "FAULT_NAMES",
    "HEALTHY",
    "TABLE1_REFERENCE",
    "Calibration",
    "ChannelMap",
    "Chirp",
    "ChirpHold",
    "ControllerParams",
    "EmaParams",
    "FaultIdentifier",
    "HighFidelityEma",
    "IdentificationResult",
    "IdentifySettings",
    "InputError",
    "IntegrationParams",
    "InverterParams",
    "MonitorEma",
    "MotorParams",
    "Ramp",
    "SensorParams",
    "SimResult",
    "SimulationError",
    "Sine",
    "Step",
    "Steps",
    "TransmissionParams",
    "Uncertainty",
    "__version__",
    "absolute_errors",
    "apply_faults",
    "as_fault_vector",
    "calibrate",
    "calibrate_detection",
    "calibrate_uq",
    "derive_thresholds",
    "detect",
    "identify",
    "load_calibration",
    "load_measurement",
    "load_params",
    "make_command",
    "percent_error",
    "read_trace",
    "rul_report",
    "run_campaign",
    "simulate",
    "to_reference",
    "verdicts",
    "write_trace",
]


__getattr__, __dir__ = lazy_names(__name__, _LAZY, globals())


if TYPE_CHECKING:  # what type checkers and IDEs see
    from .actuator import load_params
    from .calibration import Calibration, load_calibration
    from .calibration.fit_detection import calibrate_detection
    from .calibration.fit_intervals import calibrate_uq
    from .calibration.fit_monitor import calibrate
    from .campaign import run_campaign
    from .commands import Chirp, ChirpHold, Ramp, Sine, Step, Steps, make_command
    from .faults import FAULT_NAMES, HEALTHY, TABLE1_REFERENCE, apply_faults, as_fault_vector
    from .identification.api import identify
    from .identification.detection import detect
    from .identification.identifier import FaultIdentifier
    from .identification.metrics import absolute_errors, percent_error
    from .identification.result import IdentificationResult
    from .identification.settings import IdentifySettings
    from .identification.uncertainty import Uncertainty, verdicts
    from .io import read_trace, write_trace
    from .measured import ChannelMap, load_measurement, to_reference
    from .models import HighFidelityEma, MonitorEma, simulate
    from .params import (
        ControllerParams,
        EmaParams,
        IntegrationParams,
        InverterParams,
        MotorParams,
        SensorParams,
        TransmissionParams,
    )
    from .prognostics import derive_thresholds, rul_report
    from .results import SimResult
