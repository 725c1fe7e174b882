"""`inspect_file`: what a measured file holds and whether it would make a reference (JSON-ready)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..params import EmaParams
from ..units import KINDS
from .channel_map import KIND_OF_ROLE, ChannelMap
from .formats import open_source
from .limits import SATURATION_RUN
from .measurement import Channel, load_measurement
from .reference import to_reference

__all__ = ["inspect_file", "saturation"]


def saturation(x: np.ndarray) -> dict[str, Any] | None:
    """The longest run of ≥ `SATURATION_RUN` equal samples at the channel's max or min, if any.

    Returns ``{"value", "run", "at"}`` (``at``: ``"max"`` or ``"min"``) or None.
    """
    v = x[np.isfinite(x)]
    if len(v) < SATURATION_RUN:
        return None
    best: dict[str, Any] | None = None
    for at, extreme in (("max", v.max()), ("min", v.min())):
        hit = np.concatenate(([0], (v == extreme).astype(np.int8), [0]))
        edges = np.flatnonzero(np.diff(hit))
        longest = int(np.max(edges[1::2] - edges[::2])) if len(edges) else 0
        if longest >= SATURATION_RUN and (best is None or longest > best["run"]):
            best = {"value": float(extreme), "run": longest, "at": at}
    return best


def _channel_summary(ch: Channel) -> dict[str, Any]:
    finite_t = ch.t[np.isfinite(ch.t)]
    finite = ch.values[np.isfinite(ch.values)]
    return {
        "name": ch.name,
        "unit": ch.unit,  # the file's, as the map names it; min_si and max_si are in si_unit
        "si_unit": KINDS[KIND_OF_ROLE[ch.role]] if ch.role in KIND_OF_ROLE else None,
        "samples": len(ch.values),
        "rate_hz": ch.f_s,
        "duration_s": float(finite_t[-1] - finite_t[0]) if len(finite_t) > 1 else 0.0,
        "min_si": float(finite.min()) if len(finite) else None,
        "max_si": float(finite.max()) if len(finite) else None,
        "nan_samples": int(len(ch.values) - len(finite)),
        "saturation": saturation(ch.values),
        "time_source": ch.time_source,
    }


def inspect_file(
    path: str | os.PathLike[str],
    channel_map: ChannelMap | str | os.PathLike[str] | None = None,
    params: EmaParams | None = None,
) -> dict[str, Any]:
    """Describe a measured file and, with a channel map, check it (never raises for a readable file).

    Parameters
    ----------
    path : path
        The measured file (any format of `emaphm.measured.formats`).
    channel_map : ChannelMap or path, optional
        With a map, each mapped channel is summarised (rate [Hz], duration [s], min/max in SI,
        NaN count, saturation: a run of ≥ 5 equal samples at its extreme) and the whole
        conversion `to_reference` is tried; what would refuse it goes to ``problems``.
    params : EmaParams, optional
        The actuator for the plausibility checks (nominal by default).

    Returns
    -------
    dict
        ``file``, ``format``, ``size_bytes``, ``variables`` (name, length, dtype), and with a map
        ``channels``, ``problems``, ``warnings``, ``usable`` (no problem found). Without a map,
        ``usable`` says whether the file holds any numeric variable.

    Raises
    ------
    InputError
        A missing, empty, unreadable or unknown file (or an invalid map file).
    """
    p = Path(path)
    with open_source(p) as source:
        variables = source.listing()
        fmt = source.format
    out: dict[str, Any] = {
        "file": str(p),
        "format": fmt,
        "size_bytes": p.stat().st_size,
        "variables": variables,
    }
    problems: list[str] = []
    warnings: list[str] = []
    if channel_map is None:
        if not any(v.get("numeric", True) for v in variables):
            problems.append("no numeric variable in the file")
        out.update(problems=problems, warnings=warnings, usable=not problems)
        return out
    cmap = channel_map if isinstance(channel_map, ChannelMap) else ChannelMap.load(channel_map)
    out["channel_map"] = cmap.to_dict()
    try:
        measurement = load_measurement(p, cmap)
    except InputError as exc:
        problems.append(str(exc))
        out.update(channels={}, problems=problems, warnings=warnings, usable=False)
        return out
    out["sha256"] = measurement.sha256
    out["channels"] = {role: _channel_summary(ch) for role, ch in measurement.channels.items()}
    for role, summary in out["channels"].items():
        # a current's sensor or ADC clips; a position that dwells at its extreme is a surface that
        # sticks there (friction holds it at the peak of the motion), not a saturated sensor
        if summary["saturation"] is not None and role.startswith("i_"):
            s = summary["saturation"]
            warnings.append(f"{role}: {s['run']} equal samples at its {s['at']} ({s['value']:g} A): saturated?")
    try:
        reference = to_reference(measurement, params)
    except InputError as exc:
        problems.append(str(exc))
    else:
        warnings += reference.report["warnings"]
        out["reference"] = {
            "samples": reference.report["grid"]["samples"],
            "duration_s": reference.report["grid"]["duration_s"],
            "angle_offset_deg": reference.report["angle"].get("offset_deg"),
            "flags": reference.report["flags"],
        }
    out.update(problems=problems, warnings=warnings, usable=not problems)
    return out
