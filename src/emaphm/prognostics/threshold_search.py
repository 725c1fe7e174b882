"""The search for one fault's failure threshold on the HF twin (`derive_thresholds`).

Per fault: the metrics on a grid of `GRID_POINTS` distances over the fault's range ((0, 1], (0,
0.5] for kp_drift), then bisection of the first grid interval where a requirement breaks, down
to the resolution. The threshold is the upper end of the final interval: the twin breaks a
requirement there, and meets them all at the lower end, less than the resolution below.
Eccentricity takes the worst case over the phases k7 in `ECCENTRICITY_PHASES`, kp_drift over
both directions (k8 = 0.5 − d, a gain that sags, and 0.5 + d): per requirement, the largest
metric of those cases at each distance. A metric that falls between neighbouring grid points is
reported as a warning (`check_monotone`). Backlash under a free-play requirement is solved in
closed form (`free_play_threshold`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..failure import FAULTS
from ..faults import HEALTHY
from ..params import EmaParams
from .requirements import Requirement

__all__ = [
    "ECCENTRICITY_PHASES",
    "GRID_POINTS",
    "MONOTONE_TOLERANCE",
    "bisection_steps",
    "check_monotone",
    "fault_cases",
    "fault_span",
    "fault_vector",
    "free_play_threshold",
    "search",
]

GRID_POINTS = 10  # coarse grid over a fault's range, before the bisection
ECCENTRICITY_PHASES = (0.0, 0.25, 0.5, 0.75)  # k7: the eccentricity's direction, worst case over these
MONOTONE_TOLERANCE = 0.005  # a fall of a metric by more than this fraction between grid points is reported


def fault_vector(name: str, d: float, case: float) -> NDArray[np.float64]:
    """The fault vector with fault `name` at distance `d` from healthy, the others healthy;
    `case` is the eccentricity's phase k7, or the direction (±1) of the gain drift."""
    k = HEALTHY.copy()
    j = int(FAULTS[name][0][1:]) - 1
    if name == "kp_drift":
        k[j] = 0.5 + case * d
    else:
        k[j] = d
    if name == "eccentricity":
        k[6] = case
    return k


def fault_cases(name: str) -> tuple[tuple[str, float], ...]:
    """The (label, case) pairs whose worst case a fault's metrics are."""
    if name == "eccentricity":
        return tuple((f"k7 = {phase:g}", phase) for phase in ECCENTRICITY_PHASES)
    if name == "kp_drift":
        return (("k8 = 0.5 - d", -1.0), ("k8 = 0.5 + d", 1.0))
    return (("", 0.0),)


def fault_span(name: str) -> float:
    """The largest distance from healthy the fault can take."""
    return 0.5 if name == "kp_drift" else 1.0


def bisection_steps(width: float, resolution: float) -> int:
    """Halvings that bring an interval of `width` down to `resolution` or less."""
    return max(0, math.ceil(math.log2(width / resolution) - 1e-12))


def search(
    name: str,
    reqs: list[Requirement],
    simulated: list[Requirement],
    healthy: dict[str, float],
    measure: Callable[[NDArray[np.float64]], dict[str, float]],
    resolution: float,
    steps: int,
    warnings: list[str],
) -> dict[str, Any]:
    """Grid, then bisection, of the simulated requirements for one fault (see the module docstring)."""
    cases = fault_cases(name)

    def worst(d: float) -> tuple[dict[str, float], dict[str, str]]:
        runs = [(label, measure(fault_vector(name, d, case))) for label, case in cases]
        metrics, which = {}, {}
        for r in reqs:
            label, m = max(runs, key=lambda run: run[1][r.kind])
            metrics[r.kind], which[r.kind] = m[r.kind], label
        return metrics, which

    def broken(metrics: dict[str, float]) -> list[Requirement]:
        return [r for r in simulated if metrics[r.kind] >= r.limit]

    span = fault_span(name)
    distances = [span * (i + 1) / GRID_POINTS for i in range(GRID_POINTS)]
    grid = [worst(d) for d in distances]
    values = {r.kind: [m[r.kind] for m, _ in grid] for r in reqs}
    monotone = check_monotone(
        name, [0.0, *distances], simulated, {k: [healthy[k], *v] for k, v in values.items()}, warnings
    )
    found: dict[str, Any] = {"grid": {"distance": distances, **values}, "monotone": monotone}
    first = next((i for i, (m, _) in enumerate(grid) if broken(m)), None)
    if first is None:
        return found
    lo = distances[first - 1] if first > 0 else 0.0
    hi, (at, which) = distances[first], grid[first]
    for _ in range(steps):
        if hi - lo <= resolution:
            break
        mid = 0.5 * (lo + hi)
        m, w = worst(mid)
        if broken(m):
            hi, at, which = mid, m, w
        else:
            lo = mid
    limiting = max(broken(at), key=lambda r: at[r.kind] / r.limit)
    return {
        "threshold": hi, "limited_by": limiting.kind, "at_threshold": at,
        "case": which[limiting.kind] or None, "met_below": lo, **found,
    }  # fmt: skip


def check_monotone(
    name: str,
    distances: list[float],
    simulated: list[Requirement],
    values_by_kind: dict[str, list[float]],
    warnings: list[str],
) -> dict[str, bool]:
    """Whether each metric grows (within `MONOTONE_TOLERANCE`) from healthy over the grid; a
    warning for each one that falls."""
    out = {}
    for r in simulated:
        values = values_by_kind[r.kind]
        falls = [i for i in range(1, len(values)) if values[i] < values[i - 1] * (1.0 - MONOTONE_TOLERANCE)]
        out[r.kind] = not falls
        if falls:
            i = falls[0]
            warnings.append(
                f"{name}: {r.kind} is not monotone on the grid: it falls from {r.show(values[i - 1])} at "
                f"d = {distances[i - 1]:g} to {r.show(values[i])} at d = {distances[i]:g}"
                + (f" (and {len(falls) - 1} more fall(s))" if len(falls) > 1 else "")
                + "; the threshold is the first crossing found, one between grid points may be missed"
            )
    return out


def free_play_threshold(
    entry: dict[str, Any],
    req: Requirement,
    params: EmaParams,
    simulated: list[Requirement],
    measure: Callable[[NDArray[np.float64]], dict[str, float]],
) -> None:
    """The backlash threshold of the free-play requirement, in closed form: B0·(1 + 99·k2) = limit.

    It replaces the simulated threshold when it comes first; the twin is then run once there,
    for the other requirements' metrics at the threshold.
    """
    B0 = params.transmission.B0
    d = (req.limit / B0 - 1.0) / 99.0 if B0 > 0 else math.inf
    entry["free_play_reached_at"] = d if math.isfinite(d) else None
    if d > 1.0 or (entry["threshold"] is not None and entry["threshold"] <= d):
        return
    at = measure(fault_vector("backlash", d, 0.0)) if simulated else {"free_play": req.limit}
    at["free_play"] = req.limit  # B(d) = limit exactly (the mapping's rounding aside)
    entry.update(threshold=d, limited_by="free_play", at_threshold=at, case=None, met_below=None)
