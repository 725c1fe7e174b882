"""The identification fitness: the paper's eq. (3), modified total least squares (DESIGN §5).

    err = Σ_t (I_HF(t) − I_LF(t))² ⁄ sqrt( (dI_HF/dt)² + 1 )

on the comparison pipeline's signals (`signals`): both currents through the same zero-phase
150 Hz low-pass, on the model's sample grid. The slope is taken from the filtered reference by
central differences. **Units**: currents in A and the slope in A/s (SI, as the paper's Simulink
model), so err is in A². Where the measured current changes fast (steep slopes, > 1 A/s) a small
time shift between the signals would produce a large residual; the weight 1/sqrt(slope² + 1)
discounts exactly those samples, which makes the fitness tolerant to small phase lags. A slope
unit of A/ms can be chosen (`slope_unit="ms"`): the weights are then ≈ 1 and err is plain least
squares.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .signals import Comparison

__all__ = ["SLOPE_UNITS", "Fitness"]

SLOPE_UNITS = {"s": 1.0, "ms": 1e-3}  # the slope in A per this unit of time


class Fitness:
    """eq. (3) against one reference: call it on LF currents (shape (n,) or (m, n)) for err [A²]."""

    def __init__(self, reference: Comparison, slope_unit: str = "s") -> None:
        if slope_unit not in SLOPE_UNITS:
            raise InputError(f"unknown slope unit {slope_unit!r}; use one of {', '.join(SLOPE_UNITS)}")
        self.reference = reference
        self.slope_unit = slope_unit
        slope = np.gradient(reference.reference, reference.t) * SLOPE_UNITS[slope_unit]
        self.weights: NDArray[np.float64] = 1.0 / np.sqrt(slope**2 + 1.0)

    def __call__(self, currents: ArrayLike) -> NDArray[np.float64]:
        residual = self.reference.reference - self.reference.filtered(currents)
        return np.sum(self.weights * residual**2, axis=-1)  # type: ignore[no-any-return]
