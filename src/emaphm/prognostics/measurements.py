"""What one stored diagnosis (a row of a results store) says about each fault, and the draws
that correlate the faults' trends (`rul`, `fleet`).

A row's JSON columns are parsed once and kept in the row (`parsed`); a fault's measurement is its
value and standard deviation where the row sizes it (`measurement`: a verdict of `USED_VERDICTS`,
an interval, not flagged ``non_identifiable``); a fault is detected where its verdict is
"present" (`detected`). The trends of one actuator's faults are drawn together, correlated as
their identifications were (`correlations`, `joint_normals`).
"""

from __future__ import annotations

import functools
import json
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..failure import FAULTS

__all__ = ["USED_VERDICTS", "correlations", "detected", "joint_normals", "measurement", "parsed"]

USED_VERDICTS = ("fits", "doubtful")  # of the rows kept (`rul.rul_report`'s include_doubtful)


def parsed(row: dict[str, Any], column: str) -> Any:
    """A JSON column of a row, parsed once (kept in the row under "_" + its name; None when null)."""
    key = "_" + column
    if key not in row:
        row[key] = json.loads(row[column]) if row.get(column) else None
    return row[key]


def measurement(row: dict[str, Any], name: str) -> tuple[float, float] | None:
    """(value, sd) of a fault in one row, or None where the row tells nothing about it."""
    memo = row.setdefault("_measured", {})
    if name not in memo:
        memo[name] = _measure(row, name)
    return memo[name]  # type: ignore[no-any-return]


def _measure(row: dict[str, Any], name: str) -> tuple[float, float] | None:
    """`measurement`, computed (it keeps the answer in the row)."""
    column = FAULTS[name][0]
    j = int(column[1:]) - 1
    if row.get("verdict") not in USED_VERDICTS:  # "does not fit" sizes nothing; doubtful ones chosen before
        return None
    flags = parsed(row, "uq_flags")
    if flags is not None and "non_identifiable" in flags[j]:
        return None
    sd = row.get(f"std_{column}")
    if sd is None or not math.isfinite(sd) or sd <= 0:
        return None
    return float(row[column]), float(sd)


def correlations(rows: list[dict[str, Any]], names: list[str]) -> NDArray[np.float64]:
    """The mean correlation between the estimates of faults `names` over the rows that sized both
    (each identification's ``corr``; none recorded: 0), as a correlation matrix."""
    n = len(names)
    total, count = np.zeros((n, n)), np.zeros((n, n))
    for row in rows:
        corr = parsed(row, "corr")
        if corr is None:
            continue
        used = [measurement(row, name) is not None for name in names]
        for a in range(n):
            for b in range(a + 1, n):
                ja, jb = (int(FAULTS[names[i]][0][1:]) - 1 for i in (a, b))
                value = corr[ja][jb]
                if used[a] and used[b] and value is not None and math.isfinite(value):
                    total[a, b] += value
                    count[a, b] += 1
    rho = np.divide(total, count, out=np.zeros((n, n)), where=count > 0)
    rho = rho + rho.T + np.eye(n)
    w, V = np.linalg.eigh(rho)  # a mean of correlation matrices is one; clip rounding below 0
    rho = (V * np.maximum(w, 1e-9)) @ V.T
    d = np.sqrt(np.diag(rho))
    return np.asarray(rho / np.outer(d, d), dtype=np.float64)


def joint_normals(rho: NDArray[np.float64], n: int, dims: int, seed: int) -> NDArray[np.float64]:
    """(faults, n, dims) standard normal draws, fault f's correlated with fault g's by rho[f, g]
    component by component (a Gaussian copula on the trends' posteriors)."""
    L = np.linalg.cholesky(rho)
    z = _standard_normals(n, dims, len(rho), seed)  # (faults, n, dims): z_f correlated by L
    return np.asarray((L @ z.reshape(len(rho), -1)).reshape(z.shape), dtype=np.float64)


@functools.lru_cache(maxsize=8)
def _standard_normals(n: int, dims: int, faults: int, seed: int) -> NDArray[np.float64]:
    """The (faults, n, dims) standard normal draws of `seed` (drawn as (n, dims, faults)), drawn
    once: a fleet's actuators share them."""
    z = np.ascontiguousarray(
        np.moveaxis(np.random.default_rng(seed).standard_normal((n, dims, faults)), -1, 0)
    )
    z.flags.writeable = False
    return z


def detected(row: dict[str, Any], name: str) -> bool:
    if "_present" not in row:
        verdicts = parsed(row, "fault_verdicts")
        row["_present"] = (
            {n for n, v in verdicts.items() if v == "present"} if verdicts is not None
            else set((row.get("detected") or "").split(","))
        )  # fmt: skip
    return name in row["_present"]
