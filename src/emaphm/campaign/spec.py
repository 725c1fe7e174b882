"""The campaign file: a fleet of actuators to diagnose, expanded into jobs with stable keys (issue 11).

```toml
[campaign]
name  = "fleet-a"
seeds = [1]                        # each measurement is identified once per seed (default [1])

[identify]                         # settings of every identification (all optional):
optimizer = "ga"                   # optimizer, pop_size, generations, polish, second_search, uncertainty,
uncertainty = "laplace"            # monitor, calibration, uq_calibration, params

[[actuator]]                       # one measurement on the HF twin (noise on)
id = "A001"
faults = [0.2, 0.1, 0, 0, 0, 0, 0, 0.5]

[[actuator]]                       # a recording (an emaphm trace, or a rig's file with its map)
id = "A002"
reference = "rig/a002.h5"
# map = "rig/rig.toml"

[[actuator]]                       # recordings over flights, one per flight
id = "A003"
references = ["rig/a003-f1.h5", "rig/a003-f2.h5"]

[[actuator]]                       # a degradation history on the twin: one measurement per flight
id = "A004"
flights = 30
start  = [0.05, 0.02, 0, 0, 0, 0, 0, 0.5]
growth = [0.01, 0.004, 0, 0, 0, 0, 0, 0]     # per flight
law    = "linear"                            # or "exponential", or one law per fault

[[fleet]]                          # many actuators on the twin, drawn at random from `seed`
prefix = "R"                       # ids R000 .. R199 (zero-padded to the count's width)
count  = 200
seed   = 7
faults = "random"                  # DESIGN §7 ranges (`emaphm.faults.random_faults`); absent = 0.3
                                   # makes each fault healthy with that probability
[[fleet]]                          # or histories: any element of start, growth or faults may be
prefix = "H"                       # [low, high], drawn uniformly per actuator
count  = 40
seed   = 8
flights = 30
start  = [0.05, 0.02, 0, 0, 0, 0, 0, 0.5]
growth = [[0.01, 0.02], [0.004, 0.009], 0, 0, 0, 0, 0, 0]
```

- Paths are relative to the campaign file. An actuator may carry its own ``params`` and
  ``calibration`` (another type of actuator in the fleet); they override ``[identify]``'s.
- Flights: a one-off measurement (``faults``, ``reference``) is flight 0; histories number their
  flights 1..N. Linear: k(n) = start + growth·(n − 1); exponential: k(n) = start·e^{growth·(n − 1)}
  (growth is then a rate per flight, and a fault that starts at 0 stays at 0); both clipped to
  [0, 1].
- Seeds: a one-off measurement with seed S is identified exactly as ``emaphm identify
  --true-faults K --seed S`` (or ``--reference F --seed S``): same measurement noise, same
  estimate. Flight n of a history uses the seed `history_seed` (S, n), recorded as
  ``identify_seed``, so that each flight has its own noise and the row can be rerun alone.
- Fleets: ``[[fleet]]`` expands into ``count`` actuators of the kinds above (``faults`` or a
  history), each drawn from ``seed`` alone, so that the same file always gives the same fleet;
  the drawn values are the actuators' truths, in their job keys like any other.
- Job key: the SHA-256 of the job's content (campaign, actuator, flight, seed, the true vector or
  the reference file's SHA-256, the map's, the settings with every file by its SHA-256, and the
  emaphm version), 20 hex digits: the same job always has the same key, a changed input another.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._version import __version__
from ..errors import InputError
from ..faults import as_fault_vector, random_faults
from ..io import read_toml, sha256_of

__all__ = ["CampaignSpec", "Job", "history_seed", "load_campaign"]

ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
TOP_KEYS = {"campaign", "identify", "actuator", "fleet"}
CAMPAIGN_KEYS = {"name", "seeds", "description"}
# identify() settings a campaign may set, with their checks; file paths resolved to the spec's folder
IDENTIFY_KEYS = {
    "optimizer": str, "pop_size": int, "generations": int, "polish": bool, "second_search": bool, "uncertainty": str,
    "monitor": str, "calibration": Path, "uq_calibration": Path, "params": Path,
    "error_corner": float,  # "auto", "off" or Hz, as identify --error-corner
    "last_stage": str,  # "auto", "switching" or "none", as identify --last-stage
}  # fmt: skip
ACTUATOR_KEYS = {"id", "faults", "reference", "references", "map", "flights", "start", "growth", "law", "params",
                 "calibration"}  # fmt: skip
FLEET_KEYS = {"prefix", "count", "seed", "faults", "absent", "flights", "start", "growth", "law", "params",
              "calibration"}  # fmt: skip
LAWS = ("linear", "exponential")
MAX_FLIGHTS = 100_000
MAX_FLEET = 100_000


def history_seed(seed: int, flight: int) -> int:
    """The identification seed of flight `flight` of a history identified with campaign seed `seed`."""
    return int(np.random.SeedSequence([seed, flight]).generate_state(1)[0])


@dataclass(frozen=True)
class Job:
    """One identification of a campaign (JSON-ready through `to_dict`, for workers)."""

    campaign: str
    actuator: str
    flight: int
    seed: int
    identify_seed: int
    truth: tuple[float, ...] | None
    reference: str | None
    reference_sha256: str | None
    channel_map: str | None
    settings: dict[str, Any]
    key: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "campaign": self.campaign, "actuator": self.actuator, "flight": self.flight, "seed": self.seed,
            "identify_seed": self.identify_seed, "truth": None if self.truth is None else list(self.truth),
            "reference": self.reference, "reference_sha256": self.reference_sha256,
            "channel_map": self.channel_map, "settings": dict(self.settings), "key": self.key,
        }  # fmt: skip


@dataclass(frozen=True)
class _Actuator:
    id: str
    kind: str  # "faults", "reference", "references" or "history"
    truths: list[tuple[float, ...]] = field(default_factory=list)  # per flight (history) or one (faults)
    references: list[Path] = field(default_factory=list)
    channel_map: Path | None = None
    overrides: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class CampaignSpec:
    """A validated campaign file (`load_campaign`)."""

    name: str
    seeds: tuple[int, ...]
    settings: dict[str, Any]
    actuators: tuple[_Actuator, ...]
    source: str = ""
    description: str = ""

    def jobs(self) -> list[Job]:
        """Every job of the campaign, in a stable order (actuator, flight, seed)."""
        digests: dict[Path, str] = {}

        def digest(path: Path) -> str:
            if path not in digests:
                if not path.is_file():
                    raise InputError(f"{self.source}: no such file {path}")
                digests[path] = sha256_of(path)
            return digests[path]

        out = []
        for act in self.actuators:
            settings = {**self.settings, **act.overrides}
            hashed = {
                k: (digest(Path(v)) if k in _FILE_KEYS and v is not None else v) for k, v in settings.items()
            }
            cmap = str(act.channel_map) if act.channel_map is not None else None
            flights: list[tuple[int, tuple[float, ...] | None, Path | None]]
            if act.kind == "faults":
                flights = [(0, act.truths[0], None)]
            elif act.kind == "history":
                flights = [(n, truth, None) for n, truth in enumerate(act.truths, start=1)]
            elif act.kind == "reference":
                flights = [(0, None, act.references[0])]
            else:  # one recording per flight: flight n stays flight n when later ones are added
                flights = [(n, None, ref) for n, ref in enumerate(act.references, start=1)]
            for flight, truth, ref in flights:
                ref_sha = None if ref is None else digest(ref)
                for seed in self.seeds:
                    content = {
                        "campaign": self.name, "actuator": act.id, "flight": flight, "seed": seed,
                        "truth": None if truth is None else [round(v, 12) for v in truth],
                        "reference_sha256": ref_sha,
                        "map_sha256": None if act.channel_map is None else digest(act.channel_map),
                        "settings": hashed, "version": __version__,
                    }  # fmt: skip
                    text = json.dumps(content, sort_keys=True, separators=(",", ":"))
                    out.append(
                        Job(
                            campaign=self.name, actuator=act.id, flight=flight, seed=seed,
                            identify_seed=history_seed(seed, flight) if act.kind == "history" else seed,
                            truth=truth, reference=None if ref is None else str(ref),
                            reference_sha256=ref_sha, channel_map=cmap,
                            settings=settings, key=hashlib.sha256(text.encode()).hexdigest()[:20],
                        )
                    )  # fmt: skip
        return out


_FILE_KEYS = ("calibration", "uq_calibration", "params")


def _fail(where: str, message: str) -> InputError:
    return InputError(f"{where}: {message}")


def _number(v: Any) -> bool:
    """A finite int or float, not a bool."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _vector(value: Any, name: str, where: str, *, faults: bool) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != 8 or not all(_number(v) for v in value):
        raise _fail(where, f"{name} must be a list of 8 numbers, got {value!r}")
    if faults:
        try:
            return tuple(float(v) for v in as_fault_vector(value, name=name))
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
    return [tuple(float(v) for v in row) for row in np.clip(K, 0.0, 1.0)]


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


