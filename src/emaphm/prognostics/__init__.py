"""Prognostics (issue 12): from a history of diagnoses to remaining useful life.

- `trend`: `DegradationTrend`, a fault's law over flights fitted with each measurement's own
  variance (MATLAB-like ``update`` / ``restart`` / ``predict_rul``), and `RulEstimate`;
- `rul`: `rul_report`, the RUL of each tracked fault and of the first failure of an actuator of a
  campaign store (`emaphm.campaign`), with the failure thresholds and their status;
- `metrics`: α-λ, the prognostic horizon and the relative accuracy of a sequence of predictions
  against the true end of life (validation, BENCHMARKS.md).

``emaphm rul STORE --actuator ID`` is the command line; docs/prognostics.md the guide.
"""

from __future__ import annotations

from .rul import FAULTS, PLACEHOLDER_THRESHOLDS, parse_thresholds, rul_report
from .trend import LAWS, DegradationTrend, RulEstimate

__all__ = [
    "FAULTS",
    "LAWS",
    "PLACEHOLDER_THRESHOLDS",
    "DegradationTrend",
    "RulEstimate",
    "parse_thresholds",
    "rul_report",
]
