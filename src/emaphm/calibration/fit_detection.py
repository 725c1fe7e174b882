"""Detection thresholds from repeated healthy, noisy identifications, and their false-alarm rate.

`calibrate_detection` measures what ships as ``emaphm/data/detection.json`` (DESIGN §5,
docs/identification.md §4), for the nominal actuator or another one with its own calibration:

1. Identify the healthy twin (noise on) with seeds `threshold_seed`.. (`runs` of them: each seed
   gives another noise realisation and another optimiser seed). For every detectable fault the
   threshold is 1.25 × the largest departure from healthy seen in these runs, plus 0.005 (k1..k6
   from 0, k8 from 0.5).
2. Measure the false-alarm rate on fresh healthy runs, seeds `false_alarm_seed`..: a run is a
   false alarm when any fault is reported.
3. Check sensitivity: single faults of 0.1 (k8: 0.6) and of 0.2 (k8: 0.7), one run each with
   `sensitivity_seed` (None: not checked).

The record says what the thresholds were made with (the actuator's `params_hash`, the monitor and
its calibration, the last stage, the settings and versions), so that an identification with
another actuator or monitor can tell that they are not its own.
"""

from __future__ import annotations

import datetime as _dt
import functools
import json
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._version import __version__
from .._versions import versions
from ..actuator import resolve_params
from ..callbacks import Progress
from ..errors import InputError
from ..faults import FAULT_NAMES, HEALTHY
from ..identification.api import identify
from ..identification.detection import DETECTABLE, detect
from ..identification.last_stage import resolve_last_stage
from ..identification.settings import IdentifySettings
from ..identification.weights import resolve_error_corner
from ..io import atomic_path, check_output_path
from ..models import MonitorEma
from ..models._base import check_seed
from ..params import EmaParams
from .files import Calibration, params_hash

__all__ = [
    "DETECTION_RULE",
    "DETECTION_RUNS",
    "FALSE_ALARM_SEED",
    "SENSITIVITY_SEED",
    "THRESHOLD_SEED",
    "calibrate_detection",
]

DETECTION_RUNS = 20  # healthy runs in each set
# the first seed of each set; no benchmark draws from 1000..1019 and 2000..2019
THRESHOLD_SEED, FALSE_ALARM_SEED, SENSITIVITY_SEED = 1000, 2000, 3000
DETECTION_RULE = "1.25 x the largest healthy departure + 0.005 (k1..k6 from 0, k8 from 0.5)"

Identify = Callable[..., Any]  # identify() with every setting but the faults and the seed bound


