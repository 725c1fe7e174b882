"""Fault detection: which identified faults stand above what a healthy actuator shows (DESIGN §5).

A fault is reported present when its identified value departs from the healthy value by more
than its threshold: k1..k6 from 0, k8 from 0.5 (either way). k7, the eccentricity direction, has no
healthy value and is never reported by itself. The thresholds are measured, not assumed: they come
from identifications of the healthy twin with noise on (different seeds), and their false-alarm
rate is measured on another set of healthy runs (`benchmarks/detection_thresholds.py`). They ship
as ``emaphm/data/detection.json``.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._data import read_package_json
from ..errors import InputError
from ..faults import FAULT_NAMES, HEALTHY, as_fault_vector

__all__ = ["DETECTABLE", "detect", "load_thresholds"]

DETECTABLE = tuple(n for n in FAULT_NAMES if n != "eccentricity_phase")


@functools.lru_cache(maxsize=1)
def load_thresholds() -> dict[str, Any]:
    """The shipped thresholds file: {"thresholds": {name: deviation}, ...record}."""
    data = read_package_json("detection.json")
    thresholds = data.get("thresholds")
    if not isinstance(thresholds, dict) or set(thresholds) != set(DETECTABLE):
        raise InputError(f"detection thresholds must name exactly {', '.join(DETECTABLE)}")
    return data  # type: ignore[no-any-return]


def detect(estimate: ArrayLike, thresholds: dict[str, float] | None = None) -> list[str]:
    """Names of the faults whose identified value exceeds its threshold above healthy."""
    k = as_fault_vector(estimate, name="estimate")
    limits = thresholds if thresholds is not None else load_thresholds()["thresholds"]
    deviation = np.abs(k - HEALTHY)
    return [name for i, name in enumerate(FAULT_NAMES) if name in limits and deviation[i] > limits[name]]