def _parse_fleet(f: Any, index: int, folder: Path, where: str) -> list[_Actuator]:
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
        return [_Actuator(i, "faults", truths=[tuple(float(v) for v in k)], overrides=overrides) for i, k in zip(ids, K, strict=True)]  # fmt: skip
    flights, laws = _history_form(f, at)
    starts = _drawn(f["start"], "start", at, rng, count, faults=True)
    growths = _drawn(f["growth"], "growth", at, rng, count, faults=False)
    return [
        _Actuator(i, "history", truths=_grow(s0, g, flights, laws), overrides=overrides)
        for i, s0, g in zip(ids, starts, growths, strict=True)
    ]


def _file(value: Any, key: str, folder: Path, at: str) -> Path:
    """The file `value` names, relative to the campaign's folder; `InputError` if there is none."""
    if not isinstance(value, str) or not value:
        raise InputError(f"{at}: {key} must be a file path, got {value!r}")
    p = (folder / value).resolve()
    if not p.is_file():
        raise InputError(f"{at}: {key} {value!r}: no such file ({p})")
    return p


def _parse_actuator(a: Any, index: int, folder: Path, where: str) -> _Actuator:
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
    if "map" in a and kind not in ("reference", "references"):
        raise InputError(f"{at}: map reads a recording: give it with reference(s)")

    def path(value: Any, key: str) -> Path:
        return _file(value, key, folder, at)

    overrides = {k: str(path(a[k], k)) for k in ("params", "calibration") if k in a}
    channel_map = path(a["map"], "map") if "map" in a else None
    if kind == "faults":
        return _Actuator(
            ident, "faults", truths=[_vector(a["faults"], "faults", at, faults=True)], overrides=overrides
        )
    if kind == "flights":
        return _Actuator(ident, "history", truths=_history(a, at), overrides=overrides)
    refs = [a["reference"]] if kind == "reference" else a["references"]
    if not isinstance(refs, list) or not refs:
        raise InputError(f"{at}: references must be a non-empty list of file paths")
    return _Actuator(
        ident,
        kind,
        references=[path(r, kind) for r in refs],
        channel_map=channel_map,
        overrides=overrides,
    )


