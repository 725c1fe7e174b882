"""Prognostics (issue 12): from a history of diagnoses to remaining useful life.

- `trend`: `DegradationTrend`, a fault's law over flights fitted with each measurement's own
  variance (MATLAB-like ``update`` / ``restart`` / ``predict_rul``), and `RulEstimate`;
- `rul`: `rul_report`, the RUL of each tracked fault and of the first failure of an actuator of a
  campaign store (`emaphm.campaign`), with the failure thresholds and their status;
- `requirements`: `Requirement`, `parse_requirement`: the limits the actuator must meet (tracking
  error, current demand, free play);
- `thresholds`: `derive_thresholds`, the failure threshold of each fault from the HF twin and
  the requirements, found by `threshold_search` (a grid, then bisection); `threshold_table`:
  `thresholds_toml`, the ``[thresholds]`` table of the actuator file;
- `progpy_model` (the optional ``progpy`` extra; imported only when asked for): the fault-growth
  laws as a ProgPy ``PrognosticsModel`` (`FaultGrowth`), tracked by ProgPy's UKF with each
  identification's own variance (``emaphm rul --estimator ukf``), ProgPy's MonteCarlo predictor
  as a check of the closed-form crossing, and ProgPy's metrics (α-λ, prognostic horizon,
  cumulative relative accuracy) of a sequence of predictions.

``emaphm rul STORE --actuator ID`` and ``emaphm thresholds --require KIND=LIMIT`` are the command
lines; docs/prognostics.md the guide.
"""

from __future__ import annotations

from ..failure import FAULTS, PLACEHOLDER_THRESHOLDS, parse_thresholds
from .requirements import REQUIREMENT_KINDS, Requirement, parse_requirement
from .rul import rul_report
from .threshold_table import thresholds_toml
from .thresholds import derive_thresholds
from .trend import LAWS, DegradationTrend, RulEstimate

__all__ = [
    "FAULTS",
    "LAWS",
    "PLACEHOLDER_THRESHOLDS",
    "REQUIREMENT_KINDS",
    "DegradationTrend",
    "Requirement",
    "RulEstimate",
    "derive_thresholds",
    "parse_requirement",
    "parse_thresholds",
    "rul_report",
    "thresholds_toml",
]
