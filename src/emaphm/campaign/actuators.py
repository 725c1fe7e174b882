"""The actuators of a campaign file: ``[[actuator]]`` tables, ``[[fleet]]`` tables expanded into
actuators drawn from their seed, and degradation histories grown flight by flight (issue 11).

The file format is `emaphm.campaign.spec`'s docstring; `parse_actuator` and `parse_fleet` read
one table each into `CampaignActuator` entries (`InputError`, one line naming the table and the
key, for any mistake).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..faults import as_fault_vector, random_faults
from .usage import parse_usage

__all__ = ["ID_PATTERN", "CampaignActuator", "parse_actuator", "parse_fleet"]

ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
ACTUATOR_KEYS = {"id", "faults", "reference", "references", "map", "flights", "start", "growth", "law", "params",
                 "calibration", "baseline", "usage", "healthy"}  # fmt: skip
FLEET_KEYS = {"prefix", "count", "seed", "faults", "absent", "flights", "start", "growth", "law", "params",
              "calibration", "usage"}  # fmt: skip
LAWS = ("linear", "exponential")
MAX_FLIGHTS = 100_000
MAX_FLEET = 100_000


@dataclass(frozen=True)
class CampaignActuator:
    """One actuator of a campaign: its kind, its true fault vectors or its recordings, its overrides."""

    id: str
    kind: str  # "faults", "reference", "references" or "history"
    truths: list[tuple[float, ...]] = field(default_factory=list)  # per flight (history) or one (faults)
    references: list[Path] = field(default_factory=list)
    channel_map: Path | None = None
    overrides: dict[str, Any] = field(default_factory=dict)
    usage: dict[str, Any] = field(default_factory=dict)  # hours, cycles, dates (`usage.parse_usage`)
    healthy: list[Path] = field(default_factory=list)  # recordings when healthy: its baseline (`baselines`)


def _fail(where: str, message: str) -> InputError:
    return InputError(f"{where}: {message}")


def _number(v: Any) -> bool:
    """A finite int or float, not a bool."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _vector(value: Any, name: str, where: str, *, faults: bool) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != 8 or not all(_number(v) for v in value):
        raise _fail(where, f"{name} must be a list of 8 numbers, got {value!r}")
    if faults and not all(0.0 <= v <= 1.0 for v in value):
        try:  # the one-line reason of the fault vector's own check
            as_fault_vector(value, name=name)
        except InputError as exc:
            raise _fail(where, str(exc)) from None
    return tuple(float(v) for v in value)


def _history_form(a: dict[str, Any], where: str) -> tuple[int, list[str]]:
    """A history's number of flights and its laws (one per fault), checked."""
    flights = a.get("flights")
    if isinstance(flights, bool) or not isinstance(flights, int) or not 1 <= flights <= MAX_FLIGHTS:
        raise _fail(where, f"flights must be a whole number 1..{MAX_FLIGHTS}, got {flights!r}")
    if "start" not in a or "growth" not in a:
        raise _fail(where, "a degradation history needs start and growth (8 numbers each) with flights")
    law = a.get("law", "linear")
    laws = [law] * 8 if isinstance(law, str) else law
    if not isinstance(laws, list) or len(laws) != 8 or any(x not in LAWS for x in laws):
        raise _fail(where, f"law must be one of {', '.join(LAWS)}, or a list of 8 of them, got {law!r}")
    return flights, laws


def _grow(start: Any, growth: Any, flights: int, laws: list[str]) -> list[tuple[float, ...]]:
    """The fault vector of each flight 1..`flights` of a history (see the module docstring)."""
    start, growth = np.asarray(start, dtype=np.float64), np.asarray(growth, dtype=np.float64)
    n = np.arange(flights, dtype=np.float64)[:, None]  # flight 1 -> 0 growth steps
    exponential = np.array([x == "exponential" for x in laws])
    K = np.where(exponential, start * np.exp(np.clip(growth * n, None, 700.0)), start + growth * n)
    return [tuple(row) for row in np.clip(K, 0.0, 1.0).tolist()]


