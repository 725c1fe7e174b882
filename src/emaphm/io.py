"""Reading and writing traces (DESIGN §8): HDF5 (``.h5``/``.hdf5``) or CSV with a JSON side file.

HDF5: one float64 dataset per signal, named as the signal (SI units in each dataset's ``unit``
attribute); the metadata as root attributes, scalars as they are and nested values
(parameters, command) as JSON strings.

CSV: one column per signal with a header row of the names; the metadata, with the units, in
``FILE.json`` beside it (``out.csv`` → ``out.csv.json``).

Writes are atomic (`emaphm.atomic.atomic_path`, re-exported here): everything goes to temporary
files (``.NAME.emaphm-PID-XXXX.tmp`` beside the target) that replace the targets only once
complete, so a failure or Ctrl-C leaves nothing half-written. Ctrl-C during a write is held until
the write ends, then the temporary file is removed and the interruption goes on. Temporaries left
by a killed process (``kill -9``) are removed by the next write to the same target. Files are
created with the permissions the umask allows, like any other tool's.
"""

from __future__ import annotations

import hashlib
import json
import os
import tomllib
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .atomic import atomic_path
from .errors import InputError
from .results import REQUIRED_SIGNALS, UNITS, SimResult

__all__ = [
    "TRACE_SUFFIXES",
    "atomic_path",
    "check_output_path",
    "check_trace_path",
    "read_toml",
    "read_trace",
    "sha256_of",
    "side_file",
    "write_trace",
]

TRACE_SUFFIXES = (".h5", ".hdf5", ".csv")
# the rig formats the reader takes only with a channel map (`emaphm.measured`)
RECORDING_ONLY_SUFFIXES = (".parquet", ".pq", ".mat")


def side_file(path: Path) -> Path | None:
    """The JSON side file of a CSV trace (``out.csv`` → ``out.csv.json``), None for other files."""
    return path.with_name(path.name + ".json") if path.suffix.lower() == ".csv" else None


def check_output_path(
    path: str | os.PathLike[str],
    *,
    suffixes: Sequence[str],
    option: str = "--output",
    inputs: Sequence[str | os.PathLike[str] | None] = (),
) -> Path:
    """Validate an output path before any work: its suffix, a writable existing folder, not a
    folder itself, and not one of the `inputs` (or a CSV input's side file). `InputError` else.
    """
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise InputError(
            f"{option} {p}: unsupported file type {p.suffix or '(none)'!r}; use {' or '.join(suffixes)}"
        )
    targets = [p] + ([side] if (side := side_file(p)) is not None else [])
    for target in targets:
        if target.is_dir():
            raise InputError(f"{option} {p}: {target} is a folder")
    if not p.parent.is_dir():
        raise InputError(f"{option} {p}: folder {p.parent} does not exist")
    if not os.access(p.parent, os.W_OK | os.X_OK):
        raise InputError(f"{option} {p}: folder {p.parent} is not writable")
    for target in targets:
        if target.exists() and not os.access(target, os.W_OK):
            raise InputError(f"{option} {p}: {target} is not writable")
    for source in inputs:
        if source is None:
            continue
        src = Path(source)
        protected = [src] + ([side] if (side := side_file(src)) is not None else [])
        for target in targets:
            for q in protected:
                if _same_file(target, q):
                    raise InputError(f"{option} {p}: would overwrite the input {q}")
    return p


def _same_file(a: Path, b: Path) -> bool:
    try:
        if a.exists() and b.exists():
            return a.samefile(b)
    except OSError:
        pass
    return a.resolve() == b.resolve()