def calibrate_detection(
    *,
    params: EmaParams | str | os.PathLike[str] | None = None,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    settings: IdentifySettings | None = None,
    runs: int = DETECTION_RUNS,
    threshold_seed: int = THRESHOLD_SEED,
    false_alarm_seed: int = FALSE_ALARM_SEED,
    sensitivity_seed: int | None = SENSITIVITY_SEED,
    progress: Progress | None = None,
    output: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """Measure the detection thresholds (about 5 s per identification, 2·`runs` + 14 of them).

    `params` is the actuator (`EmaParams` or an actuator file), `calibration` its LF calibration
    (the packaged one by default, for the nominal actuator only); `settings` how each
    identification runs (`IdentifySettings`: the monitor, the optimiser, its budget and threads;
    its seed is replaced by each run's). `runs` healthy runs from `threshold_seed` give the
    thresholds, as many from `false_alarm_seed` the false alarms, and single faults from
    `sensitivity_seed` (None: skipped) the sensitivity. `progress` (stage, done, total) is
    called after each identification. The record (the thresholds file's content) is returned and,
    with `output`, written there atomically (a ``.json`` file; the package's own is
    ``src/emaphm/data/detection.json``). Bad input raises `InputError` before any work.
    """
    start = time.perf_counter()
    s = settings if settings is not None else IdentifySettings()
    sets = {"runs": runs, "threshold_seed": threshold_seed, "false_alarm_seed": false_alarm_seed,
            "sensitivity_seed": sensitivity_seed}  # fmt: skip
    actuator, lf = _checked(params, calibration, s.monitor, sets, output)
    run = functools.partial(identify, settings=s, calibration=calibration, params=actuator, thresholds={})
    measured = _measure(run, runs, threshold_seed, false_alarm_seed, sensitivity_seed, progress)
    record = {
        "thresholds": measured.pop("thresholds"),
        "monitor": lf.monitor,  # identify() warns when another monitor uses these thresholds
        "rule": DETECTION_RULE,
        "optimizer": s.optimizer,
        "error_corner_hz": resolve_error_corner("auto", lf.monitor),  # the eq. 3 weights the runs used
        "threshold_seeds": [threshold_seed, threshold_seed + runs - 1],
        "false_alarm_seeds": [false_alarm_seed, false_alarm_seed + runs - 1],
        **measured,
        "package_version": __version__,
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "wall_time_s": round(time.perf_counter() - start, 1),
        # what the thresholds were made with: they hold for this actuator, monitor and last stage
        "params_hash": params_hash(actuator),
        "last_stage": resolve_last_stage("auto", lf.monitor),
        "lf_calibration": {
            "monitor": lf.monitor,
            "created": lf.record.get("created"),
            "params_hash": lf.params_hash,
        },
        "settings": {**sets, "identify": s.to_json()},
        "versions": versions(),
    }
    if output is not None:
        _write(record, Path(output))
    return record


def _measure(
    run: Identify,
    runs: int,
    threshold_seed: int,
    false_alarm_seed: int,
    sensitivity_seed: int | None,
    progress: Progress | None,
) -> dict[str, Any]:
    """Steps 1-3 of the module's method: the thresholds, the false alarms, the sensitivity."""
    fit = _healthy_estimates(run, threshold_seed, runs, "healthy runs (thresholds)", progress)
    deviation = np.abs(fit - HEALTHY)[:, [FAULT_NAMES.index(n) for n in DETECTABLE]]
    thresholds = {
        name: round(1.25 * float(deviation[:, j].max()) + 0.005, 4) for j, name in enumerate(DETECTABLE)
    }
    check = _healthy_estimates(run, false_alarm_seed, runs, "healthy runs (false alarms)", progress)
    alarms = [detect(k, thresholds) for k in check]
    return {
        "thresholds": thresholds,
        "false_alarm_runs": sum(1 for a in alarms if a),
        "runs": runs,
        "false_alarms": [a for a in alarms if a],
        "healthy_estimates_threshold_set": fit.round(5).tolist(),
        "healthy_estimates_check_set": check.round(5).tolist(),
        "sensitivity": None
        if sensitivity_seed is None
        else _sensitivity(run, thresholds, sensitivity_seed, progress),
    }


def _checked(
    params: EmaParams | str | os.PathLike[str] | None,
    calibration: Calibration | str | os.PathLike[str] | None,
    monitor: str | None,
    settings: dict[str, Any],
    output: str | os.PathLike[str] | None,
) -> tuple[EmaParams, Calibration]:
    """The actuator and its LF calibration; `InputError` (one line) for any bad input."""
    runs = settings["runs"]
    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1:
        raise InputError(f"runs must be a whole number >= 1, got {runs!r}")
    first, second = check_seed(settings["threshold_seed"]), check_seed(settings["false_alarm_seed"])
    if settings["sensitivity_seed"] is not None:
        check_seed(settings["sensitivity_seed"])
    if first < second + runs and second < first + runs:
        raise InputError(
            f"the false-alarm runs must be fresh: seeds {second}..{second + runs - 1} overlap the "
            f"threshold runs' {first}..{first + runs - 1}"
        )
    if output is not None:
        check_output_path(output, suffixes=(".json",), option="output")
    actuator = resolve_params(params)
    # the calibration must be the actuator's own (MonitorEma refuses another's) and of `monitor`
    return actuator, MonitorEma(actuator, calibration=calibration, monitor=monitor).calibration


def _healthy_estimates(
    run: Identify, first_seed: int, runs: int, stage: str, progress: Progress | None
) -> NDArray[np.float64]:
    """The estimates of `runs` healthy identifications (noise on), seeds `first_seed`.. (one row each)."""
    out = []
    for j, seed in enumerate(range(first_seed, first_seed + runs)):
        out.append(run(HEALTHY, seed=seed).estimate)
        if progress is not None:
            progress(stage, j + 1, runs)
    return np.array(out)


def _sensitivity(
    run: Identify, thresholds: dict[str, float], seed: int, progress: Progress | None
) -> list[dict[str, Any]]:
    """Single faults of 0.1 and 0.2 (k8: 0.6, 0.7; eccentricity at phase 0.3), one run each: detected?"""
    out: list[dict[str, Any]] = []
    for name in DETECTABLE:
        for size in (0.1, 0.2):
            k = np.array(HEALTHY)
            i = FAULT_NAMES.index(name)
            k[i] = 0.5 + size if name == "kp_drift" else size
            if name == "eccentricity":
                k[6] = 0.3
            found = detect(run(k, seed=seed).estimate, thresholds)
            out.append({"fault": name, "value": float(k[i]), "detected": found})
            if progress is not None:
                progress("sensitivity (single faults)", len(out), 2 * len(DETECTABLE))
    return out


def _write(record: dict[str, Any], path: Path) -> None:
    """Write the thresholds file atomically: the old file or the whole new one, never a part."""
    text = json.dumps(record, indent=2) + "\n"
    with atomic_path(path) as tmp:
        tmp.write_text(text)
