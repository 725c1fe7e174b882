"""`emaphm calibrate` (the monitor's coefficients), `emaphm calibrate-uq` (the intervals' factors) and
`emaphm calibrate-detection` (the detection thresholds)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .._threads import numba_threads
from ..choices import STARTS
from ..errors import InputError
from .options import (
    CalibrationOption,
    MonitorOption,
    ParamsNeedCalibrationOption,
    ParamsOption,
    WorkersOption,
)
from .output import err, logged, progress

__all__ = ["calibrate", "calibrate_detection", "calibrate_uq"]


def calibrate(
    output: Annotated[Path, typer.Option("--output", "-o", help="Calibration file to write (JSON).")] = Path(
        "lf-calibration.json"
    ),
    seed: Annotated[int, typer.Option(help="Seed of the GA and of the noisy check.")] = 1,
    pop_size: Annotated[int, typer.Option(help="GA population size.")] = 60,
    generations: Annotated[int, typer.Option(help="GA generations.")] = 150,
    workers: WorkersOption = 0,
    monitor: Annotated[
        str, typer.Option(help="Monitor model to calibrate: 'default', or 'paper' (eqs. 1-2 alone).")
    ] = "default",
    params: ParamsOption = None,
    free: Annotated[
        str | None,
        typer.Option(
            help="Fit only these coefficients (comma-separated, e.g. 'i_D'); the others are held at --start's."
        ),
    ] = None,
    start: Annotated[
        Path | None,
        typer.Option(
            help="Calibration whose coefficients --free leaves as they are (default: the packaged one)."
        ),
    ] = None,
) -> None:
    """Re-run the LF calibration against the HF twin (of the actuator file) and write the calibration file."""
    from ..actuator import resolve_params
    from ..calibration import load_calibration
    from ..calibration.fit_monitor import calibrate as run_calibration
    from ..io import check_output_path
    from ..models._base import check_seed

    check_seed(seed)
    check_output_path(output, suffixes=(".json",), inputs=(params, start))
    if start is not None and free is None:
        raise InputError("--start needs --free: it names the coefficients the others are held for")
    names = None if free is None else [n.strip() for n in free.split(",") if n.strip()]
    actuator = resolve_params(params)
    held = None if start is None else load_calibration(start)
    with numba_threads(workers, name="--workers"), progress() as update:
        cal = run_calibration(
            monitor=monitor, seed=seed, pop_size=pop_size, generations=generations, progress=update,
            params=actuator, free=names, start=held,
        )  # fmt: skip
    from ..calibration.quality import judge, summary_lines

    cal.record["quality"] = judge(cal.record)
    cal.save(output)
    for key, title in (("fit_scenarios", "fitted"), ("check_scenarios", "held out")):
        values = [s["nrmse"] for s in cal.record[key]]
        err.print(
            f"{title}: NRMSE {100 * min(values):.1f} to {100 * max(values):.1f} % over {len(values)} scenarios"
        )
    for line in summary_lines(cal.record["quality"]):
        err.print(line, soft_wrap=True)
    err.print(
        f"wrote {output} (seed {seed}, actuator {cal.params_hash}, {cal.record['settings']['wall_time_s']:.0f} s)"
    )


def calibrate_uq(
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Interval calibration file to write (JSON).")
    ] = Path("uq-calibration.json"),
    cases: Annotated[int, typer.Option(help="Random HF actuators to identify (about 5 s each).")] = 160,
    seed: Annotated[int, typer.Option(help="Seed of the cases, their noise and the optimiser.")] = 4101,
    calibration: CalibrationOption = None,
    monitor: MonitorOption = None,
    workers: WorkersOption = 0,
    params: ParamsNeedCalibrationOption = None,
    drive_tolerance: Annotated[
        float,
        typer.Option(
            help="FOC drives: draw each case's PI gains within ±this (relative) and its carrier phase; "
            "no effect on a hysteresis drive."
        ),
    ] = 0.1,
    tolerance: Annotated[
        float,
        typer.Option(
            help="Draw each case's motor and drive-train constants within ±this (relative; 0: the exact twin)."
        ),
    ] = 0.0,
    last_stage: Annotated[
        str,
        typer.Option(
            help="The identifications' last stage ('auto', 'switching', 'none'), as 'emaphm identify "
            "--last-stage': the intervals hold for identifications that end the same way.",
        ),
    ] = "auto",
    start: Annotated[
        str,
        typer.Option(
            help="The identifications' first population ('random', 'table', 'auto'), as 'emaphm identify "
            "--start': the intervals' widths move with the search's end points, so fit them for the start you use.",
        ),
    ] = "auto",
) -> None:
    """Re-fit the calibration of the 90 % intervals for the monitor's bias (after 'emaphm calibrate')."""
    from ..actuator import resolve_params
    from ..calibration.fit_intervals import calibrate_uq as run_calibrate_uq
    from ..identification.last_stage import resolve_last_stage
    from ..io import check_output_path
    from ..models import MonitorEma
    from ..models._base import check_seed

    check_seed(seed)
    if cases < 20:
        raise InputError(f"--cases must be >= 20 (coverage needs a sample), got {cases}")
    if not 0.0 <= drive_tolerance < 1.0:
        raise InputError(f"--drive-tolerance must be in [0, 1), got {drive_tolerance:g}")
    if not 0.0 <= tolerance < 0.5:
        raise InputError(f"--tolerance must be in [0, 0.5), got {tolerance:g}")
    check_output_path(output, suffixes=(".json",), inputs=(calibration, params))
    actuator = resolve_params(params)
    lf = MonitorEma(actuator, calibration=calibration, monitor=monitor)  # a calibration that does not fit: now
    resolve_last_stage(last_stage, lf.monitor)  # an unknown one: now
    if start not in STARTS:
        raise InputError(f"unknown --start {start!r}; choose one of {', '.join(STARTS)}")
    with numba_threads(workers, name="--workers"), progress() as update:
        report = logged(update)
        factors = run_calibrate_uq(
            cases=cases, seed=seed, calibration=calibration, monitor=monitor, progress=report,
            params=actuator, drive_tolerance=drive_tolerance, tolerance=tolerance, last_stage=last_stage,
            start=start,
        )  # fmt: skip
    factors.save(output)
    for case in factors.record["skipped"]:
        err.print(
            f"left out case {case['case']}: the monitor does not explain it (NRMSE {case['fit_nrmse']:.3g})"
        )
    for name, fit in factors.record["training"].items():
        err.print(f"{name}: coverage {fit['coverage']:.2f}, median half-width {fit['median_half_width']:.4f}")
    err.print(f"wrote {output} ({cases} cases, seed {seed}, {factors.record['wall_time_s']:.0f} s)")


