"""The campaign's jobs on Dask: a local cluster of one-thread workers, or a running scheduler.

`run_dask` submits every job, collects each result or failure as it finishes and hands it to
`finished` (`runner._Collector.finished`); the cluster's workers are warmed up first (`warm_up`)
and must each run one job at a time (`checked_workers`, review M3).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

from ..errors import InputError
from .jobs import failure_row, run_job

__all__ = ["run_dask", "warm_up"]


def warm_up() -> None:
    """Load (or compile) every kernel once here, before workers start: concurrent first
    compilations of a cached numba function race (numba #10128). On a worker, its log of a failed
    task (the whole traceback, over the user's progress) is silenced: the store keeps it."""
    import logging

    from ..faults import HEALTHY

    logging.getLogger("distributed.worker").setLevel(logging.CRITICAL)
    from ..identification.api import identify

    identify(true_faults=HEALTHY, seed=0, pop_size=4, generations=1, polish=False, uncertainty="none",
             workers=1)  # fmt: skip



def run_dask(
    todo: list[Any],
    address: str | None,
    workers: int,
    finished: Callable[[Any, Any], None],
    ready: dict[str, float],
    task: Callable[[dict[str, Any]], Any] = run_job,
) -> tuple[str, int]:
    """Run `task` (`jobs.run_job`, or `baselines.run_baseline`) on each job of `todo` on Dask and
    hand each result, or its failure row, to `finished`; the backend's name and its workers."""
    import dask
    from distributed import Client, LocalCluster, as_completed

    cluster = None
    environ = dict(os.environ)  # Dask's nannies write their pre-spawn variables into ours: put back
    if address is None:
        warm_up()
        # one numba thread per worker (numba ignores the OMP_NUM_THREADS=1 Dask sets), and no
        # statistical profiler: it samples every task thread every 10 ms, which slowed
        # identifications by 11 % on 2 cores (BENCHMARKS.md, "Fleet campaigns")
        with dask.config.set({
            "distributed.nanny.pre-spawn-environ.NUMBA_NUM_THREADS": "1",
            "distributed.worker.profile.enabled": False,
            # the event loop's housekeeping wakes less often (it takes the GIL from the job)
            "distributed.admin.tick.interval": "500ms",
            "distributed.admin.system-monitor.interval": "2s",
            "distributed.worker.memory.monitor-interval": "1s",
        }):  # fmt: skip
            cluster = LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
            )
        client = Client(cluster)
        backend = f"dask LocalCluster ({workers} workers x 1 thread)"
    else:
        try:
            client = Client(address, timeout="10s")
        except OSError as exc:
            raise InputError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
        workers = checked_workers(client, address)
        backend = f"dask scheduler {address} ({workers} workers)"
    if cluster is not None:
        try:
            client.wait_for_workers(workers)
        finally:
            # the nannies set NUMBA_NUM_THREADS=1 (and OMP_*, PYTHONHASHSEED) in this process's
            # environment to pass them to the workers; left there, numba's next compile here
            # re-reads it and fails against the thread pool it launched with another count
            restore_environ(environ)
    # each worker imports emaphm and loads the compiled kernels before the first job (2-3 s a
    # process), so that jobs are timed and balanced on warm workers
    client.run(warm_up)
    ready["at"] = time.perf_counter()
    try:
        payloads = {job.key: job.to_dict() for job in todo}
        futures = [
            client.submit(task, payload, key=f"emaphm-{key}", pure=False)
            for key, payload in payloads.items()
        ]
        for future in as_completed(futures):
            payload = payloads[str(future.key).removeprefix("emaphm-")]
            try:
                row = future.result()
            except Exception as exc:  # the job's own error, or KilledWorker: recorded, the campaign goes on
                finished(None, failure_row(payload, exc))
            else:
                finished(row, None)
    except BaseException:
        client.cancel(futures) if "futures" in locals() else None
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
        restore_environ(environ)
    return backend, workers


def checked_workers(client: Any, address: str) -> int:
    """The workers of a running cluster, each of which must run one job at a time (two jobs in one
    process call numba's parallel kernels at once: review M3); `InputError` otherwise."""
    threads = [int(w.get("nthreads", 1)) for w in client.scheduler_info().get("workers", {}).values()]
    if any(n > 1 for n in threads):
        client.close()
        raise InputError(
            f"the Dask workers at {address} run {max(threads)} threads each; emaphm needs one job per worker "
            f"process: start them with 'NUMBA_NUM_THREADS=1 dask worker {address} --nthreads 1 --nworkers N'"
        )
    return max(1, len(threads))


def restore_environ(saved: dict[str, str]) -> None:
    """Make `os.environ` what it was (`saved`)."""
    for key in set(os.environ) - set(saved):
        del os.environ[key]
    for key, value in saved.items():
        if os.environ.get(key) != value:
            os.environ[key] = value
