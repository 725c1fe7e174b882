"""Comparison of signals, calibration of the monitor model, fault identification and detection.

The identification entry points are re-exported by the top-level package:
``emaphm.identify``, ``emaphm.FaultIdentifier``, ``emaphm.percent_error``.
"""

from .metrics import absolute_errors, percent_error
from .signals import CUTOFF_HZ, Comparison, lowpass, nrmse

__all__ = ["CUTOFF_HZ", "Comparison", "absolute_errors", "lowpass", "nrmse", "percent_error"]
