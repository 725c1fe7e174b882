"""Which samples eq. (3) compares and how much each counts (DESIGN §5, docs/identification.md §3).

`moving_mask` leaves out the rests in long holds of the command (their current is not the
faults'), `band_mask` the motion faster than the band the monitor was fitted on, and
`error_weights` weights each sample by 1/(1 + (f/f_c)²) of the command's local frequency
(`command_frequency`): where the monitor is known to err more, a sample pulls less. `Fitness`
(`fitness`) takes their product.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .limits import (
    BAND_HZ,
    ERROR_CORNER_HZ,
    ERROR_MEMORY_S,
    HOLD_SETTLE_S,
    LONG_HOLD_S,
    PARK_SETTLE_S,
    REST_BAND,
    REST_SETTLE_S,
    REVERSAL_FRACTION,
)
from .settings import parse_error_corner
from .windows import running_max, running_min

__all__ = [
    "BAND_HZ",
    "ERROR_CORNER_HZ",
    "ERROR_MEMORY_S",
    "HOLD_SETTLE_S",
    "LONG_HOLD_S",
    "PARK_SETTLE_S",
    "REST_BAND",
    "REST_SETTLE_S",
    "REVERSAL_FRACTION",
    "band_mask",
    "command_frequency",
    "error_weights",
    "moving_mask",
    "resolve_error_corner",
]







def _trailing_spread(pos: NDArray[np.float64], window: int) -> NDArray[np.float64]:
    """max − min of `pos` over the `window` + 1 samples ending at each sample (running max and min)."""
    return running_max(pos, window, mode="reflect") - running_min(pos, window, mode="reflect")


def moving_mask(
    theta_cmd: ArrayLike,
    f_s: float,
    settle: float = HOLD_SETTLE_S,
    theta_u: ArrayLike | None = None,
    park_settle: float = PARK_SETTLE_S,
    i_meas: ArrayLike | None = None,
    rest_current: float = 0.0,
) -> NDArray[np.float64]:
    """0 on the samples of a hold where the surface is stuck or parked, 1 everywhere else.

    In a hold longer than `LONG_HOLD_S` in all (a park, not a staircase's dwell) every sample
    after `park_settle` [s] is left out, whatever the surface does. In a shorter hold a sample is
    left out when the command has not moved for more than `settle` [s] and the measured surface
    position `theta_u` [rad] has stayed within `REST_BAND` over that time too; without `theta_u`
    those dwells stay whole (the surface hunts through a staircase's 0.2 s dwells). With the
    measured current `i_meas` [A] (filtered, on the same grid) a sample of a hold is also left out
    once the surface has rested for `REST_SETTLE_S` and |i_meas| < `rest_current` [A] (the
    identification passes the monitor's ring edge, `kernels.monitor.RING_OUTER` · i_D; 0: off;
    off too without `theta_u`, which alone says the surface rests).

    Where the surface rests, it sits wherever stick-slip left it, and the position loop's
    integrator ramps the current against that small error: the held current depends on the
    sticking point, not on the faults. On the chirp followed by a hold it differed by 30-37 mA RMS
    between the twin and the monitor at the true faults, against 16 mA over the chirp, and it drove
    identification to 25-40 %err (monitor-model.md §5). In a park the surface also slips now and
    then, when the integrator has wound up past the breakaway friction: the timing of those slips
    is chaotic, and on 3 of 40 random cases the 0.1 s of them held 74-98 % of eq. (3) at the true
    faults. The stop that begins a park follows the chirp's rattling end and is as chaotic (its
    first 50 ms held 40-70 % of eq. (3) at the true faults on 5 cases), hence the short
    `park_settle`. After a step of a staircase the surface keeps moving (the loop hunts against
    friction and backlash) and those samples stay: they carry the faults. A command that never
    holds keeps every sample. But where the stuck motor's demand is small the loop may rest on a
    zero vector or run, depending on its legs' switching state (`kernels.monitor.standstill_dead_zone`):
    the twin's current there is the demand or nothing, a coin flip the monitor can only average.
    At the true faults such rests at the ends of a staircase's dwells held 62 % of eq. (3) on the
    benchmark's worst steps case (the twin at rest carrying 0 mA at a demand of 65 mA, the monitor
    half of it), and the search bought a better fit there by moving the shorts (issue 8). A rest
    whose measured current lies below the ring's outer edge is therefore left out after a few
    ms; a rest carrying more than that (the loop running against the breakaway friction) stays.
    """
    theta = np.asarray(theta_cmd, dtype=np.float64)
    n = len(theta)
    idx = np.arange(n)
    window = max(round(settle * f_s), 1)
    peak = float(np.max(np.abs(theta))) if n else 0.0
    still = np.zeros(n, dtype=bool)
    still[1:] = np.abs(np.diff(theta)) <= 1e-9 * max(peak, 1e-12)
    last_move = np.maximum.accumulate(np.where(still, 0, idx))  # the last sample the command moved
    next_move = np.minimum.accumulate(np.where(still, n, idx)[::-1])[::-1]  # the next sample it moves
    parked = (next_move - last_move) / f_s > LONG_HOLD_S
    held = still & parked & (idx - last_move > max(round(park_settle * f_s), 1))
    if theta_u is not None:
        pos = np.asarray(theta_u, dtype=np.float64)
        if pos.shape != theta.shape:
            raise ValueError(f"theta_u has shape {pos.shape}, theta_cmd {theta.shape}")
        held |= still & (idx - last_move > window) & (_trailing_spread(pos, window) <= REST_BAND)
        if i_meas is not None and rest_current > 0.0:
            cur = np.asarray(i_meas, dtype=np.float64)
            if cur.shape != theta.shape:
                raise ValueError(f"i_meas has shape {cur.shape}, theta_cmd {theta.shape}")
            short = max(round(REST_SETTLE_S * f_s), 1)
            rests = (idx - last_move > short) & (_trailing_spread(pos, short) <= REST_BAND)
            held |= still & rests & (np.abs(cur) < rest_current)
    return np.where(held, 0.0, 1.0)







def command_frequency(theta_cmd: ArrayLike, f_s: float) -> NDArray[np.float64]:
    """The command's local frequency [Hz] at each sample, from the spacing of its reversals.

    A reversal is a turning point of θ_cmd confirmed once the command has come back from it by
    more than `REVERSAL_FRACTION` of its peak excursion from the median. Between two successive
    turning points the frequency is 1/(2·their spacing): half a period of a sine, the mean
    frequency over that half period of a chirp. Before the first and after the last turning point
    it is the neighbouring half period's, or 1/(2·the stretch) if that is lower (a hold that ends
    the command reads as slow). A command with fewer than two turning points reads 0: a staircase
    reads 1/(2·dwell) where it changes direction, a ramp or a hold 0.
    """
    theta = np.asarray(theta_cmd, dtype=np.float64)
    n = len(theta)
    f = np.zeros(n)
    if n < 3:
        return f
    threshold = REVERSAL_FRACTION * max(float(np.max(np.abs(theta - np.median(theta)))), 1e-300)
    values = theta.tolist()
    turns: list[int] = []
    direction, hi, lo = 0, 0, 0  # direction of travel (0: not yet known); the running high and low
    for i in range(1, n):
        v = values[i]
        if v > values[hi]:
            hi = i
        if v < values[lo]:
            lo = i
        # the first move only sets the direction: where the command starts is no turning point
        if direction >= 0 and values[hi] - v > threshold:  # came down from a high: a maximum
            if direction:
                turns.append(hi)
            direction, lo = -1, i
        elif direction <= 0 and v - values[lo] > threshold:  # came up from a low: a minimum
            if direction:
                turns.append(lo)
            direction, hi = 1, i
    if len(turns) < 2:
        return f
    for a, b in itertools.pairwise(turns):
        f[a:b] = f_s / (2.0 * (b - a))
    first, last = turns[0], turns[-1]
    f[:first] = min(f_s / (2.0 * (turns[1] - first)), f_s / (2.0 * max(first, 1)))
    f[last:] = min(f_s / (2.0 * (last - turns[-2])), f_s / (2.0 * (n - last)))
    return f


def band_mask(theta_cmd: ArrayLike, f_s: float, band_hz: float = BAND_HZ) -> NDArray[np.float64]:
    """0 where the command oscillates faster than `band_hz` (`command_frequency`), 1 elsewhere.

    What the monitor was not fitted on is left out of the comparison rather than fitted: a rig
    that runs the FDI chirp on to 2 s records a second of 10-19.5 Hz motion, where the monitor
    at the true faults errs by 2-5 times more than below 10 Hz and drove identification to twice
    the error of the chirp alone.
    """
    return np.where(command_frequency(theta_cmd, f_s) > band_hz, 0.0, 1.0)


def error_weights(
    theta_cmd: ArrayLike, f_s: float, corner_hz: float | None = ERROR_CORNER_HZ
) -> NDArray[np.float64]:
    """Per-sample weights 1/(1 + (f/f_c)²) for the monitor's error growing with the command's local
    frequency f (`command_frequency`, the highest over the last `ERROR_MEMORY_S`; f_c =
    `corner_hz`, None: all 1).

    Multiplied into eq. (3) (`Fitness(emphasis=...)`), they make it the weighted least squares of
    a model error whose variance grows as 1 + (f/f_c)² (`ERROR_CORNER_HZ`): the motion where the
    monitor is known to be less faithful pulls the estimate less, and so does the stop that
    follows it. Holds and ramps (f = 0) keep 1 once `ERROR_MEMORY_S` has passed.
    """
    theta = np.asarray(theta_cmd, dtype=np.float64)
    if corner_hz is None:
        return np.ones(len(theta))
    if not corner_hz > 0:
        raise InputError(f"the error corner frequency must be > 0 Hz, got {corner_hz}")
    f = command_frequency(theta, f_s)
    memory = round(ERROR_MEMORY_S * f_s)
    if memory > 0 and len(f):  # the highest over [t - memory, t]: a trailing maximum
        f = running_max(f, memory, mode="nearest")
    return 1.0 / (1.0 + (f / corner_hz) ** 2)  # type: ignore[no-any-return]


def resolve_error_corner(value: Any, monitor: str) -> float | None:
    """The corner [Hz] of the frequency weights (`error_weights`) an identification uses: "auto"
    gives `ERROR_CORNER_HZ` with the default monitor and None (none, the paper's eq. 3) with the
    paper's; otherwise as `settings.parse_error_corner` reads it."""
    corner = parse_error_corner(value)
    if corner == "auto":
        return ERROR_CORNER_HZ if monitor == "default" else None
    return corner  # type: ignore[return-value]
