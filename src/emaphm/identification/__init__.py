"""Comparison of signals, calibration of the monitor model, and (later) fault identification."""

from .signals import CUTOFF_HZ, Comparison, lowpass, nrmse

__all__ = ["CUTOFF_HZ", "Comparison", "lowpass", "nrmse"]
