"""Synthetic results stores: many actuators' histories of diagnoses without identifying anything.

For the read side of a fleet (``emaphm fleet``, ``campaign status``, ``rul``) at the scale of an
operator's fleet (issue 35: 10 000 actuators x 20 flights): rows in `store.RESULT_COLUMNS` whose
estimates are a degradation (each fault healthy, or growing linearly from a drawn start) plus
Gaussian noise of the interval's standard deviation, with verdicts per fault against the packaged
detection thresholds. A share of diagnoses is "doubtful" and a smaller one "does not fit", so
that their handling is exercised. Everything is drawn from `seed`. Not a model of any actuator:
the identifications' own figures are in BENCHMARKS.md.
"""

from __future__ import annotations

import json
import os
from typing import Any

import numpy as np

from ..faults import HEALTHY
from .store import ResultStore

__all__ = ["write_synthetic_store"]

SD = 0.01  # the estimates' standard deviation [fault units]
DOUBTFUL, NOT_FIT = 0.05, 0.01  # shares of the diagnoses
NAMES = ("friction", "backlash", "short_a", "short_b", "short_c", "eccentricity", "kp_drift")
COLUMNS = (0, 1, 2, 3, 4, 5, 7)


def _truths(rng: np.random.Generator, flights: int) -> np.ndarray:
    """(flights, 8) true fault vectors: each fault healthy (60 %) or at a start up to 0.08, and a
    fifth of them growing linearly by up to 0.008 a flight."""
    start = np.where(rng.uniform(size=8) < 0.6, 0.0, rng.uniform(0.0, 0.08, 8))
    growth = np.where(rng.uniform(size=8) < 0.2, rng.uniform(0.0, 0.008, 8), 0.0)
    k = HEALTHY + start + growth * np.arange(flights)[:, None]
    k[:, 6] = HEALTHY[6]  # the eccentricity's direction
    k[:, 7] = HEALTHY[7] + (k[:, 7] - HEALTHY[7]) * 0.5
    return np.clip(k, 0.0, 1.0)


def _rows(campaign: str, actuator: str, rng: np.random.Generator, flights: int) -> list[dict[str, Any]]:
    from ..identification.detection import load_thresholds

    thresholds = load_thresholds()["thresholds"]
    truths = _truths(rng, flights)
    rows = []
    for f in range(flights):
        u = rng.uniform()
        verdict = "does not fit" if u < NOT_FIT else "doubtful" if u < NOT_FIT + DOUBTFUL else "fits"
        k = np.clip(truths[f] + rng.normal(0.0, SD, 8), 0.0, 1.0)
        lo, hi = k - 1.645 * SD, k + 1.645 * SD
        judged = {}
        for name, j in zip(NAMES, COLUMNS, strict=True):
            a, b = lo[j] - HEALTHY[j], hi[j] - HEALTHY[j]  # the interval about healthy
            t = thresholds[name]
            judged[name] = "present" if a > t or b < -t else "absent" if -t <= a and b <= t else "cannot tell"
        row: dict[str, Any] = {
            "job_key": f"{campaign}-{actuator}-{f + 1}", "campaign": campaign, "actuator": actuator,
            "flight": f + 1, "seed": 0, "identify_seed": 0, "uq_method": "laplace", "verdict": verdict,
            "fault_verdicts": None if verdict == "does not fit" else json.dumps(judged),
            "detected": "" if verdict == "does not fit" else ",".join(n for n, v in judged.items() if v == "present"),
            "fit_nrmse": 0.2 if verdict == "does not fit" else 0.02 if verdict == "fits" else 0.04,
            "doubts": json.dumps(["synthetic: a doubtful diagnosis"] if verdict == "doubtful" else []),
            "warnings": "[]", "finished": f"2026-01-01T00:00:{f:02d}.000000+00:00", "version": "synthetic",
            "fingerprint": "synthetic", "evaluations": 0, "wall_time_s": 0.0, "fitness": 0.0,
        }  # fmt: skip
        for j in range(8):
            row[f"k{j + 1}"], row[f"true_k{j + 1}"] = float(k[j]), float(truths[f, j])
            row[f"std_k{j + 1}"], row[f"ci90_low_k{j + 1}"], row[f"ci90_high_k{j + 1}"] = (
                SD,
                float(lo[j]),
                float(hi[j]),
            )
        rows.append(row)
    return rows


def write_synthetic_store(
    root: str | os.PathLike[str], actuators: int, flights: int, *, seed: int = 0, campaign: str = "synthetic"
) -> int:
    """Write `actuators` x `flights` synthetic result rows into the store at `root` (one part file
    per actuator, as a campaign's batched writes make); the number of rows written."""
    store = ResultStore(root)
    width = len(str(max(actuators - 1, 0)))
    written = 0
    for a in range(actuators):
        rng = np.random.default_rng([seed, a])
        rows = _rows(campaign, f"A{a:0{width}d}", rng, flights)
        store.write("results", rows)
        written += len(rows)
    return written
