"""Analog-to-digital conversion of the sampled signals (DESIGN §3.9)."""

from __future__ import annotations

import numpy as np

from ._jit import jit


@jit
def quantise(x: float, lsb: float, full_scale: float) -> float:
    """Mid-tread quantiser with step `lsb`, saturating at ±full_scale; lsb = 0 is an ideal ADC.

    numpy's floor, a float, not math's: math.floor returns an integer, and the conversions to it
    and back sat in the monitor's step chain (the same numbers: every code is below 2⁵³)."""
    if lsb > 0.0:
        x = lsb * np.floor(x / lsb + 0.5)
        hi = full_scale - lsb  # a two's-complement ADC: one code fewer on the positive side
    else:
        hi = full_scale
    if x > hi:
        return hi
    if x < -full_scale:
        return -full_scale
    return x


@jit
def adc(signal, noise, lsb, full_scale, out):  # type: ignore[no-untyped-def]
    """out[i] = quantise(signal[i] + noise[i]): one converter channel over a whole trace."""
    for i in range(signal.shape[0]):
        out[i] = quantise(signal[i] + noise[i], lsb, full_scale)
