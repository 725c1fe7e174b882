"""`load_measurement`: the mapped channels of a measured file, in SI, each on its own time axis.

next-features §D.3 items 1–4 and 9. Each channel is read as stored, multiplied by its ``scale``
and its unit's factor to SI (`emaphm.units`), and given its time base (the channel's
``time`` column, its ``fs``/``t0``, its raster in the file, or the common ``t``; see
`emaphm.measured.channel_map`). Time axes must be strictly increasing wherever they are finite
(a duplicated or backward step is refused naming its row); NaN samples and gaps stay in the
channel: `to_reference` splits the record there. Nothing is resampled here.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..io import sha256_of
from ..units import factor, kind_of
from .channel_map import ChannelMap
from .formats import Column, Source, open_source

__all__ = ["Channel", "Measurement", "load_measurement"]

_LISTED = 30  # names listed in a "missing channel" message


@dataclass(frozen=True)
class Channel:
    """One mapped channel in SI units on its own time axis.

    role : str  the signal (``i_a``, ``theta_cmd``, ...)
    values : ndarray  samples in SI (A or rad); NaN where the file has none
    t : ndarray  sample times [s] (strictly increasing where finite)
    f_s : float  sample rate, 1/median step [Hz]
    name : str  the column or variable in the file
    unit : str  the unit the map declares
    time_source : str  where `t` came from (for the report)
    file_unit : str or None  the unit the file itself declares, if any
    row : callable  sample index → how the file names it (``line 12``, ``sample 12``)
    """

    role: str
    values: NDArray[np.float64]
    t: NDArray[np.float64]
    f_s: float
    name: str
    unit: str
    time_source: str
    file_unit: str | None = None
    row: Callable[[int], str] = field(default=lambda i: f"sample {i}", repr=False, compare=False)

    @property
    def label(self) -> str:
        """``i_a ('Ia')``: the role and the file's name, for messages."""
        return f"{self.role} ({self.name!r})"

    def summary(self) -> dict[str, Any]:
        """Rate, length, span and units (JSON-ready)."""
        finite = np.isfinite(self.t)
        return {
            "name": self.name,
            "unit": self.unit,
            "file_unit": self.file_unit,
            "samples": len(self.values),
            "rate_hz": self.f_s,
            "t_first": float(self.t[finite][0]) if finite.any() else None,
            "t_last": float(self.t[finite][-1]) if finite.any() else None,
            "time_source": self.time_source,
        }


@dataclass(frozen=True)
class Measurement:
    """The mapped channels of one file and where they came from.

    channels : mapping  role → `Channel`
    source : Path  the file read
    sha256 : str  SHA-256 of the file's bytes
    format : str  the format its content showed (`emaphm.measured.formats.FORMATS`)
    channel_map : ChannelMap  the map used
    warnings : tuple of str  what was noticed but not refused (e.g. a unit the file declares differently)
    """

    channels: Mapping[str, Channel]
    source: Path
    sha256: str
    format: str
    channel_map: ChannelMap
    warnings: tuple[str, ...] = ()

    def __getitem__(self, role: str) -> Channel:
        return self.channels[role]

    def __contains__(self, role: object) -> bool:
        return role in self.channels

    @property
    def provenance(self) -> dict[str, Any]:
        """Source path, SHA-256, format, the map as a dict, and each channel's summary (JSON-ready)."""
        return {
            "path": str(self.source),
            "sha256": self.sha256,
            "format": self.format,
            "channel_map": self.channel_map.to_dict(),
            "channel_map_source": self.channel_map.where,
            "channels": {role: ch.summary() for role, ch in self.channels.items()},
        }


