"""`emaphm baseline`: one actuator's constants and monitor from recordings of it when healthy (issue 33)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .._threads import numba_threads
from .options import CalibrationOption, ParamsOption, WorkersOption
from .output import err, progress

__all__ = ["baseline"]


def baseline(
    recordings: Annotated[
        list[Path], typer.Argument(help="Recordings of the actuator when healthy (new or just overhauled).")
    ],
    output: Annotated[Path, typer.Option("--output", "-o", help="The baseline folder to write.")],
    map_file: Annotated[
        Path | None,
        typer.Option("--map", help="Channel map (TOML) that reads the recordings (docs/your-actuator.md)."),
    ] = None,
    params: ParamsOption = None,
    calibration: CalibrationOption = None,
    uq_calibration: Annotated[
        Path | None, typer.Option(help="The nameplate's interval calibration (default: the packaged one).")
    ] = None,
    detection: Annotated[
        Path | None, typer.Option(help="The nameplate's detection thresholds (default: the packaged ones).")
    ] = None,
    workers: WorkersOption = 0,
) -> None:
    """Fit this actuator's constants (flux, inertia, friction, backlash, position gain, current-sensor
    gain) to its healthy recordings and write what 'emaphm identify --baseline DIR' needs.

    --params is the actuator's nameplate file (with --calibration, its monitor's calibration).
    Recordings that are not of one healthy actuator are refused with the reason (exit 2).
    """
    from ..baseline import check_output_dir, make_baseline, write_baseline
    from ..errors import InputError
    from ..identification.detection import load_thresholds
    from ..identification.uncertainty import load_factors
    from ..io import check_trace_path

    check_output_dir(output)
    if map_file is not None:
        from ..measured import ChannelMap

        ChannelMap.load(map_file)  # a bad map: refused before the work
    for rec in recordings:
        if not rec.is_file():
            raise InputError(f"{rec}: no such recording")
        if map_file is None:
            check_trace_path(rec, for_writing=False)
    load_factors(uq_calibration)  # bad files: refused before the work
    load_thresholds(detection)
    with numba_threads(workers, name="--workers"), progress() as update:
        made = make_baseline(
            [str(r) for r in recordings], channel_map=map_file, params=params, calibration=calibration,
            progress=update,
        )  # fmt: skip
    folder = write_baseline(made, output, uq_calibration=uq_calibration, detection=detection)
    if made.record["warm_start"]:
        err.print(f"emaphm: warning: {made.record['warm_start']}", soft_wrap=True)
    for c, entry in made.record["factors"].items():
        low, high = entry["ci90"]
        err.print(f"{c:>7}: {entry['factor']:.4f} x the nameplate (90 % interval {low:.4f}-{high:.4f})")
    fits = ", ".join(
        f"{100 * r['nameplate_fit_nrmse']:.2f} -> {100 * r['fit_nrmse']:.2f} %"
        for r in made.record["recordings"]
    )
    err.print(f"healthy fits at the nameplate -> the baseline: {fits}")
    err.print(
        f"wrote {folder} (the fit took {made.record['wall_time_s']:.1f} s): use it with 'emaphm identify --baseline {folder}'"
    )