def _history(a: dict[str, Any], where: str) -> list[tuple[float, ...]]:
    flights, laws = _history_form(a, where)
    start = _vector(a["start"], "start", where, faults=True)
    growth = _vector(a["growth"], "growth", where, faults=False)
    return _grow(start, growth, flights, laws)


def _drawn(
    value: Any, name: str, where: str, rng: np.random.Generator, count: int, *, faults: bool
) -> NDArray[np.float64]:
    """`count` draws of an 8-vector whose elements are numbers or [low, high] (uniform), (count, 8)."""
    if not isinstance(value, list) or len(value) != 8:
        raise _fail(where, f"{name} must be a list of 8 numbers or [low, high] pairs, got {value!r}")
    low, high = np.empty(8), np.empty(8)
    for j, v in enumerate(value):
        if _number(v):
            low[j] = high[j] = float(v)
        elif isinstance(v, list) and len(v) == 2 and all(_number(x) for x in v) and v[0] <= v[1]:
            low[j], high[j] = float(v[0]), float(v[1])
        else:
            raise _fail(where, f"{name}[{j}] must be a number or [low, high] with low <= high, got {v!r}")
    if faults:
        for bound in (low, high):
            _vector([float(x) for x in bound], name, where, faults=True)  # each end a valid fault vector
    return low + (high - low) * rng.uniform(size=(count, 8))