def _parse_identify(data: Any, folder: Path, where: str) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise _fail(where, "[identify] must be a table")
    unknown = sorted(set(data) - set(IDENTIFY_KEYS))
    if unknown:
        raise _fail(
            where, f"[identify] unknown key(s) {', '.join(unknown)}; known: {', '.join(IDENTIFY_KEYS)}"
        )
    out: dict[str, Any] = {}
    for key, value in data.items():
        kind = IDENTIFY_KEYS[key]
        if key == "error_corner":  # as identify --error-corner; stored as identify takes it
            from ..identification.settings import parse_error_corner

            try:
                out[key] = parse_error_corner(value, name="error_corner")
            except InputError as exc:
                raise _fail(where, f"[identify] {exc}") from None
        elif kind is Path:
            if not isinstance(value, str) or not (folder / value).is_file():
                raise _fail(where, f"[identify] {key} = {value!r}: no such file")
            out[key] = str((folder / value).resolve())
        elif kind is int and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
            raise _fail(where, f"[identify] {key} must be a whole number >= 1, got {value!r}")
        elif not isinstance(value, kind):
            raise _fail(where, f"[identify] {key} must be a {kind.__name__}, got {value!r}")
        else:
            out[key] = value
    from ..identification.optimizers import check_optimizer
    from ..choices import UQ_METHODS

    try:
        check_optimizer(out.get("optimizer", "ga"))
    except InputError as exc:
        raise _fail(where, f"[identify] {exc}") from None
    if out.get("uncertainty", "laplace") not in UQ_METHODS:
        raise _fail(where, f"[identify] uncertainty must be one of {', '.join(UQ_METHODS)}")
    from ..choices import LAST_STAGES

    if out.get("last_stage", "auto") not in LAST_STAGES:
        raise _fail(where, f"[identify] last_stage must be one of {', '.join(LAST_STAGES)}")
    return out


