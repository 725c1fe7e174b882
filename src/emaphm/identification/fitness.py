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

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter, sosfilt_zi

from ..errors import InputError
from ..kernels.fitness import fitness_lf_many
from .signals import CUTOFF_HZ, FILTER_ORDER, Comparison

if TYPE_CHECKING:
    from ..models import MonitorEma

__all__ = ["HOLD_SETTLE_S", "LONG_HOLD_S", "REST_BAND", "SLOPE_UNITS", "Fitness", "moving_mask"]

SLOPE_UNITS = {"s": 1.0, "ms": 1e-3}  # the slope in A per this unit of time

# a hold of the command counts for this long after the command stops (the surface settles)
HOLD_SETTLE_S = 0.05


# without a measured position, only holds of the command longer than this count as rests
LONG_HOLD_S = 0.5

# the surface counts as at rest while its measured position stays within this band [rad]: 10 LSB
# of the 16-bit ±0.3 rad position sensor, 10 σ of its noise (DESIGN §7)
REST_BAND = 1e-4


def moving_mask(
    theta_cmd: ArrayLike,
    f_s: float,
    settle: float = HOLD_SETTLE_S,
    theta_u: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """0 on the samples of a long hold where the surface is stuck, 1 everywhere else.

    A sample is left out when the command has not moved for more than `settle` [s] and the
    measured surface position `theta_u` [rad] has stayed within `REST_BAND` over that time too.
    Without `theta_u` the rest of the surface is unknown: then only the holds of the command
    longer than `LONG_HOLD_S` in all are taken as rests (after `settle`), so that the 0.2 s
    dwells of a staircase, where the surface keeps hunting, stay whole. There the surface sits wherever stick-slip left it, and the position
    loop's integrator ramps the current against that small error: the held current depends on the
    sticking point, not on the faults. On the chirp followed by a hold it differed by 30-37 mA RMS
    between the twin and the monitor at the true faults, against 16 mA over the chirp, and it drove
    identification to 25-40 %err (monitor-model.md §5). After a step the surface keeps moving
    (the loop hunts against friction and backlash) and those samples stay: they carry the faults.
    A command that never holds keeps every sample.
    """
    theta = np.asarray(theta_cmd, dtype=np.float64)
    n = len(theta)
    idx = np.arange(n)
    window = max(round(settle * f_s), 1)
    peak = float(np.max(np.abs(theta))) if n else 0.0
    still = np.zeros(n, dtype=bool)
    still[1:] = np.abs(np.diff(theta)) <= 1e-9 * max(peak, 1e-12)
    last_move = np.maximum.accumulate(np.where(still, 0, idx))  # the last sample the command moved
    held = still & (idx - last_move > window)
    if theta_u is None:
        next_move = np.minimum.accumulate(np.where(still, n, idx)[::-1])[::-1]  # the next sample it moves
        held &= (next_move - last_move) / f_s > LONG_HOLD_S
    else:
        pos = np.asarray(theta_u, dtype=np.float64)
        if pos.shape != theta.shape:
            raise ValueError(f"theta_u has shape {pos.shape}, theta_cmd {theta.shape}")
        # the position's spread over the trailing window, by running max and min
        from scipy.ndimage import maximum_filter1d, minimum_filter1d

        origin = window // 2  # trailing: the window ends at the sample
        spread = maximum_filter1d(pos, window + 1, origin=origin) - minimum_filter1d(
            pos, window + 1, origin=origin
        )
        held &= spread <= REST_BAND
    return np.where(held, 0.0, 1.0)


class Fitness:
    """eq. (3) against one reference: call it on LF currents (shape (n,) or (m, n)) for err [A²].

    `mask` (0/1 per sample, e.g. `moving_mask`) leaves samples out of the sum.
    """

    def __init__(self, reference: Comparison, slope_unit: str = "s", mask: ArrayLike | None = None) -> None:
        if slope_unit not in SLOPE_UNITS:
            raise InputError(f"unknown slope unit {slope_unit!r}; use one of {', '.join(SLOPE_UNITS)}")
        self.reference = reference
        self.slope_unit = slope_unit
        slope = np.gradient(reference.reference, reference.t) * SLOPE_UNITS[slope_unit]
        self.weights: NDArray[np.float64] = 1.0 / np.sqrt(slope**2 + 1.0)
        if mask is not None:  # samples left out of the sum (`moving_mask`)
            m = np.asarray(mask, dtype=np.float64)
            if m.shape != self.weights.shape:
                raise ValueError(f"mask has shape {m.shape}, the reference {self.weights.shape}")
            self.weights = self.weights * m
        # the comparison filter (`signals.lowpass`) for the fused kernel: sosfiltfilt's defaults
        self.sos: NDArray[np.float64] = butter(FILTER_ORDER, CUTOFF_HZ, fs=reference.f_s, output="sos")
        self.zi: NDArray[np.float64] = sosfilt_zi(self.sos)
        self.padlen = sosfiltfilt_padlen(self.sos)

    def __call__(self, currents: ArrayLike) -> NDArray[np.float64]:
        residual = self.reference.reference - self.reference.filtered(currents)
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
        ref = self.reference.reference
        if len(theta_cmd) != len(ref):
            raise ValueError(f"the monitor's grid has {len(theta_cmd)} samples, the reference {len(ref)}")
        if len(ref) <= self.padlen:
            raise ValueError(f"the filter needs more than {self.padlen} samples, got {len(ref)}")
        out = np.empty(rows.shape[0])
        fitness_lf_many(theta_cmd, rows, self.sos, self.zi, self.padlen, ref, self.weights, out)
        return out


def sosfiltfilt_padlen(sos: NDArray[np.float64]) -> int:
    """The edge `scipy.signal.sosfiltfilt` pads by default: 3·ntaps (9 for one biquad)."""
    ntaps = 2 * sos.shape[0] + 1 - min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return 3 * ntaps
