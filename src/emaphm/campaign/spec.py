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
  ``calibration`` (another type of actuator in the fleet); they override ``[identify]``'s. Or its
  own ``baseline`` folder (``emaphm baseline``): its actuator file, calibrations and thresholds
  stand for ``[identify]``'s files, and its files' digests enter the job key.
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

The ``[[actuator]]`` and ``[[fleet]]`` tables are read by `emaphm.campaign.actuators`.
"""

from __future__ import annotations

import collections
import functools
import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..io import read_toml, sha256_of
from .actuators import ID_PATTERN, CampaignActuator, parse_actuator, parse_fleet
from .fingerprint import fingerprint
from .identify_table import IDENTIFY_FILES, parse_identify
from .keys import key_head, key_tail, key_text, truth_text
from .usage import flight_usages

__all__ = ["CampaignSpec", "Job", "history_seed", "load_campaign"]

TOP_KEYS = {"campaign", "identify", "actuator", "fleet"}
CAMPAIGN_KEYS = {"name", "seeds", "description"}
# identify() settings a campaign may set, with their checks; file paths resolved to the spec's folder


@functools.lru_cache(maxsize=4096)  # a fleet's histories share their (seed, flight) pairs
def history_seed(seed: int, flight: int) -> int:
    """The identification seed of flight `flight` of a history identified with campaign seed `seed`."""
    return int(np.random.SeedSequence([seed, flight]).generate_state(1)[0])


@dataclass(frozen=True)
class Job:
    """One identification of a campaign (JSON-ready through `to_dict`, for workers).

    campaign, actuator : str  the campaign's name and the actuator's id
    flight : int  the flight number (0: a one-off measurement)
    seed : int  the job's seed in the campaign; identify_seed : int  the seed identify runs with
    truth : tuple of 8 floats or None  the twin's fault vector (None: a recording is read)
    reference, reference_sha256, channel_map : str or None  the recording, its digest, its channel map
    settings : dict  `identify`'s settings; key : str  the job's content key in the store
    fingerprint : str  what computes it: the code, the packaged data, the settings after defaults
    (`fingerprint.fingerprint`); a stored row with another was made by other code or data
    usage : dict or None  the flight's cumulative hours and cycles and its date (`usage`); not in the key
    """

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
    fingerprint: str = ""
    usage: dict[str, Any] | None = None  # hours, cycles, date of the flight (`usage.flight_usages`); not in the key

    def to_dict(self) -> dict[str, Any]:
        return {
            "campaign": self.campaign, "actuator": self.actuator, "flight": self.flight, "seed": self.seed,
            "identify_seed": self.identify_seed, "truth": None if self.truth is None else list(self.truth),
            "reference": self.reference, "reference_sha256": self.reference_sha256,
            "channel_map": self.channel_map, "settings": dict(self.settings), "key": self.key,
            "fingerprint": self.fingerprint,
        }  # fmt: skip


@dataclass(frozen=True)
class CampaignSpec:
    """A validated campaign file (`load_campaign`).

    name : str  the campaign's name; description : str  its free text
    seeds : tuple of int  the seeds each flight is identified with
    settings : dict  `identify`'s settings for every job (``[identify]``)
    actuators : tuple  the actuators and their flights (``[[actuator]]``, ``[[fleet]]``)
    source : str  the file it was read from
    """

    name: str
    seeds: tuple[int, ...]
    settings: dict[str, Any]
    actuators: tuple[CampaignActuator, ...]
    source: str = ""
    description: str = ""

    def waiting(self, out: str | os.PathLike[str] | None) -> list[str]:
        """The actuators whose identifications wait for a baseline the store `out` lacks (`baselines`)."""
        from .baselines import baseline_jobs

        if not any(a.healthy for a in self.actuators):
            return []
        return [b.actuator for b in baseline_jobs(self, out or ".") if out is None or not b.made()]

    def jobs(self, out: str | os.PathLike[str] | None = None) -> list[Job]:
        """Every job of the campaign, in a stable order (actuator, flight, seed); an actuator with
        ``healthy`` recordings identifies with its baseline in the store `out` (`baselines`), and
        has no jobs until it is made (`waiting`)."""
        from .baselines import baseline_jobs

        made = {}
        if out is not None and any(a.healthy for a in self.actuators):
            made = {b.actuator: b.folder for b in baseline_jobs(self, out) if b.made()}
        digests: dict[Path, str] = {}

        def digest(path: Path) -> str:
            if path not in digests:
                if path.is_dir():  # a baseline folder: the digest of its files' digests
                    from ..baseline import baseline_files

                    parts = "".join(sha256_of(f) for f in baseline_files(path).values())
                    digests[path] = hashlib.sha256(parts.encode()).hexdigest()
                elif not path.is_file():
                    raise InputError(f"{self.source}: no such file {path}")
                else:
                    digests[path] = sha256_of(path)
            return digests[path]

        out = []
        prints: dict[str, str] = {}  # one fingerprint per distinct settings (a fleet shares them)
        for act in self.actuators:
            if act.healthy and act.id not in made:
                continue
            settings = {**self.settings, **act.overrides, **({"baseline": made[act.id]} if act.healthy else {})}
            if "baseline" in settings:  # its actuator file and calibrations stand for the campaign's
                settings = {k: v for k, v in settings.items() if k not in IDENTIFY_FILES}
            files = (*IDENTIFY_FILES, "baseline")
            hashed = {
                k: (digest(Path(v)) if k in files and v is not None else v) for k, v in settings.items()
            }
            text = json.dumps(settings, sort_keys=True, default=str)
            if text not in prints:
                prints[text] = fingerprint(settings, digest, files)
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
            where = f"{self.source}: actuator {act.id!r}"
            head = key_head(self.name, act.id)
            tail = key_tail(hashed)
            map_sha = None if act.channel_map is None else digest(act.channel_map)
            usages = flight_usages(act.usage, [f for f, _, _ in flights], where)
            for (flight, truth, ref), usage in zip(flights, usages, strict=True):
                ref_sha = None if ref is None else digest(ref)
                truth_json = truth_text(truth)
                for seed in self.seeds:
                    content_text = key_text(head, flight, map_sha, ref_sha, seed, tail, truth_json)
                    out.append(
                        Job(
                            campaign=self.name, actuator=act.id, flight=flight, seed=seed,
                            identify_seed=history_seed(seed, flight) if act.kind == "history" else seed,
                            truth=truth, reference=None if ref is None else str(ref),
                            reference_sha256=ref_sha, channel_map=cmap,
                            settings=settings, key=hashlib.sha256(content_text.encode()).hexdigest()[:20],
                            fingerprint=prints[text], usage=usage,
                        )
                    )  # fmt: skip
        return out


def _fail(where: str, message: str) -> InputError:
    return InputError(f"{where}: {message}")


def load_campaign(path: str | os.PathLike[str]) -> CampaignSpec:
    """Read and validate a campaign file; `InputError` (one line, naming the key) for any mistake.

    Parameters
    ----------
    path : str or path
        The campaign file (TOML; docs/campaigns.md).
    """
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
    settings = parse_identify(data.get("identify", {}), folder, where)
    raw, fleets = data.get("actuator", []), data.get("fleet", [])
    if not isinstance(raw, list) or not isinstance(fleets, list) or not (raw or fleets):
        raise _fail(where, "no [[actuator]] or [[fleet]]: a campaign needs at least one actuator")
    actuators = tuple(parse_actuator(a, i, folder, where) for i, a in enumerate(raw)) + tuple(
        a for i, f in enumerate(fleets) for a in parse_fleet(f, i, folder, where)
    )
    ids = [a.id for a in actuators]
    twice = sorted(i for i, n in collections.Counter(ids).items() if n > 1)  # linear in the fleet (review M4)
    if twice:
        raise _fail(where, f"actuator id(s) given twice: {', '.join(twice)}")
    return CampaignSpec(name, tuple(seeds), settings, actuators, where, description)
