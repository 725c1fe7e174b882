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

A population of monitor-model rows is scored by `Fitness.of_monitor`: one parallel kernel call
(`kernels.fitness.fitness_lf_many`) simulates, filters and sums each row, giving the same numbers
as ``fitness(monitor.simulate_many(K, check=False))`` without the serial filter and sum.
"""

from __future__ import annotations

import copy
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..kernels.fitness import fitness_lf_many, residuals_lf_many
from .signals import Comparison, comparison_filter

if TYPE_CHECKING:
    from ..models import MonitorEma

__all__ = ["SLOPE_UNITS", "Fitness"]

SLOPE_UNITS = {"s": 1.0, "ms": 1e-3}  # the slope in A per this unit of time


class Fitness:
    """eq. (3) against one reference, `comparison` (the filtered measured current on the monitor's grid):
    call it on LF currents (shape (n,) or (m, n)) for err [A²].

    `mask` (0/1 per sample, e.g. `moving_mask`) leaves samples out of the sum; `emphasis` (≥ 0
    per sample, e.g. `error_weights`) scales each sample's weight.
    """

    def __init__(
        self,
        comparison: Comparison,
        slope_unit: str = "s",
        mask: ArrayLike | None = None,
        emphasis: ArrayLike | None = None,
    ) -> None:
        if slope_unit not in SLOPE_UNITS:
            raise InputError(f"unknown slope unit {slope_unit!r}; use one of {', '.join(SLOPE_UNITS)}")
        self.comparison = comparison
        self.slope_unit = slope_unit
        slope = np.gradient(comparison.reference, comparison.t) * SLOPE_UNITS[slope_unit]
        self.weights: NDArray[np.float64] = 1.0 / np.sqrt(slope**2 + 1.0)
        if mask is not None:  # samples left out of the sum (`moving_mask`)
            m = np.asarray(mask, dtype=np.float64)
            if m.shape != self.weights.shape:
                raise ValueError(f"mask has shape {m.shape}, the reference {self.weights.shape}")
            self.weights = self.weights * m
        if emphasis is not None:
            e = np.asarray(emphasis, dtype=np.float64)
            if e.shape != self.weights.shape:
                raise ValueError(f"emphasis has shape {e.shape}, the reference {self.weights.shape}")
            if not np.all(np.isfinite(e) & (e >= 0)):
                raise ValueError("emphasis must be finite and >= 0")
            self.weights = self.weights * e
        # the comparison filter (`signals.lowpass`) for the fused kernel: sosfiltfilt's defaults
        self.sos, self.zi, self.padlen = comparison_filter(comparison.f_s)

    def shifted(self, offset: ArrayLike) -> Fitness:
        """The same eq. 3 (weights, mask, filter) against the reference less `offset` [A] per
        sample: the score of a model whose filtered current is corrected by `offset`
        (`switching.space_mapping`). The weights stay the measurement's own."""
        d = np.asarray(offset, dtype=np.float64)
        if d.shape != self.weights.shape:
            raise ValueError(f"offset has shape {d.shape}, the reference {self.weights.shape}")
        out = copy.copy(self)
        out.comparison = replace(self.comparison, reference=self.comparison.reference - d)
        return out

    def residuals_of_monitor(
        self, monitor: MonitorEma, K: ArrayLike, *, duration: float | None = None
    ) -> NDArray[np.float64]:
        """eq. (3)'s residual vectors r = √w·(I_ref − I_LF) over the samples it weighs (w > 0) for
        each fault row of K, shape (m, samples weighed): one parallel kernel call
        (`kernels.fitness.residuals_lf_many`), Σ r² per row = `of_monitor` to rounding. A row that
        diverged gets NaN residuals."""
        _, theta_cmd = monitor.sample_grid(duration)
        rows = monitor.rows(K)
        self._check_grid(len(theta_cmd))
        keep, root_w, reference = self.weighed()
        out = np.empty((rows.shape[0], len(keep)))
        residuals_lf_many(theta_cmd, rows, self.sos, self.zi, self.padlen, keep, reference, root_w, out)
        return out

    def weighed(self) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
        """The samples eq. (3) weighs (w > 0), their √w and the reference there: the residual
        vector's layout (`residuals_of_monitor`, r = √w·(I_ref − I_LF) on these samples).

        Kept for the weights and reference it was taken from, which a least-squares descent asks
        for at every round (a few hundred times a diagnosis, 40 µs each: issue 36); a `shifted`
        copy, with its own reference, takes its own. Shared: not to be changed in place (read-only
        arrays would be another signature of the fused kernel, which the start table's build
        calls with its own writable ones)."""
        weights, reference = self.weights, self.comparison.reference
        kept = getattr(self, "_weighed", None)
        if kept is not None and kept[0] is weights and kept[1] is reference:
            return kept[2]  # type: ignore[no-any-return]
        keep = np.flatnonzero(weights > 0)
        out = (keep, np.sqrt(weights[keep]), reference[keep])
        self._weighed = (weights, reference, out)
        return out

    def _check_grid(self, n: int) -> None:
        ref = self.comparison.reference
        if n != len(ref):
            raise ValueError(f"the monitor's grid has {n} samples, the reference {len(ref)}")
        if len(ref) <= self.padlen:
            raise ValueError(f"the filter needs more than {self.padlen} samples, got {len(ref)}")

    def __call__(self, currents: ArrayLike) -> NDArray[np.float64]:
        residual = self.comparison.reference - self.comparison.filtered(currents)
        return np.sum(self.weights * residual**2, axis=-1)  # type: ignore[no-any-return]

    def of_monitor(
        self, monitor: MonitorEma, K: ArrayLike, *, duration: float | None = None
    ) -> NDArray[np.float64]:
        """eq. (3) of the monitor model's current for each fault row of K, shape (m,): one parallel
        kernel call (simulation, filter and weighted sum fused per row).

        Equal to ``self(monitor.simulate_many(K, duration=duration, check=False))`` (the same
        operations in the same order); a row that diverged gets NaN. The monitor's sample grid
        over `duration` must be the reference's.
        """
        _, theta_cmd = monitor.sample_grid(duration)
        rows = monitor.rows(K)
        ref = self.comparison.reference
        self._check_grid(len(theta_cmd))
        out = np.empty(rows.shape[0])
        fitness_lf_many(theta_cmd, rows, self.sos, self.zi, self.padlen, ref, self.weights, out)
        return out
