"""A fleet's baselines, made by the campaign (issue 33): an ``[[actuator]]`` with ``healthy`` recordings.

```toml
[[actuator]]
id = "A7"
healthy = ["rig/a7-h1.csv", "rig/a7-h2.csv", "rig/a7-h3.csv"]   # A7 new or just overhauled
map = "rig/rig.toml"                                             # reads these and its references
references = ["rig/a7-f1.csv", "rig/a7-f2.csv"]
```

Before its identifications, ``campaign run`` makes each such actuator's baseline (`emaphm.baseline`,
as ``emaphm baseline HEALTHY... --map MAP --output DIR`` would, with the campaign's ``params`` and
files as the nameplate) into ``OUT/baselines/<campaign>/<actuator>/``, one job per actuator on the
same backend as the identifications (Dask or serial); the actuator's jobs then identify with it
(``baseline = DIR``, its files' digests in their keys). A baseline is made again only when its
key moves: the recordings' and the map's SHA-256, the nameplate's files and the code
(`fingerprint.code_hash`), recorded in the folder's ``campaign.json``. A baseline that is refused
(recordings not of one healthy actuator) is a failure row with its reason, and the actuator's
identifications wait for it (`campaign status` counts them).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from ..atomic import replace_folder
from ..io import sha256_of
from .fingerprint import code_hash

__all__ = ["BaselineJob", "baseline_folder", "baseline_jobs", "install", "run_baseline"]

NAMEPLATE = ("params", "calibration", "uq_calibration")  # the [identify] files a baseline starts from
RECORD = "campaign.json"  # in the folder: the key it was made for


def baseline_folder(out: str | os.PathLike[str], campaign: str, actuator: str) -> Path:
    """Where the campaign's store `out` keeps an actuator's baseline."""
    return Path(out) / "baselines" / campaign / actuator


@dataclass(frozen=True)
class BaselineJob:
    """One actuator's baseline to make (plain data for a worker: `to_dict`)."""

    campaign: str
    actuator: str
    recordings: tuple[str, ...]
    channel_map: str | None
    nameplate: dict[str, str | None]
    folder: str
    key: str
    flight: int = 0  # for a failure row (`jobs.failure_row`)
    seed: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "recordings": list(self.recordings)}

    def made(self) -> bool:
        """Whether its folder holds a baseline made for this key."""
        try:
            return json.loads((Path(self.folder) / RECORD).read_text())["key"] == self.key
        except (OSError, ValueError, KeyError):
            return False


def baseline_jobs(spec: Any, out: str | os.PathLike[str]) -> list[BaselineJob]:
    """The baselines of `spec`'s actuators that have ``healthy`` recordings (module docstring)."""
    out_jobs = []
    for act in spec.actuators:
        if not act.healthy:
            continue
        settings = {**spec.settings, **act.overrides}
        nameplate = {k: settings.get(k) for k in NAMEPLATE}
        content = {
            "campaign": spec.name, "actuator": act.id, "healthy": [sha256_of(p) for p in act.healthy],
            "map": None if act.channel_map is None else sha256_of(act.channel_map),
            "nameplate": {k: None if v is None else sha256_of(Path(v)) for k, v in nameplate.items()},
            "code": code_hash(),
        }  # fmt: skip
        key = hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:20]
        out_jobs.append(BaselineJob(
            spec.name, act.id, tuple(str(p) for p in act.healthy),
            None if act.channel_map is None else str(act.channel_map), nameplate,
            str(baseline_folder(out, spec.name, act.id)), f"baseline-{key}",
        ))  # fmt: skip
    return out_jobs


def run_baseline(job: dict[str, Any]) -> dict[str, Any]:
    """Make one baseline where the job runs (a Dask worker or this process) and return its folder's
    files as bytes (`install` writes them where the store is: workers need no shared folder)."""
    from ..baseline import baseline

    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="emaphm-baseline-") as tmp:
        folder = Path(tmp) / "b"
        nameplate = job["nameplate"]
        baseline(job["recordings"], folder, channel_map=job["channel_map"], params=nameplate["params"],
                 calibration=nameplate["calibration"], uq_calibration=nameplate["uq_calibration"])  # fmt: skip
        files = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}
    return {"job": job, "files": files, "wall_time_s": round(time.perf_counter() - start, 3)}


def install(made: dict[str, Any]) -> Path:
    """Write a made baseline (`run_baseline`'s result) into its folder, replacing an older one whole."""
    job = made["job"]
    folder = Path(job["folder"])
    folder.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}-"))
    try:
        for name, data in made["files"].items():
            (tmp / name).write_bytes(data)
        (tmp / RECORD).write_text(json.dumps({"key": job["key"], "campaign": job["campaign"],
                                              "actuator": job["actuator"], "recordings": job["recordings"],
                                              "wall_time_s": made["wall_time_s"]}, indent=2) + "\n")  # fmt: skip
        replace_folder(tmp, folder)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return folder
