"""Fault detection: which identified faults stand above what a healthy actuator shows (DESIGN §5).

A fault is reported present when its identified value departs from the healthy value by more
than its threshold: k1..k6 from 0, k8 from 0.5 (either way). k7, the eccentricity direction, has no
healthy value and is never reported by itself. The thresholds are measured, not assumed: they come
from identifications of the healthy twin with noise on (different seeds), and their false-alarm
rate is measured on another set of healthy runs (`emaphm.calibration.calibrate_detection`). They
ship as ``emaphm/data/detection.json``, with a record of what they were made with.
"""

from __future__ import annotations

import functools
import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._data import read_package_json
from ..errors import InputError
from ..faults import FAULT_NAMES, HEALTHY, as_fault_vector

__all__ = ["DETECTABLE", "detect", "load_thresholds"]

DETECTABLE = tuple(n for n in FAULT_NAMES if n != "eccentricity_phase")


def load_thresholds(path: str | os.PathLike[str] | None = None) -> Mapping[str, Any]:
    """A thresholds file (the shipped one by default, read once): {"thresholds": {name: deviation}, ...record}.

    Read-only (mappings are `MappingProxyType`, lists tuples): the shipped one is shared by every
    caller. The record's fields beside the thresholds are optional (older files lack the
    ``params_hash``, ``last_stage``, ``settings`` that `calibration.calibrate_detection` writes).
    """
    if path is None:
        return _packaged()
    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise InputError(f"{p}: no such thresholds file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{p}: not a readable JSON thresholds file ({exc})") from None
    return _checked(data, f"{p}: ")


@functools.lru_cache(maxsize=1)
def _packaged() -> Mapping[str, Any]:
    return _checked(read_package_json("detection.json"), "")


def _checked(data: Any, where: str) -> Mapping[str, Any]:
    """`data` read-only if its thresholds name exactly `DETECTABLE`, each a number >= 0; `InputError` else."""
    thresholds = data.get("thresholds") if isinstance(data, dict) else None
    if not isinstance(thresholds, dict) or set(thresholds) != set(DETECTABLE):
        raise InputError(f"{where}detection thresholds must name exactly {', '.join(DETECTABLE)}")
    for name, value in thresholds.items():
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
            or value < 0
        ):
            raise InputError(f"{where}detection threshold {name}={value!r} must be a number >= 0")
    return _read_only(data)  # type: ignore[no-any-return]


def _read_only(value: Any) -> Any:
    """`value` with every dict a `MappingProxyType` and every list a tuple, recursively."""
    if isinstance(value, dict):
        return MappingProxyType({k: _read_only(v) for k, v in value.items()})
    if isinstance(value, list):
        return tuple(_read_only(v) for v in value)
    return value


def detect(estimate: ArrayLike, thresholds: Mapping[str, float] | None = None) -> list[str]:
    """Names of the faults whose identified value exceeds its threshold above healthy.

    Parameters
    ----------
    estimate : array_like of 8 floats in [0, 1]
        The identified fault vector k1..k8.
    thresholds : mapping of str to float, optional
        Fault name -> threshold, in fault units above healthy ({}: nothing is detected; default:
        the shipped ones, ``data/detection.json``).
    """
    k = as_fault_vector(estimate, name="estimate")
    limits = thresholds if thresholds is not None else load_thresholds()["thresholds"]
    deviation = np.abs(k - HEALTHY)
    return [name for i, name in enumerate(FAULT_NAMES) if name in limits and deviation[i] > limits[name]]
