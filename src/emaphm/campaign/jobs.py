"""One campaign job: an identification, run anywhere (a Dask worker or this process) from plain data.

`run_job` is a top-level function of plain dicts in and out, so that Dask pickles it by reference
and ships no numba object (next-features §C.1). It runs exactly what ``emaphm identify`` runs
with the job's seed, on one numba thread: the campaign's parallelism is one job per core.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import socket
import traceback
from typing import Any

from .._version import __version__

__all__ = ["identify_kwargs", "run_job"]

K = [f"k{i}" for i in range(1, 9)]


def identify_kwargs(job: dict[str, Any], *, workers: int | None = 1) -> dict[str, Any]:
    """The `emaphm.identify` arguments of a job (`spec.Job.to_dict`)."""
    settings = dict(job["settings"])
    kwargs: dict[str, Any] = {"seed": job["identify_seed"], "workers": workers}
    kwargs.update(settings)
    if job["truth"] is not None:
        kwargs["true_faults"] = job["truth"]
    else:
        kwargs["reference"] = job["reference"]
        kwargs["channel_map"] = job["channel_map"]
    return kwargs


def _worker() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def _pool() -> int:
    """The size of this process's numba thread pool."""
    import numba

    return int(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="microseconds")  # orders a redone job's rows


def run_job(job: dict[str, Any]) -> dict[str, Any]:
    """Run one job and return its results row (`store.RESULT_COLUMNS` plus campaign and actuator).

    Parameters
    ----------
    job : dict
        One job in `Job.to_dict` form (plain data, so that any worker can run it).
    """
    from ..identification.api import identify
    from ..identification.result import stage_record

    result = identify(**identify_kwargs(job))
    data = result.to_json()
    row: dict[str, Any] = {
        "job_key": job["key"], "campaign": job["campaign"], "actuator": job["actuator"],
        "flight": job["flight"], "seed": job["seed"], "identify_seed": job["identify_seed"],
        "uq_method": data["uq_method"], "uq_flags": None if data["uq_flags"] is None else json.dumps(data["uq_flags"]),
        "corr": None if data.get("corr") is None else json.dumps(data["corr"]),
        "verdict": data["verdict"], "detected": ",".join(data["detected"]),
        "fault_verdicts": None if data["fault_verdicts"] is None else json.dumps(data["fault_verdicts"]),
        "fit_nrmse": data["fit_nrmse"], "fitness": data["fitness"], "evaluations": data["evaluations"],
        "wall_time_s": data["wall_time_s"], "reference": job["reference"],
        "second_search": json.dumps(second) if (second := stage_record(data["settings"].get("stages", []), "second_search") or {}).get("ran") else None,
        "reference_sha256": job["reference_sha256"], "settings": json.dumps(job["settings"], sort_keys=True),
        "warnings": json.dumps(data["warnings"]), "doubts": json.dumps(data["doubts"]), "worker": _worker(), "finished": _now(), "version": __version__,
        "fingerprint": job.get("fingerprint") or None,
        "numba_threads": _pool(),
    }  # fmt: skip
    for j, k in enumerate(K):
        row[k] = data["estimate"][j]
        row[f"true_{k}"] = None if data["truth"] is None else data["truth"][j]
        for field in ("std", "ci90_low", "ci90_high"):
            row[f"{field}_{k}"] = None if data[field] is None else data[field][j]
    return row


def failure_row(
    job: dict[str, Any], error: BaseException | str, message: str | None = None
) -> dict[str, Any]:
    """The failures row of a job that raised `error` (or whose worker died: a name and a message)."""
    name = error if isinstance(error, str) else type(error).__name__
    text = message if message is not None else " ".join(str(error).split())[:2000]
    trace = None if isinstance(error, str) else "".join(traceback.format_exception(error))[-20000:]
    return {
        "job_key": job["key"], "campaign": job["campaign"], "actuator": job["actuator"], "flight": job["flight"],
        "seed": job["seed"], "error": name, "message": text, "traceback": trace, "worker": _worker(),
        "finished": _now(), "version": __version__,
    }  # fmt: skip


def failure_line(row: dict[str, Any]) -> str:
    """One line for a failures row: which job, and its error (the traceback stays in the store)."""
    message = row["message"] if len(row["message"]) <= 200 else row["message"][:199] + "…"
    return f"actuator {row['actuator']} flight {row['flight']} seed {row['seed']}: {row['error']}: {message}"
