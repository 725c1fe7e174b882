"""The optional ProgPy extra, imported once: a one-line `InputError` when it is missing."""

from __future__ import annotations

from ..errors import InputError

try:
    from progpy import PrognosticsModel
    from progpy.predictors import MonteCarlo, ToEPredictionProfile
    from progpy.state_estimators import UnscentedKalmanFilter
    from progpy.uncertain_data import MultivariateNormalDist, UnweightedSamples
except ImportError as exc:  # pragma: no cover - exercised by the test without progpy
    raise InputError(
        "the ProgPy estimator needs the optional extra: pip install 'emaphm[progpy]' "
        f"({type(exc).__name__}: {exc})"
    ) from None

__all__ = [
    "MonteCarlo",
    "MultivariateNormalDist",
    "PrognosticsModel",
    "ToEPredictionProfile",
    "UnscentedKalmanFilter",
    "UnweightedSamples",
]
