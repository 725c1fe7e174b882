"""The store's part files (`store`): one written whole or not at all, and the latest row per job."""

from __future__ import annotations

import os
import uuid
from pathlib import Path
from typing import Any

__all__ = ["latest_per_job", "write_file"]


def latest_per_job(table: Any) -> Any:
    """One row per job key: the one finished last (a job redone for another fingerprint, or a row
    written twice by a retried flush, is read once: review M2, H1)."""
    import pyarrow.compute as pc

    if pc.count_distinct(table.column("job_key")).as_py() == table.num_rows:
        return table
    keys, finished = table.column("job_key").to_pylist(), table.column("finished").to_pylist()
    latest: dict[str, int] = {}
    for i, (key, when) in enumerate(zip(keys, finished, strict=True)):
        j = latest.get(key)
        if j is None or (when or "") >= (finished[j] or ""):
            latest[key] = i
    if len(latest) == len(keys):
        return table
    return table.take(sorted(latest.values()))


def write_file(folder: Path, table: Any, name: str | None = None) -> Path:
    """Write `table` as the file `name` in `folder` (made if new; default a new part file's name),
    whole under a hidden temporary name, flushed to disk, then renamed into place (replacing one of
    that name)."""
    import pyarrow.parquet as pq

    folder.mkdir(parents=True, exist_ok=True)
    name = name or f"part-{uuid.uuid4().hex}.parquet"
    tmp = folder / f".{name}.tmp"
    try:
        with tmp.open("wb") as fh:
            pq.write_table(table, fh, row_group_size=8192)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, folder / name)
    finally:
        tmp.unlink(missing_ok=True)
    return folder / name