def calibrate_detection(
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Detection thresholds file to write (JSON).")
    ] = Path("detection.json"),
    runs: Annotated[
        int,
        typer.Option(help="Healthy identifications for the thresholds, and as many to count false alarms."),
    ] = 20,
    seed: Annotated[
        int, typer.Option(help="Seed of the first healthy run (the false alarms' start 1000 later).")
    ] = 1000,
    sensitivity: Annotated[
        bool,
        typer.Option(
            "--sensitivity/--no-sensitivity", help="Also check that each single fault of 0.1 is detected."
        ),
    ] = True,
    calibration: CalibrationOption = None,
    monitor: MonitorOption = None,
    workers: WorkersOption = 0,
    params: ParamsNeedCalibrationOption = None,
) -> None:
    """Measure the detection thresholds on healthy runs of the HF twin (after 'emaphm calibrate')."""
    from ..calibration.fit_detection import calibrate_detection as run_calibrate_detection
    from ..identification.settings import IdentifySettings
    from ..io import check_output_path

    check_output_path(output, suffixes=(".json",), inputs=(calibration, params))
    settings = IdentifySettings(monitor=monitor, workers=workers)  # the rest as identify's defaults
    with progress() as update:
        report = logged(update)
        record = run_calibrate_detection(
            params=params, calibration=calibration, settings=settings, runs=runs, threshold_seed=seed,
            false_alarm_seed=seed + 1000, sensitivity_seed=seed + 2000 if sensitivity else None,
            progress=report, output=output,
        )  # fmt: skip
    for name, value in record["thresholds"].items():
        err.print(f"{name}: threshold {value:g}")
    err.print(
        f"false alarms: {record['false_alarm_runs']} of {record['runs']} fresh healthy runs; "
        f"wrote {output} ({record['wall_time_s']:.0f} s)"
    )
