"""`emaphm simulate` (a trace from the HF twin or the monitor) and `emaphm demo` (the paper's Table 1)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..choices import HEALTHY_TEXT
from .options import (
    CALIBRATION_HELP,
    COMMANDS_TEXT,
    MONITOR_HELP,
    CalibrationOption,
    MonitorOption,
    OptimizerOption,
    ParamsNeedCalibrationOption,
    ParamsOption,
)
from .output import err, status, stdout_console

__all__ = ["demo", "simulate"]


def simulate(
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Trace to write: .h5 or .csv (+ .csv.json).")
    ],
    faults: Annotated[
        str, typer.Option(help="Fault vector k1..k8, comma separated, each in [0, 1].")
    ] = HEALTHY_TEXT,
    model: Annotated[
        str, typer.Option(help="hf: the high-fidelity twin; lf: the calibrated monitor model.")
    ] = "hf",
    noise: Annotated[bool, typer.Option("--noise/--no-noise", help="Seeded measurement noise.")] = True,
    seed: Annotated[int, typer.Option(help="Seed of every random choice.")] = 0,
    command: Annotated[str, typer.Option(help=f"Position command: {COMMANDS_TEXT}.")] = "chirp",
    duration: Annotated[
        float | None, typer.Option(help="Simulated time [s]; default: the command's.")
    ] = None,
    calibration: Annotated[
        Path | None, typer.Option(help=CALIBRATION_HELP + " Only with --model lf.")
    ] = None,
    monitor: Annotated[str | None, typer.Option(help=MONITOR_HELP + " Only with --model lf.")] = None,
    params: ParamsOption = None,
) -> None:
    """Simulate the actuator with a fault vector and write the sampled signals."""
    from ..actuator import resolve_params
    from ..commands import make_command
    from ..faults import describe, parse_faults
    from ..io import TRACE_SUFFIXES, check_output_path, write_trace
    from ..models import make_model
    from ..models._base import check_seed

    k = parse_faults(faults)
    check_seed(seed)
    check_output_path(output, suffixes=TRACE_SUFFIXES, inputs=(calibration, params))  # before the work
    ema = make_model(
        model, params=resolve_params(params), command=make_command(command), calibration=calibration,
        monitor=monitor,
    )  # fmt: skip
    ema.sample_grid(duration)  # a duration no run can have: before the work
    with status(f"simulating {model.upper()} twin ({describe(k)})"):
        result = ema.simulate(k, noise=noise, seed=seed, duration=duration)
    replaced = output.exists()
    write_trace(result, output)
    note = ", replaced the existing file" if replaced else ""
    err.print(f"wrote {output} ({len(result.t)} samples, model {model}, seed {seed}{note})")


def demo(
    output_dir: Annotated[Path, typer.Option(help="Folder for the figures.")] = Path("emaphm-demo"),
    seed: Annotated[int, typer.Option(help="Seed of the measurement noise.")] = 0,
    optimizer: OptimizerOption = "ga",
    runs: Annotated[int, typer.Option(help="Identifications (optimiser seeds 1..runs).")] = 5,
    calibration: CalibrationOption = None,
    monitor: MonitorOption = None,
    params: ParamsNeedCalibrationOption = None,
) -> None:
    """The main job: the paper's Table 1 experiment (HF twin with noise, five identifications)."""
    from ..demo import run_demo
    from .options import settings_from_options

    run_demo(
        output_dir, seed=seed, runs=runs, settings=settings_from_options({"optimizer": optimizer, "monitor": monitor}),
        calibration=calibration, console=stdout_console(), status=status, params=params,
    )  # fmt: skip
