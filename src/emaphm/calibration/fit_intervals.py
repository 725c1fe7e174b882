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
from typing import Any

import numpy as np

from .._versions import versions
from ..actuator import resolve_params
from ..callbacks import Progress
from ..choices import STARTS
from ..errors import InputError
from ..faults import random_faults
from ..identification.uncertainty import FIT_COVERAGE, Factors, fit_factors
from ..identification.verdict import fit_distribution
from ..models import MonitorEma
from ..models._base import check_seed
from ..params import EmaParams
from ..tolerances import DRIVE_TOLERANCE
from .files import Calibration

__all__ = ["UQ_ABSENT", "UQ_CASES", "UQ_CASE_SEED", "calibrate_uq", "collect_cases"]

UQ_CASE_SEED = 4101  # no benchmark draws from it (bench_multifault 2611, uq_coverage 4201)
UQ_CASES = 160
UQ_ABSENT = 1.0 / 3.0  # the probability that each fault of a case is absent
# the share of cases that may not fit (and are left out, listed in the record): an FOC drive's loop
# goes unstable with two phases shorted by more than about 45 % (docs/theory/hf-model.md §4b), which
# the monitor does not model; more than this means the monitor does not explain the actuator
MAX_SKIPPED = 0.1


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
    drive_tolerance: float = 0.0,
    tolerance: float = 0.0,
    last_stage: str = "auto",
    start: str = "auto",
) -> dict[str, Any]:
    """Identify random actuators `first`..`cases`−1 of `seed` (HF twin, noise on; case i with the
    identification seed 1000·seed + i) with noise-only Laplace intervals: {"truths", "estimates",
    "raw_std", "added_std" (the constants' part, `uncertainty.constants`), "fit_nrmse"} arrays (one
    row per case) and "skipped", the cases the monitor could not explain. The draws do not depend on
    `cases`: a longer set extends a shorter one, `first` resumes one. Each case's twin is drawn
    about `params` (`tolerances.drawn_actuator`) with `tolerance` > 0, or of an FOC drive with
    `drive_tolerance` > 0 (the PI gains, the carrier's phase).

    Parameters
    ----------
    cases, seed : int — the number of cases and the seed of their draws.
    calibration, monitor : the LF calibration (default: the packaged one) and the monitor model (None: its).
    absent : float
        Probability that each fault of a case is absent (healthy value), in [0, 1].
    first : int — the first case to identify (to resume a set).
    progress : callable, optional
        ``progress(stage, done, total)`` after each case.
    params : EmaParams, optional — the actuator (default: the paper's nominal one).
    drive_tolerance, tolerance : float
        The spread of the drawn twins' PI gains (FOC) and of their constants (0: the actuator's own twin).
    last_stage, start : the identifications' last stage and first population (`IdentifySettings`).
    """
    from ..identification.api import identify
    from ..identification.recording import split_seed
    from ..models import HighFidelityEma
    from ..tolerances import drawn_actuator

    actuator = params if params is not None else EmaParams()
    drawn = (actuator.inverter.foc and drive_tolerance > 0) or tolerance > 0
    K = random_faults(cases, seed, absent=absent)[first:]
    kept: list[tuple[Any, ...]] = []  # (truth, estimate, raw σ, fit NRMSE) of each usable case
    walls, skipped = [], []
    for i, k in enumerate(K, start=first):
        run_seed = 1000 * seed + i
        source: dict[str, Any] = {"true_faults": k}
        if drawn:  # the twin of an actuator drawn about this one, measured as identify's twin would be
            plant = drawn_actuator(actuator, run_seed, tolerance=tolerance, drive_tolerance=drive_tolerance)
            source = {"reference": HighFidelityEma(plant).simulate(k, seed=split_seed(run_seed)[0])}
        r = identify(
            **source, seed=run_seed, calibration=calibration, monitor=monitor,
            uncertainty="laplace", uq_calibration=Factors.identity(), params=params, last_stage=last_stage, start=start,
        )  # fmt: skip
        if r.uncertainty is None:  # the monitor could not explain the twin: not a usable case
            skipped.append({"case": i, "faults": k.tolist(), "fit_nrmse": r.fit_nrmse})
        else:
            added = getattr(r.uncertainty, "details", {}).get("constants_std") or [0.0] * len(k)
            kept.append((k, r.estimate, r.uncertainty.raw_std, r.fit_nrmse, added))  # (added: `constants`)
        walls.append(r.wall_time_s)
        if progress is not None:
            progress("identifications", i + 1, cases)
    if len(skipped) > MAX_SKIPPED * len(K):
        raise InputError(
            f"{len(skipped)} of {len(K)} cases did not fit (e.g. case {skipped[0]['case']}, NRMSE "
            f"{skipped[0]['fit_nrmse']}): the monitor does not explain this actuator; check its calibration"
        )
    rows = (len(kept), K.shape[1])
    return {
        **{
            name: np.array([c[j] for c in kept]).reshape(rows)
            for j, name in zip((0, 1, 2, 4), ("truths", "estimates", "raw_std", "added_std"), strict=True)
        },
        "fit_nrmse": np.array([c[3] for c in kept], dtype=np.float64),
        "skipped": skipped,
        "wall_time_s": walls,
    }


