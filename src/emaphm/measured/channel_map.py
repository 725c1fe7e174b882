"""The channel map: which column or variable of a measured file is which signal, in which unit.

next-features §D.3 item 2: the mapping is a TOML file written by the user, never guessed. Format::

    [channels]                                   # one entry per signal, SI names of emaphm.results
    t         = { name = "time", unit = "ms" }   # a common time column (or per channel: fs/t0, time)
    theta_cmd = { name = "cmd",  unit = "deg" }  # the position demand, user side (required)
    theta_u   = { name = "pos",  unit = "deg" }  # the measured user position (optional)
    i_q       = { name = "Iq",   unit = "mA" }   # either i_q ...
    i_a       = { name = "Ia",   unit = "mA" }   # ... or the phase currents (i_c optional) ...
    i_b       = { name = "Ib",   unit = "mA" }
    theta_e   = { name = "elec", unit = "deg" }  # ... with the electrical angle, or theta_m (shaft)

    [angle]                                      # optional
    offset = "estimate"                          # or a number: θ0 [deg] added to the angle
    kind = "electrical"                          # the offset's degrees: "electrical" or "mechanical"

Keys of a channel entry:

- ``name`` (required): the column (CSV, Parquet) or variable (HDF5, .mat) in the file. A path
  ``"group/dataset"`` reaches into HDF5 groups and MATLAB structs; inside a MATLAB struct array
  whose elements carry a ``Name`` field (Paderborn's ``Y``), a path part selects the element by
  that name (``"Y/phase_current_1"``). When the file holds a single struct, paths may start
  inside it.
- ``unit`` (required): from the closed table of `emaphm.units`, of the channel's kind.
- ``scale``: multiplier applied before the unit conversion (counts, sensor gain, −1 to flip a
  sign); default 1.
- ``fs`` [Hz] and ``t0`` [s]: a channel without a time column, sampled at t0 + k/fs.
- ``time`` and ``time_unit``: the name of the channel's own time column or variable, and its unit
  (default ``s``). ``time_unit`` also applies to a time raster found in the file (Paderborn
  ``X``).

Each channel's time base is, in this order: its ``time``, its ``fs``, its raster in the file, the
common ``t``. The ``t`` entry takes ``name``, ``unit`` and ``scale`` only.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..units import kind_of, units_of_kind

__all__ = ["ROLES", "ChannelMap", "ChannelSpec"]

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
ROLES = tuple(KIND_OF_ROLE)
ENTRY_KEYS = ("name", "unit", "scale", "fs", "t0", "time", "time_unit")
TIME_ENTRY_KEYS = ("name", "unit", "scale")
TOP_KEYS = ("channels", "angle")
ANGLE_KEYS = ("offset", "kind")
OFFSET_KINDS = ("electrical", "mechanical")


@dataclass(frozen=True)
class ChannelSpec:
    """One mapped channel.

    name : str  column or variable in the file (a ``/`` path for nested data)
    unit : str  unit of the samples (after `scale`), from `emaphm.units.CHANNEL_UNITS`
    scale : float  multiplier applied before the unit conversion [-]
    fs : float or None  sample rate when the channel has no time column [Hz]
    t0 : float  time of the first sample with `fs` [s]
    time : str or None  the channel's own time column or variable
    time_unit : str or None  unit of that time column or of the file's raster (default s)
    """

    name: str
    unit: str
    scale: float = 1.0
    fs: float | None = None
    t0: float = 0.0
    time: str | None = None
    time_unit: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The TOML entry (defaults left out)."""
        out: dict[str, Any] = {"name": self.name, "unit": self.unit}
        if self.scale != 1.0:
            out["scale"] = self.scale
        if self.fs is not None:
            out["fs"] = self.fs
            out["t0"] = self.t0
        if self.time is not None:
            out["time"] = self.time
        if self.time_unit is not None:
            out["time_unit"] = self.time_unit
        return out


