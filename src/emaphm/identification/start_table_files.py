"""Where start tables are kept (`start_table`): the folder, one file a table, its bound.

A table's file (`TABLE_SUFFIX`) holds four .npy arrays one after the other: its key, the box
points X, the grid samples' index and the currents T as float32; T is memory-mapped when read,
so a diagnosis reads only what its ranking passes over, from the page cache, with no conversion
(format 1 kept an .npz with T in float16, whose read, CRC check and conversion to float32 took
45-140 ms of every diagnosis's start on machine G; issue 36, thirteenth session). The folder is
kept within ``$EMAPHM_TABLE_CACHE_MB`` (`prune`, format 1's files among those counted).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["PRUNED", "TABLE_CACHE_MB", "TABLE_SUFFIX", "cache_limit", "prune", "read_table", "table_dir", "write_table"]

TABLE_SUFFIX = ".table"  # a table's file: <the key's first 32 hex digits>.table
# the table folder is kept under this many MiB (``$EMAPHM_TABLE_CACHE_MB``; 0: no bound): after a
# table is written, the least recently used ones go (`prune`, format 1's .npz files among them); a
# table gone is built again, the same. 2 GiB holds about 60 tables of the 1 s chirp (33 MB each:
# one per actuator type, calibration and command)
TABLE_CACHE_MB = 2048
PRUNED = ("*" + TABLE_SUFFIX, "*.npz")  # the files `prune` counts: this format's and format 1's


def table_dir() -> Path:
    """Where start tables are kept: ``$EMAPHM_TABLE_DIR``, else ``$XDG_CACHE_HOME/emaphm/start-tables``
    (``~/.cache/...``)."""
    given = os.environ.get("EMAPHM_TABLE_DIR")
    if given:
        return Path(given)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "emaphm" / "start-tables"


def read_table(path: Path, key: str) -> tuple[NDArray[np.float64], NDArray[np.float32], NDArray[np.intp]] | None:
    """The arrays (X, T, index) of the table kept at `path` if it is whole and its key is `key`
    (else None: built again). Its four arrays follow one another in the file (`write_table`); the
    currents T are memory-mapped, read from the page cache as the ranking passes over them."""
    from numpy.lib import format as npy

    try:
        with open(path, "rb") as f:
            if str(np.load(f, allow_pickle=False)) != key:
                return None
            X, index = np.load(f, allow_pickle=False), np.load(f, allow_pickle=False).astype(np.intp)
            version = npy.read_magic(f)
            read_header = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
            shape, fortran, dtype = read_header(f)
            offset = f.tell()
        if dtype != np.float32 or fortran or shape != (len(X), len(index)):
            return None
        T = np.memmap(path, dtype=np.float32, mode="r", offset=offset, shape=shape)
        os.utime(path)  # its use, for `prune`
        return X, T, index
    except (OSError, ValueError, KeyError):
        return None  # missing, half-copied or foreign: built again


def cache_limit() -> float:
    """The table folder's bound in bytes: ``$EMAPHM_TABLE_CACHE_MB`` MiB (default `TABLE_CACHE_MB`;
    0: none); a setting that is not a number of MiB >= 0 is refused in one line."""
    given = os.environ.get("EMAPHM_TABLE_CACHE_MB", str(TABLE_CACHE_MB))
    try:
        mib = float(given)
    except ValueError:
        mib = float("nan")
    if not mib >= 0 or mib == float("inf"):
        raise InputError(f"EMAPHM_TABLE_CACHE_MB must be a number of MiB (0: no bound), got {given!r}")
    return mib * 2**20


def prune(folder: Path, keep: Path | None = None) -> list[Path]:
    """Remove the least recently used tables (by modification time: written or read) until the
    folder's tables take at most `cache_limit` bytes (0: no bound), never `keep`; returns those
    removed."""
    limit = cache_limit()
    kept: list[tuple[float, int, Path]] = []
    for path in (p for pattern in PRUNED for p in folder.glob(pattern)):
        try:
            st = path.stat()
        except OSError:
            continue  # removed by another process meanwhile
        kept.append((st.st_mtime, st.st_size, path))
    total, removed = sum(size for _, size, _ in kept), []
    for _, size, path in sorted(kept):  # the oldest first
        if limit <= 0 or total <= limit:
            break
        if path == keep:
            continue
        try:
            path.unlink()
        except OSError:
            continue
        total -= size
        removed.append(path)
    return removed


def write_table(path: Path, key: str, X: NDArray[np.float64], index: NDArray[np.intp], T: NDArray[np.float32]) -> None:
    """Keep a table at `path`, written atomically, then the folder pruned (`prune`); a folder that
    cannot be written leaves it to the process (no error)."""
    from ..atomic import atomic_path

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp, open(tmp, "wb") as f:  # `read_table` reads them in this order
            for array in (np.array(key), X, index, np.ascontiguousarray(T, dtype=np.float32)):
                np.save(f, array, allow_pickle=False)
        prune(path.parent, keep=path)
    except OSError:
        pass  # a folder that cannot be written: the table lives in this process only
