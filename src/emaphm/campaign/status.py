"""`campaign_status`: what a results store holds of a campaign's jobs (``emaphm campaign status``)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from .spec import CampaignSpec, load_campaign
from .store import ResultStore

__all__ = ["campaign_status"]


def campaign_status(
    spec: CampaignSpec | str | os.PathLike[str], out: str | os.PathLike[str]
) -> dict[str, Any]:
    """Done, failed (and not done since) and missing jobs of `spec` in `out`, in all and per actuator;
    ``other_rows``: stored rows of this campaign that no job of `spec` has (an older file or version)."""
    spec = spec if isinstance(spec, CampaignSpec) else load_campaign(spec)
    store = ResultStore(out)
    jobs = spec.jobs(out)
    stored, failed_keys = store.fingerprints(spec.name), store.keys("failures", spec.name)
    done = set(stored)
    per: dict[str, dict[str, int]] = {}
    totals = {"jobs": len(jobs), "done": 0, "failed": 0, "missing": 0}
    for job in jobs:
        state = "done" if job.key in done else "failed" if job.key in failed_keys else "missing"
        entry = per.setdefault(job.actuator, {"jobs": 0, "done": 0, "failed": 0, "missing": 0})
        entry["jobs"] += 1
        entry[state] += 1
        totals[state] += 1
    keys = {j.key for j in jobs}
    rows = store.read("results", spec.name, columns=["job_key"]).num_rows
    return {
        "campaign": spec.name, "store": str(Path(out)), **totals, "stored_rows": rows,
        "other_rows": len(done - keys), "actuators": per,
        # done rows made by other code, data or settings than this version's (`campaign run` redoes them)
        "stale": sum(1 for j in jobs if j.key in stored and stored[j.key] != j.fingerprint),
        # actuators with healthy recordings whose baseline is not made yet: their jobs wait for it
        "waiting_for_baseline": spec.waiting(out),
    }  # fmt: skip