@dataclass(frozen=True)
class ChannelMap:
    """Signal name → `ChannelSpec`, plus the angle offset setting (see the module docstring).

    channels : mapping  role (``t``, ``theta_cmd``, ``theta_u``, ``i_q``, ``i_a``, ``i_b``,
        ``i_c``, ``theta_e``, ``theta_m``) → `ChannelSpec`
    angle_offset_deg : float or None  θ0 [deg] added to the electrical angle; None: estimate it
    angle_offset_kind : str  the degrees θ0 is given in: "electrical" (default) or "mechanical"
        (a shaft encoder's data sheet; × pole pairs: `electrical_offset_deg`)
    where : str  where the map came from (a path), for messages
    """

    channels: Mapping[str, ChannelSpec]
    angle_offset_deg: float | None = None
    angle_offset_kind: str = "electrical"
    where: str = field(default="channel map", compare=False)

    def electrical_offset_deg(self, pole_pairs: int) -> float | None:
        """θ0 in electrical degrees (a mechanical offset × `pole_pairs`); None: estimate it."""
        if self.angle_offset_deg is None:
            return None
        return self.angle_offset_deg * (pole_pairs if self.angle_offset_kind == "mechanical" else 1)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> ChannelMap:
        """Read a TOML channel map; `InputError` for a missing, unreadable or invalid file."""
        from ..io import read_toml

        p = Path(path)
        return cls.from_dict(read_toml(p, "channel map"), where=f"channel map {p}")

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "channel map") -> ChannelMap:
        """Build and validate a map from the TOML structure (a dict); `InputError` names the key."""
        if not isinstance(data, Mapping):
            raise InputError(f"{where}: expected a table with [channels], got {type(data).__name__}")
        _unknown(data, TOP_KEYS, where, "top level")
        raw = data.get("channels")
        if not isinstance(raw, Mapping) or not raw:
            raise InputError(f"{where}: needs a [channels] table (theta_cmd and i_q or the phase currents)")
        _unknown(raw, ROLES, where, "[channels]", what="channel")
        channels = {role: _entry(role, entry, where) for role, entry in raw.items()}
        offset, kind = _angle_offset(data.get("angle", {}), where)
        _check_roles(channels, where)
        return cls(channels=channels, angle_offset_deg=offset, angle_offset_kind=kind, where=where)

    def to_dict(self) -> dict[str, Any]:
        """The TOML structure of this map (JSON-ready)."""
        out: dict[str, Any] = {"channels": {role: spec.to_dict() for role, spec in self.channels.items()}}
        out["angle"] = {"offset": "estimate" if self.angle_offset_deg is None else self.angle_offset_deg,
                        "kind": self.angle_offset_kind}  # fmt: skip
        return out

    @property
    def from_phases(self) -> bool:
        """True when i_q is to be computed from the phase currents and an angle."""
        return "i_q" not in self.channels

    @property
    def angle_role(self) -> str | None:
        """``"theta_e"`` or ``"theta_m"``, whichever is mapped (None for neither)."""
        return next((r for r in ("theta_e", "theta_m") if r in self.channels), None)

    def __contains__(self, role: object) -> bool:
        return role in self.channels

    def __getitem__(self, role: str) -> ChannelSpec:
        return self.channels[role]


def _unknown(
    table: Mapping[str, Any], allowed: tuple[str, ...], where: str, at: str, what: str = "key"
) -> None:
    for key in table:
        if key not in allowed:
            raise InputError(f"{where}: unknown {what} {key!r} in {at}; allowed: {', '.join(allowed)}")


def _number(value: Any, key: str, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where}: {key} must be a finite number, got {value!r}")
    return float(value)


def _unit(value: Any, kind: str, key: str, where: str) -> str:
    if not isinstance(value, str):
        raise InputError(f"{where}: {key} must be a unit name (a string), got {value!r}")
    if kind_of(value) is None:
        raise InputError(
            f"{where}: unknown unit {value!r} in {key}; {kind} units: {', '.join(units_of_kind(kind))}"
        )
    if kind_of(value) != kind:
        raise InputError(
            f"{where}: {key} = {value!r} is {_a(kind_of(value))} unit, {key.split('.')[1]} needs {_a(kind)} "
            f"unit ({', '.join(units_of_kind(kind))})"
        )
    return value


def _a(kind: str | None) -> str:
    return f"an {kind}" if kind and kind[0] in "aeiou" else f"a {kind}"


