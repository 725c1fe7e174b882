"""The closed table of units emaphm reads, and the parser of ``"<number> <unit>"`` (issue 31).

`UNITS` holds every unit with its factor to SI, grouped by the SI unit of its quantity (the
``unit`` of the parameter dataclasses' field metadata). Anything outside the table is refused: a
unit is never guessed. Two kinds of input read it:

- an actuator file and a requirement of ``emaphm thresholds``: a value is a number in SI or a
  string ``"1.5 mH"`` (`to_si`), in any unit of its quantity but the channel-only ones
  (`parameter_units`); ``μ`` and ``µ``, ``*`` and ``·``, ``^2`` and ``²``, a space and ``·`` are
  one (`normalise_unit`);
- a channel map (`emaphm.measured`): a channel's unit is named exactly, from the units of its
  kind (`CHANNEL_UNITS`), and its samples are converted as ``x_SI = x_file · scale · factor(unit)``.

============  ==========================================  =========
kind          channel units                               SI
============  ==========================================  =========
current       ``A``, ``mA``, ``kA``                       A
angle         ``rad``, ``mrad``, ``deg``, ``rev``         rad
time          ``s``, ``ms``, ``us``, ``µs`` (``μs``)      s
============  ==========================================  =========
"""

from __future__ import annotations

import math
import re
from typing import Any

from .errors import InputError

__all__ = [
    "CHANNEL_ONLY",
    "CHANNEL_UNITS",
    "KINDS",
    "QUANTITY",
    "UNITS",
    "factor",
    "kind_of",
    "normalise_unit",
    "parameter_units",
    "split_quantity",
    "to_si",
    "units_of_kind",
]

_DEG = math.pi / 180.0

# every unit emaphm reads, by the SI unit of its quantity: factor to SI
UNITS: dict[str, dict[str, float]] = {
    "-": {"-": 1.0, "%": 0.01},
    "Ω": {"Ω": 1.0, "ohm": 1.0, "mΩ": 1e-3, "mohm": 1e-3},
    "H": {"H": 1.0, "mH": 1e-3, "µH": 1e-6, "uH": 1e-6},
    "Wb": {"Wb": 1.0, "mWb": 1e-3, "V·s": 1.0},
    "V": {"V": 1.0, "kV": 1e3},
    "A": {"A": 1.0, "mA": 1e-3, "kA": 1e3},
    "kg·m²": {"kg·m²": 1.0, "kg·cm²": 1e-4, "g·cm²": 1e-7},
    "N·m·s/rad": {"N·m·s/rad": 1.0, "mN·m·s/rad": 1e-3},
    "N·m": {"N·m": 1.0, "Nm": 1.0, "mN·m": 1e-3, "mNm": 1e-3},
    "rad": {"rad": 1.0, "mrad": 1e-3, "deg": _DEG, "°": _DEG, "arcmin": _DEG / 60.0, "rev": 2.0 * math.pi},
    "A/rad": {"A/rad": 1.0, "A/deg": 1.0 / _DEG},
    "A/(rad·s)": {"A/(rad·s)": 1.0, "A/(deg·s)": 1.0 / _DEG},
    "A·s/rad": {"A·s/rad": 1.0, "A·s/deg": 1.0 / _DEG},
    "V/A": {"V/A": 1.0, "Ω": 1.0, "mV/A": 1e-3},  # an FOC drive's PI gains (InverterParams)
    "V/(A·s)": {"V/(A·s)": 1.0, "kV/(A·s)": 1e3},
    # "μs" is GREEK SMALL LETTER MU U+03BC, "µs" MICRO SIGN U+00B5
    "s": {"s": 1.0, "ms": 1e-3, "µs": 1e-6, "us": 1e-6, "μs": 1e-6, "ns": 1e-9},
    "Hz": {"Hz": 1.0, "kHz": 1e3},
    "bit": {"bit": 1.0, "bits": 1.0},
}

# units a channel map may name and an actuator file or a requirement may not (a rig's file counts
# revolutions and kiloamperes; "μs" is read as "µs" there, see `normalise_unit`)
CHANNEL_ONLY: frozenset[str] = frozenset({"kA", "rev", "μs"})

# the kind of quantity a channel holds -> its SI unit
KINDS: dict[str, str] = {"current": "A", "angle": "rad", "time": "s"}

# the units a channel map may name, by kind, in the order its messages list them
CHANNEL_UNITS: dict[str, tuple[str, ...]] = {
    "current": ("A", "mA", "kA"),
    "angle": ("rad", "mrad", "deg", "rev"),
    "time": ("s", "ms", "us", "µs", "μs"),
}

_KIND_OF = {unit: kind for kind, units in CHANNEL_UNITS.items() for unit in units}

# "<number> <unit>": the number, then the unit text (maybe empty)
QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


def parameter_units(si_unit: str) -> dict[str, float]:
    """The units an actuator file or a requirement may give a value of SI unit `si_unit` in,
    with their factors to SI, in table order."""
    return {u: f for u, f in UNITS[si_unit].items() if u not in CHANNEL_ONLY}


def normalise_unit(unit: str) -> str:
    """One spelling of a unit: ``μ`` → ``µ``, ``*`` → ``·``, ``^2`` → ``²``, ``"kg m²"`` → ``"kg·m²"``."""
    u = unit.strip().replace("μ", "µ").replace("*", "·").replace("^2", "²")
    return re.sub(r"(?<=\w) (?=\w)", "·", u)  # "kg m²" -> "kg·m²"


def split_quantity(text: str) -> tuple[float, str] | None:
    """(number, normalised unit) of ``"<number> <unit>"`` (unit "" when none), None when `text`
    does not start with a number."""
    match = QUANTITY.match(text)
    if match is None:
        return None
    return float(match.group(1)), normalise_unit(match.group(2))


def to_si(raw: Any, key: str, si_unit: str, where: str) -> float | int:
    """The SI value of one entry: a number as it is, or a string "<number> <unit>" in one of
    `parameter_units` (`si_unit`); `InputError` naming `where` and `key` otherwise."""
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise InputError(f"{where}: {key} must be a number or a string with a unit, got {raw!r}")
    if not isinstance(raw, str):
        return raw
    match = QUANTITY.match(raw)
    if match is None:
        raise InputError(f'{where}: {key} = {raw!r} is not a number with a unit (e.g. "1.5 {si_unit}")')
    number, unit = float(match.group(1)), normalise_unit(match.group(2))
    table = parameter_units(si_unit)
    if unit == "":
        return number
    if unit not in table:
        raise InputError(
            f"{where}: {key} = {raw!r}: unit {match.group(2)!r} is not one for {key} "
            f"(its unit is {si_unit}; accepted: {', '.join(table)})"
        )
    # 12 significant digits: "1.8 mH" is 0.0018 H, not 0.0018000000000000002 (one actuator, one hash)
    return float(f"{number * table[unit]:.12g}")


def kind_of(unit: str | None) -> str | None:
    """The kind (``"current"``, ``"angle"``, ``"time"``) of a channel unit, None when a channel map
    may not name it."""
    return _KIND_OF.get(unit) if unit is not None else None


def factor(unit: str) -> float:
    """Factor from the channel unit `unit` to SI (A, rad, s); `unit` must be one of `CHANNEL_UNITS`."""
    return UNITS[KINDS[_KIND_OF[unit]]][unit]


def units_of_kind(kind: str) -> list[str]:
    """The channel units of one kind, in table order (for messages; "μs" is shown as "µs")."""
    return [u for u in CHANNEL_UNITS[kind] if u != "μs"]
