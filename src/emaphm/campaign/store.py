"""The results store of campaigns: a Parquet dataset that survives any interruption (issue 11).

Layout under the output folder::

    results/campaign=<name>/actuator=<id>/part-<uuid>.parquet     one row per finished job
    failures/campaign=<name>/actuator=<id>/part-<uuid>.parquet    one row per failed attempt

and, after `ResultStore.compact` (the end of each ``campaign run``), the rows of many part files
merged into one, sorted by actuator, with ``campaign`` and ``actuator`` as columns::

    compact/<kind>/campaign=<name>/part-<uuid>.parquet

(a store of 10 000 actuators is otherwise 10 000 folders, which take seconds to list and open).

Every part file is written whole to ``.part-<uuid>.parquet.tmp`` in its folder, flushed to disk
and renamed into place (`os.replace`, atomic on one file system): a reader sees a complete file
or none, and dataset discovery skips names that start with ``.``. A process killed mid-write
(``kill -9``) leaves at most a temporary file, which the next run removes. Partition values are
read back as strings (an explicit schema: pyarrow would read an actuator ``007`` as the
integer 7).

Columns of ``results`` (`RESULT_COLUMNS`): the job's key and coordinates, the estimate
``k1``..``k8``, the truth ``true_k1``..``true_k8`` (null when not known), the uncertainty
(``std_k*``, ``ci90_low_k*``, ``ci90_high_k*``, ``uq_flags`` and the 8 x 8 ``corr`` as JSON; null when not
computed), the verdict and the
detected faults, ``fit_nrmse``, ``fitness``, ``evaluations``, ``wall_time_s``, the second search
a poor fit started (``second_search``: its record as JSON, null when none ran), the reference, the
settings (JSON), the worker, the size of its numba thread pool (``numba_threads``: 1 on a
campaign's workers, so that workers × threads stay within the cores) and the ``version``.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..errors import InputError
from .part_files import latest_per_job, write_file

__all__ = ["FAILURE_COLUMNS", "RESULT_COLUMNS", "ResultStore"]

K = [f"k{i}" for i in range(1, 9)]
RESULT_COLUMNS: dict[str, str] = {
    "job_key": "string", "flight": "int64", "seed": "int64", "identify_seed": "int64",
    **{k: "float64" for k in K}, **{f"true_{k}": "float64" for k in K},
    **{f"std_{k}": "float64" for k in K}, **{f"ci90_low_{k}": "float64" for k in K},
    **{f"ci90_high_{k}": "float64" for k in K},
    "uq_method": "string", "uq_flags": "string", "corr": "string", "verdict": "string", "detected": "string", "fault_verdicts": "string",
    "fit_nrmse": "float64", "fitness": "float64", "evaluations": "int64", "wall_time_s": "float64",
    "second_search": "string", "reference": "string", "reference_sha256": "string", "settings": "string", "warnings": "string",
    "worker": "string", "numba_threads": "int64", "finished": "string", "version": "string",
    "fingerprint": "string",  # what computed the row (`fingerprint`); null in stores made before it
    "doubts": "string",  # JSON: why the verdict is "doubtful" (none: []); null in stores made before it
}  # fmt: skip
FAILURE_COLUMNS: dict[str, str] = {
    "job_key": "string", "flight": "int64", "seed": "int64", "error": "string", "message": "string",
    "traceback": "string",  # the job's whole traceback (null in stores made before it)
    "worker": "string", "finished": "string", "version": "string",
}  # fmt: skip
USAGE_COLUMNS: dict[str, str] = {
    "campaign": "string", "actuator": "string", "flight": "int64", "hours": "float64", "cycles": "float64",
    "date": "string",
}  # fmt: skip
PARTITIONS = ("campaign", "actuator")
BATCH_ACTUATORS = 64  # a write of rows of this many actuators or more is one file (`ResultStore.write`)


def _pyarrow() -> Any:
    try:
        import pyarrow as pa
        import pyarrow.dataset as ds
        import pyarrow.parquet as pq
    except ImportError:
        raise InputError("campaigns store their results in Parquet: pip install 'emaphm[cluster]'") from None
    return pa, ds, pq


class ResultStore:
    """The ``results`` and ``failures`` datasets under `root` (created on the first write)."""

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)
        if self.root.exists() and not self.root.is_dir():
            raise InputError(f"{self.root}: exists and is not a folder")

    # -- writing ----------------------------------------------------------------------------

    def write(self, kind: str, rows: Sequence[dict[str, Any]]) -> list[Path]:
        """Append `rows` (each with ``campaign`` and ``actuator``) to ``kind`` ("results" or
        "failures"), each file written atomically: one part file per actuator, or, for rows of
        `BATCH_ACTUATORS` actuators or more of a campaign, one compacted file (`compact`'s layout)."""
        if not rows:
            return []
        pa, _, _ = _pyarrow()
        columns = RESULT_COLUMNS if kind == "results" else FAILURE_COLUMNS
        schema = pa.schema([(name, getattr(pa, dtype)()) for name, dtype in columns.items()])
        groups: dict[str, dict[str, list[dict[str, Any]]]] = {}
        for row in rows:
            groups.setdefault(row["campaign"], {}).setdefault(row["actuator"], []).append(row)
        written = []
        for campaign, actuators in groups.items():
            if len(actuators) >= BATCH_ACTUATORS:  # a fleet's rows at once: one file, not thousands
                wide = pa.schema([*schema, *((p, pa.string()) for p in PARTITIONS)])
                ordered = [{c: r.get(c) for c in wide.names} for a in sorted(actuators) for r in actuators[a]]
                folder = self.root / "compact" / kind / f"campaign={campaign}"
                written.append(write_file(folder, pa.Table.from_pylist(ordered, schema=wide)))
                continue
            for actuator, group in actuators.items():
                folder = self.root / kind / f"campaign={campaign}" / f"actuator={actuator}"
                table = pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in group], schema=schema)
                written.append(write_file(folder, table))
        return written

    def write_usage(self, campaign: str, rows: Sequence[dict[str, Any]]) -> Path | None:
        """Replace the usage of `campaign`'s flights (`USAGE_COLUMNS`, `campaign.usage`) by `rows`,
        atomically; none written (and an old one removed) when `rows` is empty."""
        pa, _, _ = _pyarrow()
        target = self.root / "usage" / f"campaign={campaign}" / "usage.parquet"
        if not rows:
            target.unlink(missing_ok=True)
            return None
        schema = pa.schema([(n, getattr(pa, t)()) for n, t in USAGE_COLUMNS.items()])
        table = pa.Table.from_pylist([{c: r.get(c) for c in USAGE_COLUMNS} for r in rows], schema=schema)
        return write_file(target.parent, table, target.name)

    def read_usage(self, campaign: str | None = None) -> Any:
        """The usage of the flights of every campaign (or one) as a pyarrow Table (empty: none given)."""
        pa, _, pq = _pyarrow()
        files = sorted((self.root / "usage").glob(f"campaign={campaign or '*'}/usage.parquet"))
        schema = pa.schema([(n, getattr(pa, t)()) for n, t in USAGE_COLUMNS.items()])
        try:
            tables = [pq.read_table(f, schema=schema) for f in files]
        except (pa.ArrowInvalid, OSError) as exc:
            raise InputError(
                f"{self.root / 'usage'}: a usage file cannot be read ({exc})".splitlines()[0]
            ) from None
        return pa.concat_tables(tables) if tables else schema.empty_table()

    def loose_parts(self) -> int:
        """How many part files are not compacted (`compact`)."""
        return sum(1 for _ in self.root.glob("*/campaign=*/actuator=*/part-*.parquet"))

    def compact(self, min_files: int = 64, batch: int = 2000) -> int:
        """Merge each campaign's part files of both kinds, `batch` at a time, into compacted files,
        when there are at least `min_files` of them; the number of part files merged. Each merged
        file is written atomically before its sources are removed: an interruption between the two
        leaves rows twice, which the reader reads once (`part_files.latest_per_job`)."""
        merged = 0
        for kind in ("results", "failures"):
            for folder in sorted((self.root / kind).glob("campaign=*")):
                parts = sorted(folder.glob("actuator=*/part-*.parquet"))
                if len(parts) < min_files:
                    continue
                for i in range(0, len(parts), batch):  # the memory of `batch` files' rows at a time
                    self._merge(kind, folder.name, parts[i : i + batch])
                merged += len(parts)
        return merged

    def _merge(self, kind: str, campaign_folder: str, parts: list[Path]) -> None:
        """Write the rows of `parts` as one compacted file of ``kind``, then remove them."""
        table = self._dataset(kind, parts).to_table()
        write_file(self.root / "compact" / kind / campaign_folder, table.sort_by("actuator"))
        for part in parts:
            part.unlink(missing_ok=True)
            with contextlib.suppress(OSError):  # a folder a concurrent write still fills stays
                part.parent.rmdir()

    def remove_temporaries(self) -> int:
        """Delete the temporary files a killed run left behind; their number."""
        removed = 0
        for tmp in [*self.root.glob("*/campaign=*/actuator=*/.part-*.parquet.tmp"),
                    *self.root.glob("compact/*/campaign=*/.part-*.parquet.tmp")]:  # fmt: skip
            tmp.unlink(missing_ok=True)
            removed += 1
        return removed

    # -- reading ----------------------------------------------------------------------------

    def _dataset(self, kind: str, files: list[Path] | None = None) -> Any:
        """The ``kind`` rows as one pyarrow dataset (None: nothing written): the partitioned part
        files and the compacted ones, or only the partitioned `files`; every column of the full
        schema (a part file written before a column existed reads with nulls there)."""
        pa, ds, _ = _pyarrow()
        base = RESULT_COLUMNS if kind == "results" else FAILURE_COLUMNS
        schema = pa.schema(
            [(n, getattr(pa, t)()) for n, t in base.items()] + [(p, pa.string()) for p in PARTITIONS]
        )
        partitioning = ds.partitioning(pa.schema([(p, pa.string()) for p in PARTITIONS]), flavor="hive")
        folder, compacted = self.root / kind, self.root / "compact" / kind
        if files is not None:
            return ds.dataset([str(f) for f in files], format="parquet", partitioning=partitioning,
                              partition_base_dir=str(folder), schema=schema)  # fmt: skip
        sources = []
        if folder.is_dir():
            sources.append(ds.dataset(folder, format="parquet", partitioning=partitioning, schema=schema))
        if compacted.is_dir():
            sources.append(ds.dataset(compacted, format="parquet", schema=schema))
        return None if not sources else sources[0] if len(sources) == 1 else ds.dataset(sources)

    def read(
        self,
        kind: str = "results",
        campaign: str | None = None,
        columns: Iterable[str] | None = None,
        actuator: str | None = None,
        actuators: Sequence[str] | None = None,
    ) -> Any:
        """The ``kind`` dataset as a pyarrow Table (empty if nothing was written), optionally of
        one campaign (and `actuator`, or `actuators`) and some columns; one row per job key for
        results (its latest); `InputError` naming a part file that cannot be read."""
        pa, ds, _ = _pyarrow()
        base = RESULT_COLUMNS if kind == "results" else FAILURE_COLUMNS
        names = list(columns) if columns is not None else [*PARTITIONS, *base]
        extra = [n for n in ("job_key", "finished") if n not in names]  # what the latest row per job needs
        try:
            data = self._dataset(kind)
            if data is None:
                types = {**base, "campaign": "string", "actuator": "string"}
                return pa.table({n: pa.array([], type=getattr(pa, types[n])()) for n in names})
            filt = None  # the partitions asked for are the only ones read (review L5)
            for name, value in (("campaign", campaign), ("actuator", actuator)):
                if value is not None:
                    term = ds.field(name) == value
                    filt = term if filt is None else filt & term
            if actuators is not None:  # partitions pruned: only these actuators' folders are read
                term = ds.field("actuator").isin(list(actuators))
                filt = term if filt is None else filt & term
            table = data.to_table(columns=[*names, *extra], filter=filt)
        except (pa.ArrowInvalid, OSError) as exc:
            raise InputError(
                f"{self.root / kind}: a part file cannot be read ({exc})".splitlines()[0]
            ) from None
        return latest_per_job(table).drop_columns(extra) if kind == "results" else table.drop_columns(extra)

    def actuators(self, campaign: str | None = None) -> list[str]:
        """The ids of the actuators with results (of `campaign`), sorted: their folders' names and
        the compacted files' actuator column (no result row is read)."""
        pa, ds, _ = _pyarrow()
        import pyarrow.compute as pc

        ids = {
            d.name.removeprefix("actuator=")
            for d in (self.root / "results").glob(f"campaign={campaign or '*'}/actuator=*")
        }
        compacted = self.root / "compact" / "results"
        if compacted.is_dir():
            data = ds.dataset(
                compacted,
                format="parquet",
                schema=pa.schema([("campaign", pa.string()), ("actuator", pa.string())]),
            )
            filt = None if campaign is None else ds.field("campaign") == campaign
            ids.update(
                pc.unique(data.to_table(columns=["actuator"], filter=filt).column("actuator")).to_pylist()
            )
        return sorted(ids)

    def fingerprints(self, campaign: str | None = None) -> dict[str, str | None]:
        """The fingerprint of each stored job's latest result row (None: a row made before them)."""
        table = self.read("results", campaign, columns=["job_key", "fingerprint"])
        return dict(
            zip(table.column("job_key").to_pylist(), table.column("fingerprint").to_pylist(), strict=True)
        )

    def keys(self, kind: str = "results", campaign: str | None = None) -> set[str]:
        """The job keys stored in ``kind`` (of one campaign)."""
        table = self.read(kind, campaign, columns=["job_key"])
        return {str(k) for k in table.column("job_key").to_pylist()}
