"""Calibration of the 90 % intervals for the monitor's discrepancy (issue 9, item 3; ``emaphm calibrate-uq``).

The Laplace intervals (`identification.uncertainty.laplace`) see the measurement noise only;
the monitor's discrepancy from the actuator biases every estimate by more than that. This module
identifies random actuators of the HF twin (noise on) whose truth is known, keeps each estimate
with its noise-only σ, and fits a scale and a floor per fault
(`identification.uncertainty.fit_factors`) so that 90 % of the intervals hold with the narrowest
median interval. The cases are drawn from a seed of their own (`UQ_CASE_SEED`), different from
every benchmark's; a third of the faults are truly absent (`faults.random_faults(absent=...)`),
so that intervals at the bound are calibrated too. The fitted `Factors` (with `load_factors`)
stay in `identification.uncertainty`, which applies them.

The result is tied to the LF calibration it was fitted with (its monitor, date and actuator):
identification with another calibration falls back to noise-only intervals and says so. Re-run
``emaphm calibrate-uq`` whenever the monitor model or its calibration changes.
"""

from __future__ import annotations

import datetime as _dt
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .._versions import versions
from ..actuator import resolve_params
from ..errors import InputError
from ..faults import random_faults
from ..identification.uncertainty import FIT_COVERAGE, Factors, fit_factors
from ..models import MonitorEma
from ..models._base import check_seed
from ..params import EmaParams
from .files import Calibration

__all__ = ["UQ_ABSENT", "UQ_CASES", "UQ_CASE_SEED", "calibrate_uq", "collect_cases"]

UQ_CASE_SEED = 4101  # no benchmark draws from it (bench_multifault 2611, uq_coverage 4201)
UQ_CASES = 160
UQ_ABSENT = 1.0 / 3.0  # the probability that each fault of a case is absent

Progress = Callable[[str, int, int], None]


def collect_cases(
    cases: int,
    seed: int,
    *,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    monitor: str | None = None,
    absent: float = UQ_ABSENT,
    first: int = 0,
    progress: Progress | None = None,
    params: EmaParams | None = None,
) -> dict[str, Any]:
    """Identify random actuators `first`..`cases`−1 of `seed` (HF twin, noise on; case i with the
    identification seed 1000·seed + i) with noise-only Laplace intervals: {"truths", "estimates",
    "raw_std"} arrays (one row per case). The draws do not depend on `cases`, so a longer set
    extends a shorter one, and `first` resumes one.

    Parameters
    ----------
    cases, seed : int
        The number of cases and the seed of their draws.
    calibration : Calibration or path, optional
        The LF calibration (default: the packaged one).
    monitor : {"default", "paper"}, optional
        The monitor model (None: the calibration's).
    absent : float
        Probability that each fault of a case is absent (healthy value), in [0, 1].
    first : int
        The first case to identify (to resume a set).
    progress : callable, optional
        ``progress(stage, done, total)`` after each case.
    params : EmaParams, optional
        The actuator (default: the paper's nominal one).
    """
    from ..identification.api import identify

    K = random_faults(cases, seed, absent=absent)[first:]
    estimates, raw, walls = np.empty_like(K), np.empty_like(K), []
    for i, k in enumerate(K, start=first):
        r = identify(
            true_faults=k, seed=1000 * seed + i, calibration=calibration, monitor=monitor,
            uncertainty="laplace", uq_calibration=Factors.identity(), params=params,
        )  # fmt: skip
        if r.uncertainty is None:  # the monitor could not explain the twin: not a usable case
            raise InputError(
                f"case {i} ({k.tolist()}) did not fit (NRMSE {r.fit_nrmse}); cannot calibrate on it"
            )
        estimates[i - first], raw[i - first] = r.estimate, r.uncertainty.raw_std
        walls.append(r.wall_time_s)
        if progress is not None:
            progress("identifications", i + 1, cases)
    return {"truths": K, "estimates": estimates, "raw_std": raw, "wall_time_s": walls}


def calibrate_uq(
    *,
    cases: int = UQ_CASES,
    seed: int = UQ_CASE_SEED,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    monitor: str | None = None,
    progress: Progress | None = None,
    params: EmaParams | str | os.PathLike[str] | None = None,
) -> Factors:
    """Fit the interval calibration on `cases` random HF actuators (about 5 s each on 2 cores).

    `params` is the actuator (`EmaParams` or an actuator file): `calibration` must be its own.

    Parameters
    ----------
    cases : int
        Random HF actuators identified.
    seed : int
        Seed of the cases' draws (case i is identified with seed 1000·seed + i).
    calibration : Calibration or path, optional
        The actuator's LF calibration (default: the packaged one).
    monitor : {"default", "paper"}, optional
        The monitor model (None: the calibration's).
    progress : callable, optional
        ``progress(stage, done, total)`` after each case.
    params : EmaParams or path, optional
        The actuator (default: the paper's nominal one).
    """
    from ..identification.last_stage import resolve_last_stage
    from ..identification.weights import resolve_error_corner

    seed = check_seed(seed)
    if not isinstance(cases, int) or cases < 20:
        raise InputError(f"cases must be a whole number >= 20 (coverage needs a sample), got {cases!r}")
    actuator = resolve_params(params)
    lf = MonitorEma(actuator, calibration=calibration, monitor=monitor).calibration
    start = time.perf_counter()
    data = collect_cases(
        cases, seed, calibration=calibration, monitor=monitor, progress=progress, params=actuator
    )
    fitted, report = fit_factors(data["estimates"], data["raw_std"], data["truths"])
    record = {
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "method": "laplace",
        "lf_calibration": {
            "monitor": lf.monitor,
            "created": lf.record.get("created"),
            "params_hash": lf.params_hash,
        },
        # the eq. 3 frequency weights the identifications used (`weights.error_weights`)
        "error_corner_hz": resolve_error_corner("auto", lf.monitor),
        # the last stage the identifications ran (`switching`): it sets how far estimates fall
        # from the truth, so intervals fitted with one do not hold for the other
        "last_stage": resolve_last_stage("auto", lf.monitor),
        "cases": cases,
        "seed": seed,
        "absent": UQ_ABSENT,
        "form": "sigma = sqrt((scale * sigma_raw)^2 + floor^2); the narrowest median interval covering coverage_target of these cases",
        "coverage_target": FIT_COVERAGE,
        "training": report,
        "wall_time_s": round(time.perf_counter() - start, 1),
        "versions": versions(),
        "data": {k: np.asarray(v).round(6).tolist() for k, v in data.items() if k != "wall_time_s"},
    }
    return Factors(fitted.scale, fitted.floor, record)