def calibrate_uq(
    *,
    cases: int = UQ_CASES,
    seed: int = UQ_CASE_SEED,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    monitor: str | None = None,
    progress: Progress | None = None,
    params: EmaParams | str | os.PathLike[str] | None = None,
    drive_tolerance: float = DRIVE_TOLERANCE,
    tolerance: float = 0.0,
    last_stage: str = "auto",
    start: str = "auto",
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
    drive_tolerance : float
        Of an FOC drive: each case's twin is drawn with its PI gains within ±drive_tolerance and
        its carrier at a random phase (`tolerances.drawn_actuator`), so that the intervals hold on
        drives that differ from the file in what a data sheet does not fix; no effect on a
        hysteresis drive.
    tolerance : float
        Each case's twin drawn with its motor and drive-train constants within ±tolerance
        (`tolerances.drawn_actuator`; 0: the exact twin). Either way the factors are fitted to the
        intervals as identify gives them, widened for the constants (`identification.uncertainty.
        constants`), so that the widening is not counted twice.
    last_stage : {"auto", "switching", "none"}
        The identifications' last stage: the factors hold for identifications that end the same way
        (``emaphm identify --last-stage``; the record says which, `identify` warns on a mismatch).
        "none" remakes the packaged ``uq_calibration_no_last_stage.json``.
    start : {"random", "table", "auto"}
        The GA's first population (``emaphm identify --start``): the intervals' widths move with
        the exact end point, and the table's end points need factors of their own (issue 36:
        the packaged factors held 0.913 of the truth with the table's start, refitted on it 0.929).
    """
    from ..identification.last_stage import resolve_last_stage

    seed = check_seed(seed)
    if not isinstance(cases, int) or cases < 20:
        raise InputError(f"cases must be a whole number >= 20 (coverage needs a sample), got {cases!r}")
    if not (isinstance(drive_tolerance, (int, float)) and 0.0 <= drive_tolerance < 1.0):
        raise InputError(f"drive_tolerance must be in [0, 1), got {drive_tolerance!r}")
    actuator = resolve_params(params)
    lf = MonitorEma(actuator, calibration=calibration, monitor=monitor).calibration
    stage = resolve_last_stage(last_stage, lf.monitor)  # refused now if unknown
    if start not in STARTS:
        raise InputError(f"unknown start {start!r}; choose one of {', '.join(STARTS)}")
    began = time.perf_counter()
    data = collect_cases(
        cases, seed, calibration=calibration, monitor=monitor, progress=progress, params=actuator,
        drive_tolerance=drive_tolerance, tolerance=tolerance, last_stage=last_stage, start=start,
    )  # fmt: skip
    # fitted without the shorts' allowance for psi_m (`uncertainty.balanced`): a baselined run, which
    # has none, uses these factors too; without a baseline the two overlap (wider, not narrower)
    fitted, report = fit_factors(data["estimates"], data["raw_std"], data["truths"], added=data["added_std"])
    record = _record(lf, actuator, data, report, cases=cases, seed=seed, drive_tolerance=drive_tolerance,
                     tolerance=tolerance, wall=time.perf_counter() - began, last_stage=stage, start=start)  # fmt: skip
    return Factors(fitted.scale, fitted.floor, record)


def _record(
    lf: Calibration, actuator: EmaParams, data: dict[str, Any], report: dict[str, Any], *, cases: int, seed: int,
    drive_tolerance: float, tolerance: float, wall: float, last_stage: str, start: str = "auto",
) -> dict[str, Any]:  # fmt: skip
    """The interval calibration's record: how it was made, on what, and its cases' data."""
    from ..identification.weights import resolve_error_corner

    return {
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
        "last_stage": last_stage,
        "start": start,  # the GA's first population (`IdentifySettings.start`; the same reason)
        "cases": cases,
        "seed": seed,
        "absent": UQ_ABSENT,
        # of an FOC drive, the spread of the drawn twins' PI gains (0: the actuator's own twin)
        "drive_tolerance": float(drive_tolerance) if actuator.inverter.foc else 0.0,
        # the actuators' constants drawn within ±tolerance (`tolerances.drawn_actuator`), and each
        # interval widened for them as identify widens it (`uncertainty.constants`)
        "tolerance": float(tolerance),
        "skipped": data["skipped"],
        "form": "sigma = sqrt((scale * sigma_raw)^2 + floor^2 + sigma_constants^2); the narrowest median interval covering coverage_target of these cases",
        "coverage_target": FIT_COVERAGE,
        "training": report,
        "fit": fit_distribution(data["fit_nrmse"]),  # how well it explains its twin (`verdict.fit_limit`)
        "wall_time_s": round(wall, 1),
        "versions": versions(),
        "data": {
            k: np.asarray(v).round(6).tolist() for k, v in data.items() if k not in ("wall_time_s", "skipped")
        },
    }
