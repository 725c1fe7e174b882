"""Fleet campaigns (issue 11): many identifications from one file, on Dask, into a results store
that survives interruption.

- `spec`: the campaign file (TOML) and its jobs with stable content keys; `identify_table` its
  ``[identify]`` table; `fingerprint` what computes a job (code, packaged data, settings);
- `actuators`: its ``[[actuator]]`` and ``[[fleet]]`` tables, histories grown flight by flight;
- `jobs`: one job, run anywhere from plain data (`run_job`);
- `store`: the Parquet results store, written atomically;
- `runner`: `run_campaign` (the missing and stale jobs only; serial, or on Dask by `cluster`); `status`:
  `campaign_status`.

``emaphm campaign run SPEC.toml --out DIR`` and ``emaphm campaign status SPEC.toml DIR`` are the
command line; docs/campaigns.md the guide.
"""

from __future__ import annotations

from .jobs import run_job
from .runner import CampaignSummary, run_campaign
from .spec import CampaignSpec, Job, history_seed, load_campaign
from .status import campaign_status
from .store import ResultStore

__all__ = [
    "CampaignSpec",
    "CampaignSummary",
    "Job",
    "ResultStore",
    "campaign_status",
    "history_seed",
    "load_campaign",
    "run_campaign",
    "run_job",
]
