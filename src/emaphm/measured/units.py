"""The closed table of units a channel map may name, and their factors to SI (next-features §D.3).

A channel's samples are converted as ``x_SI = x_file · scale · factor(unit)``: `scale` (from the
map, 1 by default) turns counts or a sensor gain into the named unit, `factor` turns the unit into
SI. Anything outside the table is refused: a unit is never guessed.

============  ==========================================  =========
kind          units                                       SI
============  ==========================================  =========
current       ``A``, ``mA``, ``kA``                       A
angle         ``rad``, ``mrad``, ``deg``, ``rev``         rad
time          ``s``, ``ms``, ``us``, ``µs`` (``μs``)      s
============  ==========================================  =========
"""

from __future__ import annotations

import math

__all__ = ["KIND_OF_ROLE", "UNIT_TABLE", "factor", "kind_of", "units_of_kind"]

# unit -> (kind, factor to SI)
UNIT_TABLE: dict[str, tuple[str, float]] = {
    "A": ("current", 1.0),
    "mA": ("current", 1e-3),
    "kA": ("current", 1e3),
    "rad": ("angle", 1.0),
    "mrad": ("angle", 1e-3),
    "deg": ("angle", math.pi / 180.0),
    "rev": ("angle", 2.0 * math.pi),
    "s": ("time", 1.0),
    "ms": ("time", 1e-3),
    "us": ("time", 1e-6),
    "µs": ("time", 1e-6),  # MICRO SIGN U+00B5
    "μs": ("time", 1e-6),  # GREEK SMALL LETTER MU U+03BC
}

# the physical kind of each channel a map may name (the signal names of emaphm.results.UNITS)
KIND_OF_ROLE: dict[str, str] = {
    "t": "time",
    "theta_cmd": "angle",
    "theta_u": "angle",
    "i_q": "current",
    "i_a": "current",
    "i_b": "current",
    "i_c": "current",
    "theta_e": "angle",
    "theta_m": "angle",
}


def kind_of(unit: str) -> str | None:
    """The kind (``"current"``, ``"angle"``, ``"time"``) of `unit`, None when it is not in the table."""
    entry = UNIT_TABLE.get(unit)
    return entry[0] if entry else None


def factor(unit: str) -> float:
    """Factor from `unit` to SI (A, rad, s); `unit` must be in `UNIT_TABLE`."""
    return UNIT_TABLE[unit][1]


def units_of_kind(kind: str) -> list[str]:
    """The units of one kind, in table order (for messages)."""
    return [u for u, (k, _) in UNIT_TABLE.items() if k == kind and u != "μs"]
