"""emaphm: model-based prognostics and health management of PMSM-driven electromechanical actuators.

The public API:

- `simulate` runs the high-fidelity twin (DESIGN §3) or the monitor model for a fault vector and
  returns a `SimResult`;
- `HighFidelityEma` is the twin itself, `MonitorEma` the calibrated low-fidelity monitor model
  (DESIGN §4); `EmaParams` and its groups hold the parameters;
- `FAULT_NAMES`, `HEALTHY`, `TABLE1_REFERENCE`, `as_fault_vector`, `apply_faults` define the
  fault vector k1..k8 (DESIGN §2);
- `Chirp`, `Step`, `Ramp`, `Sine` are position commands;
- `read_trace` / `write_trace` store traces as HDF5 or CSV;
- `identify` / `FaultIdentifier` find the fault vector from a measured current (DESIGN §5) and
  `percent_error` scores it (paper eq. 4, the reading that reproduces Table 1).
"""

from ._version import __version__
from .commands import Chirp, Ramp, Sine, Step, make_command
from .errors import InputError
from .faults import FAULT_NAMES, HEALTHY, TABLE1_REFERENCE, apply_faults, as_fault_vector
from .identification.identify import FaultIdentifier, IdentificationResult, identify
from .identification.metrics import percent_error
from .io import read_trace, write_trace
from .models import HighFidelityEma, simulate
from .monitor import MonitorEma
from .params import (
    ControllerParams,
    EmaParams,
    IntegrationParams,
    InverterParams,
    MotorParams,
    SensorParams,
    TransmissionParams,
)
from .results import SimResult

__all__ = [
    "FAULT_NAMES",
    "HEALTHY",
    "TABLE1_REFERENCE",
    "Chirp",
    "ControllerParams",
    "EmaParams",
    "FaultIdentifier",
    "HighFidelityEma",
    "IdentificationResult",
    "InputError",
    "IntegrationParams",
    "InverterParams",
    "MonitorEma",
    "MotorParams",
    "Ramp",
    "SensorParams",
    "SimResult",
    "Sine",
    "Step",
    "TransmissionParams",
    "__version__",
    "apply_faults",
    "as_fault_vector",
    "identify",
    "make_command",
    "percent_error",
    "read_trace",
    "simulate",
    "write_trace",
]
