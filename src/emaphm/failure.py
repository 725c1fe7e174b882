"""The faults prognostics tracks and their failure thresholds (issue 12; a leaf, issue 31).

`FAULTS`: each tracked fault's column of the fault vector, growth law and healthy value (k7, a
direction, is not a damage); `PLACEHOLDER_THRESHOLDS`: the distance from healthy at which each
fails when no threshold is given (next-features §B.3); `parse_thresholds`: thresholds given on
the command line (``--threshold friction=0.45``) or as the ``[thresholds]`` table of an actuator
file (`emaphm.actuator.load_thresholds`).

The actuator file (`emaphm.actuator`) and prognostics (`emaphm.prognostics`) both read these;
this module imports neither.
"""

from __future__ import annotations

import math
from typing import Any

from .errors import InputError

__all__ = ["FAULTS", "PLACEHOLDER_THRESHOLDS", "parse_thresholds"]

# tracked faults: name -> (column, law, healthy value); k7 (a direction) is not a damage
FAULTS: dict[str, tuple[str, str, float]] = {
    "friction": ("k1", "linear", 0.0),
    "backlash": ("k2", "linear", 0.0),
    "short_a": ("k3", "exponential", 0.0),
    "short_b": ("k4", "exponential", 0.0),
    "short_c": ("k5", "exponential", 0.0),
    "eccentricity": ("k6", "linear", 0.0),
    "kp_drift": ("k8", "linear", 0.5),
}
# distances from healthy at which each fault fails, when none is given (next-features §B.3):
# friction and backlash are actuator- and airframe-specific, shorts self-accelerate past a fifth
# of a winding, eccentricity well before a rub, gain drift past its stability margin
PLACEHOLDER_THRESHOLDS: dict[str, float] = {
    "friction": 0.5, "backlash": 0.25, "short_a": 0.2, "short_b": 0.2, "short_c": 0.2,
    "eccentricity": 0.3, "kp_drift": 0.3,
}  # fmt: skip


def parse_thresholds(
    items: list[str] | dict[str, Any] | None, where: str = "--threshold"
) -> dict[str, float]:
    """{"friction": 0.45, ...} from ``["friction=0.45", ...]`` or a dict; `InputError` naming a bad one.

    Parameters
    ----------
    items : list of str, dict or None
        ``["friction=0.45", ...]`` or ``{"friction": 0.45, ...}``: fault name -> threshold in fault
        units from healthy (None: {}).
    where : str
        The option or table they came from, for the error message.
    """
    if not items:
        return {}
    pairs = items.items() if isinstance(items, dict) else (_split(s, where) for s in items)
    out = {}
    for name, value in pairs:
        if name not in FAULTS:
            raise InputError(f"{where}: unknown fault {name!r}; choose from {', '.join(FAULTS)}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(f"{where}: {name} = {value!r} is not a number") from None
        if not (math.isfinite(v) and 0 < v <= 1):
            raise InputError(f"{where}: {name} = {v!r} must be a distance from healthy in (0, 1]")
        out[name] = v
    return out


def _split(item: str, where: str) -> tuple[str, str]:
    if "=" not in item:
        raise InputError(f"{where}: {item!r} must be FAULT=VALUE, e.g. friction=0.45")
    name, value = item.split("=", 1)
    return name.strip(), value.strip()