def load_campaign(path: str | os.PathLike[str]) -> CampaignSpec:
    """Read and validate a campaign file; `InputError` (one line, naming the key) for any mistake."""
    p = Path(path)
    where = str(p)
    data = read_toml(p, "campaign file")
    unknown = sorted(set(data) - TOP_KEYS)
    if unknown:
        raise _fail(
            where,
            f"unknown table(s) {', '.join(unknown)}; a campaign has [campaign], [identify], [[actuator]], "
            "[[fleet]]",
        )
    head = data.get("campaign")
    if not isinstance(head, dict):
        raise _fail(where, "no [campaign] table with its name")
    bad = sorted(set(head) - CAMPAIGN_KEYS)
    if bad:
        raise _fail(
            where, f"[campaign] unknown key(s) {', '.join(bad)}; known: {', '.join(sorted(CAMPAIGN_KEYS))}"
        )
    name = head.get("name")
    if not isinstance(name, str) or not ID_PATTERN.match(name):
        raise _fail(where, "[campaign] name must be 1-64 letters, digits, '_', '.' or '-'")
    seeds = head.get("seeds", [1])
    if (
        not isinstance(seeds, list) or not seeds
        or not all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < 2**63 for s in seeds)
        or len(set(seeds)) != len(seeds)
    ):  # fmt: skip
        raise _fail(where, f"[campaign] seeds must be a list of distinct whole numbers >= 0, got {seeds!r}")
    description = head.get("description", "")
    if not isinstance(description, str):
        raise _fail(where, "[campaign] description must be text")
    folder = p.resolve().parent
    settings = _parse_identify(data.get("identify", {}), folder, where)
    raw, fleets = data.get("actuator", []), data.get("fleet", [])
    if not isinstance(raw, list) or not isinstance(fleets, list) or not (raw or fleets):
        raise _fail(where, "no [[actuator]] or [[fleet]]: a campaign needs at least one actuator")
    actuators = tuple(_parse_actuator(a, i, folder, where) for i, a in enumerate(raw)) + tuple(
        a for i, f in enumerate(fleets) for a in _parse_fleet(f, i, folder, where)
    )
    ids = [a.id for a in actuators]
    twice = sorted({i for i in ids if ids.count(i) > 1})
    if twice:
        raise _fail(where, f"actuator id(s) given twice: {', '.join(twice)}")
    return CampaignSpec(name, tuple(seeds), settings, actuators, where, description)