def parse_fleet(f: Any, index: int, folder: Path, where: str) -> list[CampaignActuator]:
    """The actuators of one ``[[fleet]]`` table (see the module docstring)."""
    at = f"{where}: [[fleet]] {index + 1}"
    if not isinstance(f, dict):
        raise InputError(f"{at} must be a table")
    unknown = sorted(set(f) - FLEET_KEYS)
    if unknown:
        raise InputError(f"{at}: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(FLEET_KEYS))}")
    prefix, count, seed = f.get("prefix"), f.get("count"), f.get("seed")
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_FLEET:
        raise InputError(f"{at}: count must be a whole number 1..{MAX_FLEET}, got {count!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise InputError(f"{at}: seed must be a whole number >= 0 (the fleet is drawn from it), got {seed!r}")
    width = len(str(count - 1))
    if not isinstance(prefix, str) or not ID_PATTERN.match(prefix + "0" * width):
        raise InputError(
            f"{at}: prefix must be letters, digits, '_', '.' or '-', starting with a letter or digit"
        )
    kinds = [k for k in ("faults", "flights") if k in f]
    if len(kinds) != 1:
        raise InputError(
            f"{at}: give exactly one of faults (one measurement each) or flights (a history each)"
        )
    if kinds == ["faults"] and any(k in f for k in ("start", "growth", "law")):
        raise InputError(f"{at}: start, growth and law belong to a history (flights = N)")
    if "absent" in f and f.get("faults") != "random":
        raise InputError(f'{at}: absent goes with faults = "random"')
    overrides = {k: str(_file(f[k], k, folder, at)) for k in ("params", "calibration") if k in f}
    usage = parse_usage(f.get("usage"), at)
    if usage and "faults" in f:
        raise InputError(f"{at}: usage belongs to flights: give it with flights (a history each)")
    ids = [f"{prefix}{i:0{width}d}" for i in range(count)]
    rng = np.random.default_rng(seed)
    if "faults" in f:
        if f["faults"] == "random":
            absent = f.get("absent", 0.0)
            if isinstance(absent, bool) or not isinstance(absent, (int, float)) or not 0.0 <= absent <= 1.0:
                raise InputError(f"{at}: absent must be a probability in [0, 1], got {absent!r}")
            K = random_faults(count, seed, absent=float(absent))
        else:
            K = _drawn(f["faults"], "faults", at, rng, count, faults=True)
        return [CampaignActuator(i, "faults", truths=[tuple(float(v) for v in k)], overrides=overrides, usage=usage) for i, k in zip(ids, K, strict=True)]  # fmt: skip
    flights, laws = _history_form(f, at)
    starts = _drawn(f["start"], "start", at, rng, count, faults=True)
    growths = _drawn(f["growth"], "growth", at, rng, count, faults=False)
    return [
        CampaignActuator(i, "history", truths=_grow(s0, g, flights, laws), overrides=overrides, usage=usage)
        for i, s0, g in zip(ids, starts, growths, strict=True)
    ]


def _baseline_folder(value: Any, folder: Path, at: str) -> Path:
    """The baseline folder `value` names, relative to the campaign's folder, checked (`baseline.baseline_files`)."""
    from ..baseline import baseline_files

    if not isinstance(value, str) or not value:
        raise InputError(f"{at}: baseline must be a folder path, got {value!r}")
    p = (folder / value).resolve()
    try:
        baseline_files(p)
    except InputError as exc:
        raise InputError(f"{at}: {exc}") from None
    return p


def _file(value: Any, key: str, folder: Path, at: str) -> Path:
    """The file `value` names, relative to the campaign's folder; `InputError` if there is none."""
    if not isinstance(value, str) or not value:
        raise InputError(f"{at}: {key} must be a file path, got {value!r}")
    p = (folder / value).resolve()
    if not p.is_file():
        raise InputError(f"{at}: {key} {value!r}: no such file ({p})")
    return p


def parse_actuator(a: Any, index: int, folder: Path, where: str) -> CampaignActuator:
    if not isinstance(a, dict):
        raise _fail(where, f"[[actuator]] {index + 1} must be a table")
    ident = a.get("id")
    at = f"{where}: actuator {ident!r}" if isinstance(ident, str) else f"{where}: [[actuator]] {index + 1}"
    unknown = sorted(set(a) - ACTUATOR_KEYS)
    if unknown:
        raise InputError(
            f"{at}: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(ACTUATOR_KEYS))}"
        )
    if not isinstance(ident, str) or not ID_PATTERN.match(ident):
        raise InputError(
            f"{at}: id must be 1-64 letters, digits, '_', '.' or '-' (starting with a letter or digit)"
        )
    kinds = [k for k in ("faults", "reference", "references", "flights") if k in a]
    if len(kinds) != 1:
        raise InputError(
            f"{at}: give exactly one of faults (the twin), reference(s) (recordings) or flights (a history), "
            f"got {', '.join(kinds) or 'none'}"
        )
    kind = kinds[0]
    if kind != "flights" and any(k in a for k in ("start", "growth", "law")):
        raise InputError(f"{at}: start, growth and law belong to a history (flights = N)")
    if "map" in a and kind not in ("reference", "references") and "healthy" not in a:
        raise InputError(f"{at}: map reads a recording: give it with reference(s) or healthy")
    if "healthy" in a and "baseline" in a:
        raise InputError(f"{at}: give baseline (a folder made) or healthy (recordings to make it from), not both")

    def path(value: Any, key: str) -> Path:
        return _file(value, key, folder, at)

    overrides = {k: str(path(a[k], k)) for k in ("params", "calibration") if k in a}
    if "baseline" in a:  # the actuator's own baseline folder (`emaphm baseline`): its files stand for those
        overrides["baseline"] = str(_baseline_folder(a["baseline"], folder, at))
    channel_map = path(a["map"], "map") if "map" in a else None
    healthy = a.get("healthy", [])
    if not isinstance(healthy, list) or ("healthy" in a and not healthy):
        raise InputError(f"{at}: healthy must be a non-empty list of recordings of the actuator when healthy")
    healthy = [path(h, "healthy") for h in healthy]
    usage = parse_usage(a.get("usage"), at)
    if usage and kind in ("faults", "reference"):
        raise InputError(f"{at}: usage belongs to flights: give it with flights (a history) or references")
    if kind == "faults":
        return CampaignActuator(
            ident, "faults", truths=[_vector(a["faults"], "faults", at, faults=True)], overrides=overrides,
            healthy=healthy,
        )  # fmt: skip
    if kind == "flights":
        return CampaignActuator(ident, "history", truths=_history(a, at), overrides=overrides, usage=usage,
                                healthy=healthy)  # fmt: skip
    refs = [a["reference"]] if kind == "reference" else a["references"]
    if not isinstance(refs, list) or not refs:
        raise InputError(f"{at}: references must be a non-empty list of file paths")
    return CampaignActuator(
        ident,
        kind,
        references=[path(r, kind) for r in refs],
        channel_map=channel_map,
        overrides=overrides,
        usage=usage,
        healthy=healthy,
    )
