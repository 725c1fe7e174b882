"""The data of one actuator's trend chart on the fleet page: each tracked fault's diagnoses over the
flights, the trend fitted to them, its healthy value and its failure threshold (`fleet`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..failure import FAULTS
from .measurements import measurement

__all__ = ["series"]

AHEAD = 10  # the trend is drawn this many flights past the last one (or to the inspection interval's end)


def _numbers(values: list[Any]) -> list[float | None]:
    """Values rounded to 4 decimals, None where missing or not finite."""
    a = np.array([np.nan if v is None else v for v in values], dtype=np.float64)
    return [None if not math.isfinite(v) else v for v in np.round(a, 4).tolist()]


def series(rows: list[dict[str, Any]], report: dict[str, Any], include_doubtful: bool) -> dict[str, Any]:
    """Per tracked fault of `report` (`rul.rul_of_rows` on `rows`): flights, values, 90 % bounds,
    whether each entered the trend (a doubtful diagnosis left out, a "does not fit" one), the
    trend line, the healthy value and the threshold as a fault value (k8 on the side it drifts)."""
    out: dict[str, Any] = {}
    trends = report.get("_trends", {})
    for name, entry in report["faults"].items():
        if entry.get("status") != "tracked" or name not in trends:
            continue
        column, _, healthy = FAULTS[name]
        ks = [r.get(column) for r in rows]
        last = next((k for k in reversed(ks) if k is not None and math.isfinite(k)), healthy)
        side = -1.0 if last < healthy else 1.0
        bound = healthy if side < 0 else 1.0 - healthy  # a fault value lies in [0, 1]: no projection past it
        t_now = float(report["at_flight"])
        end = t_now + max(AHEAD, report["inspection_interval"])
        t = np.linspace(float(entry.get("tracked_from", rows[0]["flight"])), end, 24)
        trend = trends[name]
        try:
            distance = np.asarray(trend.value(t), dtype=np.float64)
        except Exception:  # a trend that cannot be drawn (a degenerate fit) is left undrawn
            distance = np.array([])
            t = np.array([])
        used = [
            (r.get("verdict") == "fits" or (include_doubtful and r.get("verdict") == "doubtful"))
            and r["flight"] >= entry.get("tracked_from", 0)
            and measurement(r, name) is not None
            for r in rows
        ]
        out[name] = {
            "flight": [r["flight"] for r in rows], "value": _numbers(ks),
            "low": _numbers([r.get(f"ci90_low_{column}") for r in rows]),
            "high": _numbers([r.get(f"ci90_high_{column}") for r in rows]), "used": used,
            "trend_flight": np.round(t, 3).tolist(),
            "trend_value": np.round(healthy + side * np.clip(distance, 0.0, bound), 4).tolist(),
            "healthy": healthy, "threshold_value": round(healthy + side * float(entry["threshold"]), 4),
        }  # fmt: skip
    return out