def check_trace_path(path: str | os.PathLike[str], *, for_writing: bool = True) -> Path:
    """Validate a trace path's extension; for writing as `check_output_path`, for reading that
    it is an existing file."""
    p = Path(path)
    if not for_writing and p.suffix.lower() in RECORDING_ONLY_SUFFIXES:
        raise InputError(
            f"{p}: a {p.suffix.lower()} recording is read through a channel map: give it with --map MAP "
            "(docs/your-actuator.md §3); a trace without one is an emaphm .h5 or .csv"
        )
    if p.suffix.lower() not in TRACE_SUFFIXES:
        raise InputError(f"{p}: unsupported file type {p.suffix or '(none)'!r}; use .h5 or .csv")
    if for_writing:
        check_output_path(p, suffixes=TRACE_SUFFIXES, option="output")
    elif p.is_dir():
        raise InputError(f"{p}: is a folder, not a trace file")
    elif not p.is_file():
        raise InputError(f"{p}: no such file")
    return p


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def write_trace(result: SimResult, path: str | os.PathLike[str]) -> Path:
    """Write `result` to `path` (format by extension); returns the path written."""
    p = check_trace_path(path)
    metadata = _jsonable(dict(result.metadata))
    if p.suffix.lower() == ".csv":
        names = result.names
        data = np.column_stack([result[n] for n in names])
        side = p.with_name(p.name + ".json")
        with atomic_path(p) as tmp_csv, atomic_path(side) as tmp_json:
            np.savetxt(tmp_csv, data, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
            units = {n: UNITS.get(n, "") for n in names}
            tmp_json.write_text(json.dumps({"metadata": metadata, "units": units}, indent=2))
        return p
    import h5py

    with atomic_path(p) as tmp, h5py.File(tmp, "w") as f:
        for name in result.names:
            ds = f.create_dataset(name, data=result[name])
            ds.attrs["unit"] = UNITS.get(name, "")
        for key, value in metadata.items():
            f.attrs[key] = json.dumps(value) if isinstance(value, (dict, list)) else value
    return p


def read_trace(path: str | os.PathLike[str]) -> SimResult:
    """Read a trace written by `write_trace` (or any file of the same schema).

    Raises `InputError` for a missing or unreadable file, missing required signals
    (t, theta_cmd, i_q; theta_u is optional), signals of unequal length, NaN/inf values or a time axis that
    is not strictly increasing.

    Parameters
    ----------
    path : str or path
        A ``.h5`` file, or a ``.csv`` file with its ``.json`` metadata beside it.
    """
    p = check_trace_path(path, for_writing=False)
    try:
        if p.suffix.lower() == ".csv":
            columns, metadata = _read_csv(p)
        else:
            columns, metadata = _read_h5(p)
    except InputError:
        raise
    except Exception as exc:  # corrupt file: say which and why, in one line
        raise InputError(f"{p}: cannot read trace ({type(exc).__name__}: {exc})".splitlines()[0]) from None
    missing = [n for n in REQUIRED_SIGNALS if n not in columns]
    if missing:
        raise InputError(f"{p}: missing signal(s) {', '.join(missing)}")
    n = len(columns["t"])
    for name, values in columns.items():
        if values.ndim != 1 or len(values) != n:
            raise InputError(f"{p}: signal {name!r} has {values.size} values, t has {n}")
        if not np.all(np.isfinite(values)):
            raise InputError(f"{p}: signal {name!r} contains NaN or inf")
    if n < 2 or np.any(np.diff(columns["t"]) <= 0):
        raise InputError(f"{p}: time axis t must hold at least 2 strictly increasing samples")
    t = columns.pop("t")
    return SimResult(t=t, signals=columns, metadata=metadata)


def _read_csv(p: Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    with p.open() as fh:
        header = fh.readline().strip().lstrip("#").strip()
    if not header:
        raise InputError(f"{p}: the file is empty")
    names = [h.strip().strip('"').strip("'") for h in header.split(",")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpy's "input contained no data": said below, in one line
        data = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2)
    if data.size == 0:
        raise InputError(f"{p}: the file has a header but no data rows")
    if data.shape[1] != len(names):
        raise InputError(f"{p}: header names {len(names)} columns, rows have {data.shape[1]}")
    side = p.with_name(p.name + ".json")
    metadata = json.loads(side.read_text()).get("metadata", {}) if side.is_file() else {}
    return {n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)}, metadata


def _read_h5(p: Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    import h5py

    with h5py.File(p, "r") as f:
        columns = {
            name: np.asarray(f[name][()], dtype=np.float64) for name in f if isinstance(f[name], h5py.Dataset)
        }
        metadata: dict[str, Any] = {}
        for key, value in f.attrs.items():
            if isinstance(value, bytes):
                value = value.decode()
            if isinstance(value, str) and value[:1] in "[{":
                value = json.loads(value)
            elif isinstance(value, np.generic):
                value = value.item()
            metadata[key] = value
    return columns, metadata


# digests already taken in this process, by the file's identity and state (`sha256_of`)
_DIGESTS: dict[tuple[int, ...], str] = {}
_DIGESTS_KEPT = 4096


def _state(path: str | os.PathLike[str]) -> tuple[int, ...]:
    st = os.stat(path)
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def sha256_of(path: str | os.PathLike[str]) -> str:
    """The SHA-256 of a file (hex), read in 1 MiB blocks: the provenance of an input.

    Read once per process while the file stays as it was (device, inode, size, modification and
    change times): a campaign run keys its jobs and baselines from the same recordings several
    times (before and after making the baselines, and for its status), and a fleet's healthy
    recordings run to many megabytes."""
    state = _state(path)
    if state in _DIGESTS:
        return _DIGESTS[state]
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    if _state(path) == state:  # not written to while it was read
        if len(_DIGESTS) >= _DIGESTS_KEPT:
            _DIGESTS.clear()
        _DIGESTS[state] = digest.hexdigest()
    return digest.hexdigest()


def read_toml(path: str | os.PathLike[str], what: str) -> dict[str, Any]:
    """A TOML file's content; `InputError` naming `what` (e.g. "actuator file") when it is
    missing, unreadable or not TOML."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such {what}")
    try:
        return tomllib.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot read the {what} ({exc})".splitlines()[0]) from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: not a valid TOML file ({exc})".splitlines()[0]) from None
