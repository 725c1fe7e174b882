"""The comparison pipeline shared by calibration and identification (DESIGN §5).

Both signals (the measured or HF i_q and the LF current) go through the same zero-phase low-pass
filter on the same time grid before they are compared:

- **filter**: 2nd-order Butterworth at 150 Hz (*choice*), applied forward and backward
  (``scipy.signal.sosfiltfilt``'s numbers): zero phase, so no lag between the signals; it keeps
  the 1θ_e and 2θ_e fault harmonics (≤ 80 Hz on the FDI chirp) and removes the hysteresis ripple
  (kHz). The one biquad is designed here (`butterworth2`, `biquad_zi`) and run by the numba
  kernel `kernels.fitness.sosfiltfilt_many`: the numbers of ``butter`` and ``sosfilt_zi`` to the
  last bit, those of ``sosfiltfilt`` to the last bit on the machines measured (the tests allow
  1e-12 for a scipy built with fused multiply-adds). Not scipy's own, because importing
  ``scipy.signal`` costs 0.9 s (scipy 1.17 loads all of it, ``scipy.stats`` included) on every
  ``emaphm identify``, whose goal is 2 s in all; the order-8 anti-aliasing filter of `resample`
  still imports it.
- **grid**: the LF model's sample grid t_k = k/f_s; a reference trace on another grid is
  interpolated onto it (`Comparison.from_trace`, `resample`), after an anti-aliasing low-pass on
  its own grid when it is sampled faster.
- **NRMSE** (the calibration objective and the LF-vs-HF figure of merit):

      NRMSE = ‖I_ref − I‖₂ ⁄ ‖I_ref − mean(I_ref)‖₂          (both filtered)

  i.e. the RMS error over the standard deviation of the reference (MATLAB's goodnessOfFit
  'NRMSE' cost). 0 is a perfect match; 1 is no better than the reference's mean.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..kernels.fitness import sosfiltfilt_many, sosfiltfilt_one

__all__ = [
    "CUTOFF_HZ",
    "FILTER_ORDER",
    "Comparison",
    "biquad_zi",
    "butterworth2",
    "comparison_filter",
    "lowpass",
    "nrmse",
    "resample",
    "sosfiltfilt_padlen",
]

CUTOFF_HZ = 150.0
FILTER_ORDER = 2


def butterworth2(cutoff: float, f_s: float) -> NDArray[np.float64]:
    """The digital 2nd-order Butterworth low-pass at `cutoff` [Hz] for rate `f_s` [Hz] as one
    second-order section [[b0, b1, b2, 1, a1, a2]]: ``scipy.signal.butter(2, cutoff, fs=f_s,
    output="sos")``, computed in the same steps (analogue poles −ω_w·e^(±jπ/4) at the pre-warped
    ω_w = 4·tan(π·W/2), W = 2·cutoff/f_s; bilinear transform at 2·fs = 4; the two zeros at z = −1),
    so the same numbers to the last bit (tested over rates and cutoffs)."""
    cutoff, f_s = float(cutoff), float(f_s)
    if not (math.isfinite(cutoff) and math.isfinite(f_s) and 0.0 < cutoff < f_s / 2.0):
        raise ValueError(f"the cutoff must lie in (0, f_s/2) = (0, {f_s / 2:g}) Hz, got {cutoff:g}")
    warped = 4.0 * np.tan(np.pi * (2.0 * cutoff / f_s) / 2.0)
    p = -np.exp(1j * np.pi * np.array([-1.0, 1.0]) / 4.0) * warped
    p_z = (4.0 + p) / (4.0 - p)
    k_z = warped**2 * np.real(1.0 / np.prod(4.0 - p))
    a = np.real(np.poly(p_z))
    return np.array([[k_z, 2.0 * k_z, k_z, a[0], a[1], a[2]]])


def biquad_zi(sos: NDArray[np.float64]) -> NDArray[np.float64]:
    """``scipy.signal.sosfilt_zi`` of one section (a0 = 1): the state of direct form II transposed
    after a unit step has settled, (I − Aᵀ)·zi = b[1:] − a[1:]·b0 with A the companion of a."""
    if sos.shape != (1, 6) or sos[0, 3] != 1.0:
        raise ValueError(f"one normalised second-order section is needed, got shape {sos.shape}")
    b0, b1, b2, _, a1, a2 = sos[0]
    i_minus_a = np.array([[1.0 + a1, -1.0], [a2, 1.0]])
    return np.linalg.solve(i_minus_a, np.array([b1 - a1 * b0, b2 - a2 * b0]))[None, :]  # type: ignore[no-any-return]


def comparison_filter(
    f_s: float, cutoff: float = CUTOFF_HZ
) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    """The comparison filter for rate `f_s`: (sos, zi, pad), pad = ``sosfiltfilt``'s default edge
    (9 samples). Read-only arrays (cached per rate and cutoff)."""
    return _comparison_filter(float(f_s), float(cutoff))


@functools.lru_cache(maxsize=16)
def _comparison_filter(f_s: float, cutoff: float) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    sos = butterworth2(cutoff, f_s)
    zi = biquad_zi(sos)
    sos.flags.writeable = False
    zi.flags.writeable = False
    return sos, zi, sosfiltfilt_padlen(sos)


def sosfiltfilt_padlen(sos: NDArray[np.float64]) -> int:
    """The edge `scipy.signal.sosfiltfilt` pads by default: 3·ntaps (9 for one biquad)."""
    ntaps = 2 * sos.shape[0] + 1 - min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return 3 * ntaps


def lowpass(x: ArrayLike, f_s: float, *, cutoff: float = CUTOFF_HZ, axis: int = -1) -> NDArray[np.float64]:
    """Zero-phase Butterworth low-pass (order 2, forward–backward) along `axis`: the numbers of
    ``sosfiltfilt(butter(2, cutoff, fs=f_s, output="sos"), x, axis=axis)``.

    Parameters
    ----------
    x : array_like
        The signal(s), sampled at `f_s`.
    f_s : float
        Sample rate [Hz].
    cutoff : float
        Cut-off frequency [Hz].
    axis : int
        The time axis of `x`.
    """
    sos, zi, pad = comparison_filter(f_s, cutoff)
    a = np.moveaxis(np.asarray(x, dtype=np.float64), axis, -1)
    n = a.shape[-1]
    if n <= pad:
        raise ValueError(f"the filter needs more than {pad} samples, got {n}")
    rows = np.ascontiguousarray(a.reshape(-1, n))
    out = np.empty_like(rows)
    if rows.shape[0] == 1:  # the usual case (a reference, a figure): no parallel launch
        sosfiltfilt_one(rows[0], sos, zi, pad, out[0])
    else:
        sosfiltfilt_many(rows, sos, zi, pad, out)
    return np.moveaxis(out.reshape(a.shape), -1, axis)


def nrmse(reference: ArrayLike, estimate: ArrayLike, *, axis: int = -1) -> NDArray[np.float64] | float:
    """‖ref − est‖ ⁄ ‖ref − mean(ref)‖ along `axis` (inputs already filtered and on one grid).

    Parameters
    ----------
    reference : array_like
        The reference signal (the measured or HF current) [A].
    estimate : array_like
        The model's signal on the same grid [A].
    axis : int
        The time axis.
    """
    ref = np.asarray(reference, dtype=np.float64)
    est = np.asarray(estimate, dtype=np.float64)
    scale = np.linalg.norm(ref - ref.mean(axis=axis, keepdims=True), axis=axis)
    return np.linalg.norm(est - ref, axis=axis) / scale  # type: ignore[no-any-return]


# a source sampled faster than this many times the model grid is low-passed on its own grid first
ANTI_ALIAS_ABOVE = 1.1
ANTI_ALIAS_ORDER = 8
ANTI_ALIAS_FRACTION = 0.4  # of the model grid's rate: 4 kHz for 10 kHz, below its Nyquist
# the samples at each end that `_smooth_edges` replaces, in periods of the anti-aliasing cutoff
EDGE_PERIODS = 2.0


def resample(t_src: ArrayLike, x_src: ArrayLike, t_grid: ArrayLike, f_s: float) -> NDArray[np.float64]:
    """A signal sampled at t_src [s] on the model grid t_grid (rate f_s [Hz]), by linear interpolation.

    A source sampled faster than the grid (by more than `ANTI_ALIAS_ABOVE`, on a uniform grid) is
    first low-passed on its own grid (zero-phase Butterworth, order 8, at 0.4·f_s): interpolating
    first would fold the inverter's ripple above the grid's Nyquist rate into the comparison band
    (issue 10; `studies/bench_resample.py` measured it). A source at the grid's rate or
    slower is interpolated as it is, so a trace on the model grid comes through unchanged.
    """
    t_src = np.asarray(t_src, dtype=np.float64)
    x = np.asarray(x_src, dtype=np.float64)
    t_grid = np.asarray(t_grid, dtype=np.float64)
    if t_grid[0] < t_src[0] - 1e-12 or t_grid[-1] > t_src[-1] + 1e-12:
        raise InputError(
            f"the trace covers {t_src[0]:g}..{t_src[-1]:g} s, the model needs {t_grid[0]:g}..{t_grid[-1]:g} s"
        )
    dt = np.diff(t_src)
    if len(dt) > 0 and np.all(dt > 0):
        step = float(np.median(dt))
        uniform = bool(np.max(np.abs(dt - step)) <= 1e-3 * step)
        f_src = 1.0 / step
        if uniform and f_src > ANTI_ALIAS_ABOVE * f_s:
            from scipy.signal import butter, sosfiltfilt  # 0.9 s to import: only here

            cutoff = ANTI_ALIAS_FRACTION * f_s
            sos = butter(ANTI_ALIAS_ORDER, cutoff, fs=f_src, output="sos")
            if len(x) > 3 * (2 * len(sos) + 1):  # sosfiltfilt's default padding
                x = _smooth_edges(sosfiltfilt(sos, x), math.ceil(EDGE_PERIODS * f_src / cutoff))
    return np.interp(t_grid, t_src, x)


def _smooth_edges(y: NDArray[np.float64], m: int) -> NDArray[np.float64]:
    """The first and last `m` samples of a low-passed signal replaced by a quadratic through the
    next 3m: the filter's padding reflects the ripple about its edge value, and the kink rings for
    about m samples; the comparison's own filter would spread that ringing over milliseconds
    (issue 10: on a 64 kHz recording with a 16 kHz ripple, 1.03 mA in the band, 0.006 mA with this).
    """
    n = len(y)
    if n < 8 * m:
        return y
    head, tail = np.arange(m, 4 * m), np.arange(n - 4 * m, n - m)
    y[:m] = np.polyval(np.polyfit(head, y[m : 4 * m], 2), np.arange(m))
    y[n - m :] = np.polyval(np.polyfit(tail, y[n - 4 * m : n - m], 2), np.arange(n - m, n))
    return y


@dataclass(frozen=True)
class Comparison:
    """A filtered reference current on the model grid, ready to score model currents against.

    t : sample grid [s]; reference : filtered reference current [A]; f_s : sample rate [Hz].
    """

    t: NDArray[np.float64]
    reference: NDArray[np.float64]
    f_s: float

    @classmethod
    def from_signal(cls, t: ArrayLike, i_q: ArrayLike, f_s: float) -> Comparison:
        """From a current sampled on the model grid t (unfiltered)."""
        t = np.asarray(t, dtype=np.float64)
        i_q = np.asarray(i_q, dtype=np.float64)
        if t.shape != i_q.shape or t.ndim != 1:
            raise InputError(f"t and i_q must be 1-D of equal length, got {t.shape} and {i_q.shape}")
        if len(t) < 20:
            raise InputError(f"the reference has {len(t)} samples; at least 20 are needed to filter it")
        if not np.all(np.isfinite(i_q)):
            raise InputError("the reference current contains NaN or inf")
        reference = lowpass(i_q, f_s)
        if not np.ptp(reference) > 0.0:  # NRMSE divides by its spread
            raise InputError("the reference current is constant: there is nothing to compare")
        return cls(t, reference, f_s)

    @classmethod
    def from_trace(cls, t_src: ArrayLike, i_q_src: ArrayLike, t_grid: ArrayLike, f_s: float) -> Comparison:
        """From a trace on its own grid: onto the model grid (`resample`), then the filter."""
        return cls.from_signal(
            np.asarray(t_grid, dtype=np.float64), resample(t_src, i_q_src, t_grid, f_s), f_s
        )

    def filtered(self, currents: ArrayLike) -> NDArray[np.float64]:
        """Model currents (shape (n,) or (m, n)) through the same filter."""
        return lowpass(currents, self.f_s, axis=-1)

    def nrmse(self, currents: ArrayLike) -> NDArray[np.float64] | float:
        """NRMSE of model currents (unfiltered, shape (n,) or (m, n)) against the reference."""
        return nrmse(self.reference, self.filtered(currents), axis=-1)