def load_measurement(
    path: str | os.PathLike[str], channel_map: ChannelMap | str | os.PathLike[str]
) -> Measurement:
    """Read the channels `channel_map` names from the measured file `path`, in SI.

    Parameters
    ----------
    path : path
        CSV, HDF5 (emaphm traces included), MATLAB ``.mat`` (v4, v5/v7, v7.3) or Parquet; the
        format is recognised by content (`emaphm.measured.formats`).
    channel_map : ChannelMap or path
        The map, or the path of its TOML file.

    Returns
    -------
    Measurement
        One `Channel` per mapped signal (the ``t`` entry becomes each channel's time axis).

    Raises
    ------
    InputError
        A missing, empty, unreadable or unknown file; a mapped name the file lacks (the message
        lists the names it has); non-numeric values (naming the row); a channel without a time
        base or of another length than its time axis; a duplicated or backward time step.
    """
    cmap = channel_map if isinstance(channel_map, ChannelMap) else ChannelMap.load(channel_map)
    p = Path(path)
    with open_source(p) as source:
        sha = sha256_of(p)
        wanted = _wanted_names(cmap)
        _require(source, wanted, p)
        columns = source.read(list(dict.fromkeys(name for name, _ in wanted)))
        notes: list[str] = []
        common_t = _common_time(cmap, columns, p) if "t" in cmap else None
        channels = {}
        for role, spec in cmap.channels.items():
            if role == "t":
                continue
            col = columns[spec.name]
            t, time_source, row = _time_of(role, cmap, col, columns, common_t, p)
            if len(t) != len(col.values):
                raise InputError(
                    f"{p}: {role} ({spec.name!r}) has {len(col.values)} samples, its time axis "
                    f"({time_source}) has {len(t)}"
                )
            if len(col.values) == 0:
                raise InputError(f"{p}: {role} ({spec.name!r}) has no samples")
            f_s = _check_increasing(t, row, f"{p}: {role} ({time_source})")
            values = col.values * (spec.scale * factor(spec.unit))
            file_unit = col.unit.strip() if col.unit else None
            if file_unit and kind_of(file_unit) is not None and file_unit != spec.unit:
                notes.append(
                    f"{role}: the file declares {file_unit!r}, the map {spec.unit!r}; the map's unit is used"
                )
            channels[role] = Channel(role, values, t, f_s, spec.name, spec.unit, time_source, file_unit, row)
        return Measurement(channels, p, sha, source.format, cmap, tuple(notes))


def _wanted_names(cmap: ChannelMap) -> list[tuple[str, str]]:
    out = []
    for role, spec in cmap.channels.items():
        out.append((spec.name, role))
        if spec.time is not None:
            out.append((spec.time, f"{role}.time"))
    return out


def _require(source: Source, wanted: list[tuple[str, str]], p: Path) -> None:
    for name, role in wanted:
        if not source.has(name):
            names = source.names()
            listed = ", ".join(repr(n) for n in names[:_LISTED]) + (" ..." if len(names) > _LISTED else "")
            raise InputError(
                f"{p}: no column or variable {name!r} (mapped to {role}); the file has: {listed or 'nothing'}"
            )


def _common_time(cmap: ChannelMap, columns: dict[str, Column], p: Path) -> Column:
    spec = cmap["t"]
    col = columns[spec.name]
    return Column(values=col.values * (spec.scale * factor(spec.unit)), row=col.row)


def _time_of(
    role: str, cmap: ChannelMap, col: Column, columns: dict[str, Column], common_t: Column | None, p: Path
) -> tuple[NDArray[np.float64], str, Callable[[int], str]]:
    spec = cmap[role]
    if spec.time is not None:
        tcol = columns[spec.time]
        unit = spec.time_unit or "s"
        return tcol.values * factor(unit), f"time column {spec.time!r} in {unit}", tcol.row
    if spec.fs is not None:
        n = len(col.values)
        return spec.t0 + np.arange(n) / spec.fs, f"fs = {spec.fs:g} Hz from t0 = {spec.t0:g} s", col.row
    if col.time is not None:
        declared = col.time_unit if kind_of(col.time_unit) == "time" else None
        unit = spec.time_unit or declared or "s"
        return col.time * factor(unit), f"raster {col.raster!r} in {unit}", col.row
    if spec.time_unit is not None:
        raise InputError(
            f"{cmap.where}: channels.{role}.time_unit is given, but {role} has no time column or raster "
            f"in {p.name}; set channels.{role}.time or drop time_unit"
        )
    if common_t is not None:
        return common_t.values, f"t column {cmap['t'].name!r} in {cmap['t'].unit}", common_t.row
    raise InputError(
        f"{cmap.where}: {role} ({spec.name!r}) has no time base in {p}: map t, or give channels.{role}.fs "
        f"or channels.{role}.time"
    )


def _check_increasing(t: NDArray[np.float64], row: Callable[[int], str], where: str) -> float:
    """Strictly increasing where finite, else `InputError` naming the row; returns 1/median step."""
    idx = np.flatnonzero(np.isfinite(t))
    if len(idx) < 2:
        raise InputError(f"{where}: fewer than 2 finite time stamps")
    steps = np.diff(t[idx])
    bad = np.flatnonzero(steps <= 0)
    if len(bad):
        k = int(idx[bad[0] + 1])
        what = "duplicated time" if steps[bad[0]] == 0 else "time goes backwards"
        raise InputError(
            f"{where}: {what} at {row(k)} (t = {t[k]:.9g} s after {t[idx[bad[0]]]:.9g} s); "
            "the time axis must be strictly increasing"
        )
    return float(1.0 / np.median(steps))
