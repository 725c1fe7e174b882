"""Running a campaign: the missing jobs only, on Dask (or in this process), into the results store.

Backends (next-features §C):

- **Dask** (``pip install 'emaphm[cluster]'``): an existing cluster by address (``scheduler=``
  or ``DASK_SCHEDULER_ADDRESS``), or a `LocalCluster` of `workers` processes (default: one per
  core) with one thread each. Dask sets OMP_NUM_THREADS=1 in its workers, but numba ignores it:
  ``NUMBA_NUM_THREADS=1`` is set before the workers spawn, and each job runs on one numba thread
  (`jobs.run_job`), so workers × threads never exceed the cores.
- **serial**: the jobs one after the other in this process (``scheduler="serial"``, or one
  worker and no address): no Dask needed.

Only the jobs whose key is not in the store are submitted, so a rerun after any interruption
(Ctrl-C, ``kill -9``, a dead worker) completes the campaign with every job exactly once. Rows are
written by this process (workers need no shared file system) in batches, every `flush_rows`
rows or `flush_seconds`, each batch atomically (`store.ResultStore.write`); an interruption
loses at most the unflushed rows, which the rerun recomputes. A job that raises (or whose worker
dies, `KilledWorker`) is written to ``failures`` and the campaign goes on; the rerun tries it again.
At the end the store's part files are compacted (`store.ResultStore.compact`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

from .._threads import usable_cores
from ..errors import InputError
from .cluster import run_dask
from .jobs import failure_line, failure_row, run_job
from .spec import CampaignSpec, load_campaign
from .store import ResultStore

__all__ = ["CampaignSummary", "run_campaign"]

Progress = Callable[[int, int, int, float], None]  # done, failed, to do, elapsed [s]


@dataclass(frozen=True)
class CampaignSummary:
    """What a run did: `campaign` (its name), `jobs` (in the spec), `already_done` (in the store
    before, made by this code and data), `stale` (stored rows made by other code, data or settings:
    redone, or kept when `kept_stale`), `submitted`, `done`, `failed` (this run's) and `failures`
    (a line each, `jobs.failure_line`), `wall_time_s` and `startup_s` (the wall time, and the
    cluster's start and warm-up before the first job [s]), `backend` and `workers` (how many at once),
    `baselines` (made by this run, `baselines`) and `waiting` (actuators whose baseline is not made:
    their identifications wait)."""

    campaign: str
    jobs: int
    already_done: int
    submitted: int
    done: int
    failed: int
    wall_time_s: float
    backend: str
    workers: int
    startup_s: float = 0.0
    stale: int = 0
    kept_stale: bool = False
    failures: tuple[str, ...] = ()
    baselines: int = 0
    waiting: tuple[str, ...] = ()

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def _spec(spec: CampaignSpec | str | os.PathLike[str]) -> CampaignSpec:
    return spec if isinstance(spec, CampaignSpec) else load_campaign(spec)


def run_campaign(
    spec: CampaignSpec | str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Progress | None = None,
    flush_rows: int = 20,
    flush_seconds: float = 10.0,
    keep_stale: bool = False,
) -> CampaignSummary:
    """Run the jobs of `spec` (a `CampaignSpec` or its file) that the results store `out` (a directory)
    does not hold yet (module docstring). `scheduler`: a Dask scheduler's address or "serial" (None:
    ``DASK_SCHEDULER_ADDRESS``, else a local cluster of `workers` processes, one per core if None);
    `progress` (done, failed, to_do, elapsed_s); rows are written each `flush_rows` or `flush_seconds` [s].
    A stored row made by other code, data or settings (its fingerprint, `fingerprint`) is redone,
    or kept with `keep_stale`; the latest row of a job is the one read."""
    spec = _spec(spec)
    store = ResultStore(out)
    jobs = spec.jobs(out)  # reads every file it names: a missing one is refused before the work
    address, cores, serial = _backend(scheduler, workers)
    store.remove_temporaries()
    baselined = make_baselines(spec, out, store, address, workers or cores, serial, progress)
    if baselined["made"]:
        jobs = spec.jobs(out)  # the actuators whose baseline this run made have their jobs now
    store.write_usage(spec.name, [{"campaign": spec.name, "actuator": j.actuator, "flight": j.flight, **j.usage}
                                  for j in jobs if j.usage and j.seed == spec.seeds[0]])  # fmt: skip
    stored = store.fingerprints(spec.name)
    stale = sum(1 for j in jobs if j.key in stored and stored[j.key] != j.fingerprint)
    todo = [j for j in jobs if j.key not in stored or (stored[j.key] != j.fingerprint and not keep_stale)]
    start = time.perf_counter()
    collector = _Collector(store, len(todo), progress, flush_rows, flush_seconds, start)
    n_workers = 1
    backend = "serial"
    ready = {"at": start}
    try:
        if progress is not None:
            progress(0, 0, len(todo), 0.0)
        if todo and serial:
            _run_serial(todo, collector.finished)
        elif todo:
            backend, n_workers = run_dask(todo, address, workers or cores, collector.finished, ready)
    finally:
        collector.flush(force=True)
    store.compact()  # many small part files into one per campaign: a fleet's reads take seconds, not minutes
    return CampaignSummary(
        campaign=spec.name, jobs=len(jobs), already_done=len(jobs) - len(todo), submitted=len(todo), stale=stale,
        kept_stale=keep_stale,
        done=collector.done, failed=collector.failed + baselined["failed"],
        failures=tuple(baselined["lines"]) + tuple(collector.lines),
        wall_time_s=round(time.perf_counter() - start, 3),
        backend=backend, workers=n_workers, startup_s=round(ready["at"] - start, 3),
        baselines=baselined["made"], waiting=tuple(baselined["waiting"]),
    )  # fmt: skip


def _backend(scheduler: str | None, workers: int | None) -> tuple[str | None, int, bool]:
    """The scheduler's address (None: a local cluster), this machine's cores, and whether the
    jobs run in this process; `InputError` for a worker count the machine lacks, or no Dask."""
    address = scheduler if scheduler is not None else os.environ.get("DASK_SCHEDULER_ADDRESS") or None
    cores = usable_cores()
    if workers is not None and not 1 <= workers <= cores and address is None:
        raise InputError(
            f"--workers must be 1..{cores} on this machine (one numba thread each), got {workers}"
        )
    serial = address == "serial" or (address is None and workers == 1)
    if not serial and address is None:
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise InputError(
                "campaigns on several cores run on Dask: pip install 'emaphm[cluster]' (or --workers 1)"
            ) from None
    return address, cores, serial


class _Collector:
    """The rows and failures of a run, written to the store in batches (every `flush_rows` rows or
    `flush_seconds`), counted, with the progress callback after each job."""

    def __init__(
        self,
        store: ResultStore,
        todo: int,
        progress: Progress | None,
        flush_rows: int,
        flush_seconds: float,
        start: float,
    ) -> None:
        self.store, self.todo, self.progress, self.start = store, todo, progress, start
        self.flush_rows, self.flush_seconds = flush_rows, flush_seconds
        self.rows: list[dict[str, Any]] = []
        self.failures: list[dict[str, Any]] = []
        self.done = 0
        self.failed = 0
        self.lines: list[str] = []
        self.last_flush = time.monotonic()

    def flush(self, force: bool = False) -> None:
        if (
            force
            or len(self.rows) + len(self.failures) >= self.flush_rows
            or time.monotonic() - self.last_flush >= self.flush_seconds
        ):
            # each buffer cleared right after its own write: a failed write of one never writes
            # the other twice (review M2)
            self.store.write("results", self.rows)
            self.rows = []
            self.store.write("failures", self.failures)
            self.failures, self.last_flush = [], time.monotonic()

    def finished(self, row: dict[str, Any] | None, failure: dict[str, Any] | None) -> None:
        if row is not None:
            self.rows.append(row)
            self.done += 1
        if failure is not None:
            self.failures.append(failure)
            self.failed += 1
            self.lines.append(failure_line(failure))
        self.flush()
        if self.progress is not None:
            self.progress(self.done, self.failed, self.todo, time.perf_counter() - self.start)


def _run_serial(todo: list[Any], finished: Callable[[Any, Any], None]) -> None:
    """The jobs one after the other in this process; a job that raises is a failure row."""
    for job in todo:
        payload = job.to_dict()
        try:
            row = run_job(payload)
        except Exception as exc:  # as on Dask: the job's error recorded, the campaign goes on (review L9)
            finished(None, failure_row(payload, exc))
        else:  # outside the try: a failed store write is not this job's failure (review M2)
            finished(row, None)


def make_baselines(
    spec: CampaignSpec,
    out: Any,
    store: ResultStore,
    address: str | None,
    workers: int,
    serial: bool,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Make the baselines of `spec` that the store lacks (`baselines`), each installed as it
    finishes (`progress` after each); a refused one is a failure row. How many were made and
    failed, a line per failure, and the actuators still waiting for theirs."""
    from .baselines import baseline_jobs, install, run_baseline

    todo = [b for b in baseline_jobs(spec, out) if not b.made()]
    counts: dict[str, Any] = {"made": 0, "failed": 0, "lines": [], "waiting": [b.actuator for b in todo]}
    start = time.perf_counter()

    def finished(made: dict[str, Any] | None, failure: dict[str, Any] | None) -> None:
        if made is not None:
            install(made)
            counts["made"] += 1
            counts["waiting"].remove(made["job"]["actuator"])
        if failure is not None:
            store.write("failures", [failure])
            counts["failed"] += 1
            counts["lines"].append("baseline of " + failure_line(failure))
        if progress is not None:
            progress(counts["made"], counts["failed"], len(todo), time.perf_counter() - start)

    if todo and serial:
        for job in todo:
            payload = job.to_dict()
            try:
                made = run_baseline(payload)
            except Exception as exc:  # a refused baseline is the actuator's failure, the campaign goes on
                finished(None, failure_row(payload, exc))
            else:
                finished(made, None)
    elif todo:
        run_dask(todo, address, workers, finished, {"at": 0.0}, task=run_baseline)
    return counts
