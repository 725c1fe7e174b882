"""Running maxima and minima over a sliding window, in numpy.

The three windows the pipeline needs (`weights.moving_mask`'s trailing spread of the position,
`weights.error_weights`'s trailing maximum of the command's frequency, `coverage.matches`'s
centred maximum of its curvature) were scipy.ndimage's ``maximum_filter1d`` and
``minimum_filter1d``. Importing scipy.ndimage costs about 0.16 s of every diagnosis's start
(issue 36); these give the same values to the bit (a maximum is exact) with the van Herk /
Gil-Werman scheme: two cumulative maxima per block of the window's length, O(n) for any window.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["running_max", "running_min"]

Edge = Literal["nearest", "reflect"]
_PAD_MODE = {"nearest": "edge", "reflect": "symmetric"}  # scipy.ndimage's names, numpy's modes


def running_max(x: ArrayLike, before: int, after: int = 0, *, mode: Edge = "nearest") -> NDArray[np.float64]:
    """max of `x` over the samples i − `before` … i + `after` at each sample i.

    Beyond the ends `x` is extended as scipy.ndimage extends it: "nearest" repeats the end
    sample, "reflect" mirrors the signal about its end (d c b a | a b c d | d c b a).
    """
    a = np.asarray(x, dtype=np.float64)
    if a.ndim != 1:
        raise ValueError(f"running_max takes a 1-D signal, got shape {a.shape}")
    if before < 0 or after < 0:
        raise ValueError(f"the window reaches back and ahead by >= 0 samples, got {before} and {after}")
    n = len(a)
    k = before + after + 1
    if n == 0 or k == 1:
        return a.copy()
    padded = np.pad(a, (before, after), mode=_PAD_MODE[mode])  # type: ignore[call-overload]
    blocks = -(-len(padded) // k)
    tail = np.full(blocks * k - len(padded), -np.inf)
    b = np.concatenate((padded, tail)).reshape(blocks, k)
    ahead = np.maximum.accumulate(b, axis=1).ravel()  # max from its block's start to the sample
    back = np.maximum.accumulate(b[:, ::-1], axis=1)[:, ::-1].ravel()  # max from it to the block's end
    # the window padded[i : i + k] spans at most two blocks: the end of one, the start of the next
    return np.maximum(back[:n], ahead[k - 1 : k - 1 + n])


def running_min(x: ArrayLike, before: int, after: int = 0, *, mode: Edge = "nearest") -> NDArray[np.float64]:
    """min of `x` over the samples i − `before` … i + `after` (`running_max` of −x)."""
    return -running_max(-np.asarray(x, dtype=np.float64), before, after, mode=mode)