def _entry(role: str, entry: Any, where: str) -> ChannelSpec:
    at = f"channels.{role}"
    if not isinstance(entry, Mapping):
        raise InputError(f'{where}: {at} must be a table such as {{ name = "col", unit = "A" }}')
    _unknown(entry, TIME_ENTRY_KEYS if role == "t" else ENTRY_KEYS, where, f"[{at}]")
    name = entry.get("name")
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"{where}: {at}.name must be the column or variable name (a non-empty string)")
    if "unit" not in entry:
        raise InputError(f"{where}: {at}.unit is missing; {KIND_OF_ROLE[role]} units: "
                         f"{', '.join(units_of_kind(KIND_OF_ROLE[role]))}")  # fmt: skip
    unit = _unit(entry["unit"], KIND_OF_ROLE[role], f"{at}.unit", where)
    scale = _number(entry.get("scale", 1.0), f"{at}.scale", where)
    if scale == 0.0:
        raise InputError(f"{where}: {at}.scale must not be 0")
    fs = entry.get("fs")
    if fs is not None:
        fs = _number(fs, f"{at}.fs", where)
        if fs <= 0:
            raise InputError(f"{where}: {at}.fs must be > 0 Hz, got {fs!r}")
    if "t0" in entry and fs is None:
        raise InputError(f"{where}: {at}.t0 needs {at}.fs (t0 is the time of the first sample at rate fs)")
    t0 = _number(entry.get("t0", 0.0), f"{at}.t0", where)
    time = entry.get("time")
    if time is not None and (not isinstance(time, str) or not time.strip()):
        raise InputError(f"{where}: {at}.time must be the name of a time column (a non-empty string)")
    if time is not None and fs is not None:
        raise InputError(f"{where}: {at} gives both time and fs; use one")
    time_unit = entry.get("time_unit")
    if time_unit is not None:
        if fs is not None:
            raise InputError(f"{where}: {at}.time_unit does not apply with fs (fs is in Hz, t0 in s)")
        time_unit = _unit(time_unit, "time", f"{at}.time_unit", where)
    return ChannelSpec(name=name, unit=unit, scale=scale, fs=fs, t0=t0, time=time, time_unit=time_unit)


def _angle_offset(table: Any, where: str) -> tuple[float | None, str]:
    """The [angle] table: (θ0 [deg] or None to estimate it, the kind of its degrees)."""
    if not isinstance(table, Mapping):
        raise InputError(f'{where}: [angle] must be a table, e.g. [angle] offset = "estimate"')
    _unknown(table, ANGLE_KEYS, where, "[angle]")
    kind = table.get("kind", "electrical")
    if kind not in OFFSET_KINDS:
        raise InputError(f"{where}: angle.kind must be one of {', '.join(map(repr, OFFSET_KINDS))}, got {kind!r}")
    offset = table.get("offset", "estimate")
    if offset == "estimate":
        return None, kind
    if isinstance(offset, str):
        raise InputError(f'{where}: angle.offset must be "estimate" or a number of degrees, got {offset!r}')
    return _number(offset, "angle.offset", where), kind


def _check_roles(channels: Mapping[str, ChannelSpec], where: str) -> None:
    if "theta_cmd" not in channels:
        raise InputError(f"{where}: [channels] has no theta_cmd; the position demand is required")
    if "theta_e" in channels and "theta_m" in channels:
        raise InputError(f"{where}: map one angle, theta_e or theta_m, not both")
    phases = [r for r in ("i_a", "i_b") if r in channels]
    angle = "theta_e" in channels or "theta_m" in channels
    if "i_c" in channels and len(phases) < 2:
        raise InputError(f"{where}: channels.i_c needs i_a and i_b as well")
    if len(phases) == 1:
        other = "i_b" if phases[0] == "i_a" else "i_a"
        raise InputError(f"{where}: channels.{phases[0]} needs {other} as well (two phases at least)")
    if "i_q" not in channels and not (len(phases) == 2 and angle):
        missing = [r for r in ("i_a", "i_b") if r not in channels] + ([] if angle else ["theta_e or theta_m"])
        raise InputError(
            f"{where}: [channels] needs i_q, or the phase currents i_a, i_b with theta_e or theta_m "
            f"(missing: {', '.join(missing)})"
        )
