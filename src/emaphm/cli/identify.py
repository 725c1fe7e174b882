"""`emaphm identify`: the fault vector from a recording, a trace or the HF twin, printed or as JSON.

The options are declared first, one type each; the command checks every input before the work
(`_checked_inputs`: exit 2 and nothing written), runs `emaphm.identification.identify`, then
writes what was asked for: the JSON file, the report folder, the table or one JSON object.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..choices import LAST_STAGES, UQ_METHODS
from ..errors import InputError
from .options import (
    CalibrationOption,
    MonitorOption,
    OptimizerOption,
    ParamsNeedCalibrationOption,
    WorkersOption,
)
from .output import err, progress
from .render import print_identification

__all__ = ["identify"]

TrueFaultsOption = Annotated[
    str | None,
    typer.Option(help="Simulate the HF twin (noise on) with these faults k1..k8 and identify them."),
]
ReferenceOption = Annotated[
    Path | None,
    typer.Option(
        help="Identify from a trace ('emaphm simulate', 'emaphm convert'), or a recording with --map."
    ),
]
MapOption = Annotated[
    Path | None,
    typer.Option(
        "--map",
        help="Channel map (TOML) that reads --reference as a rig's recording (docs/your-actuator.md).",
    ),
]
SeedOption = Annotated[int, typer.Option(help="Seed of the optimiser (and of the twin's noise).")]
PopSizeOption = Annotated[int | None, typer.Option(help="Population size (default per optimiser).")]
GenerationsOption = Annotated[int | None, typer.Option(help="Maximum generations (default per optimiser).")]
PolishOption = Annotated[bool, typer.Option("--polish/--no-polish", help="Local polish of the best point.")]
# the triggers are identify.SECOND_SEARCH_NRMSE's (a test checks), written out: no numpy for --help
SecondSearchOption = Annotated[
    bool,
    typer.Option(
        "--second-search/--no-second-search",
        help="With --polish: search again from another seed when the fit is poorer than the monitor's usual "
        "(NRMSE above 3 %; 5 % with --monitor paper), keeping the lower eq. 3 fitness (docs/identification.md).",
    ),
]
JsonOption = Annotated[bool, typer.Option("--json", help="Print one JSON object to stdout.")]
OutputOption = Annotated[Path | None, typer.Option("--output", "-o", help="Also write the JSON result here.")]
UncertaintyOption = Annotated[
    str,
    typer.Option(
        help="90 % interval per fault: laplace (fast, default), mcmc (emcee, minutes; "
        "pip install 'emaphm[uq]') or none."
    ),
]
UqCalibrationOption = Annotated[
    Path | None,
    typer.Option(help="Interval calibration from 'emaphm calibrate-uq' (default: the packaged one)."),
]
ReportOption = Annotated[
    Path | None,
    typer.Option(help="Also write a report to this folder: figures and a self-contained index.html."),
]
ErrorCornerOption = Annotated[
    str,
    typer.Option(
        help="Weight eq. 3 by 1/(1 + (f/F)^2) of the command's frequency f: F in Hz, 'auto' (the "
        "default monitor's measured corner; none with --monitor paper) or 'off' (the paper's eq. 3)."
    ),
]
LastStageOption = Annotated[
    str,
    typer.Option(
        help="With --polish, after the search: 'switching' corrects the monitor's bias near the estimate by the twin's "
        "switching drive (about 0.5 s more), 'none' skips it, 'auto' (default) runs it with the default "
        "monitor, not with --monitor paper (docs/identification.md)."
    ),
]


def identify(
    true_faults: TrueFaultsOption = None,
    reference: ReferenceOption = None,
    map_file: MapOption = None,
    optimizer: OptimizerOption = "ga",
    seed: SeedOption = 0,
    workers: WorkersOption = 0,
    pop_size: PopSizeOption = None,
    generations: GenerationsOption = None,
    polish: PolishOption = True,
    second_search: SecondSearchOption = True,
    json_out: JsonOption = False,
    output: OutputOption = None,
    calibration: CalibrationOption = None,
    monitor: MonitorOption = None,
    uncertainty: UncertaintyOption = "laplace",
    uq_calibration: UqCalibrationOption = None,
    params: ParamsNeedCalibrationOption = None,
    report: ReportOption = None,
    error_corner: ErrorCornerOption = "auto",
    last_stage: LastStageOption = "auto",
) -> None:
    """Identify the fault vector from a measured (or simulated) quadrature current.

    Exit status 0 with a diagnosis, 2 for bad input (nothing run), 3 when the monitor cannot
    explain the recording (verdict "does not fit": no faults are reported).
    """
    import json

    from ..identification.identify import identify as run_identify
    from ..io import atomic_path

    truth, corner = _checked_inputs(
        true_faults=true_faults, reference=reference, map_file=map_file, optimizer=optimizer, seed=seed,
        uncertainty=uncertainty, uq_calibration=uq_calibration, error_corner=error_corner,
        last_stage=last_stage, output=output, report=report, calibration=calibration, params=params,
    )  # fmt: skip
    with progress() as update:
        result = run_identify(
            truth, reference, optimizer=optimizer, seed=seed, workers=workers, pop_size=pop_size,
            generations=generations, local_polish=polish, second_search=second_search, calibration=calibration, monitor=monitor,
            uncertainty=uncertainty, uq_calibration=uq_calibration, params=params, channel_map=map_file,
            error_corner_hz=corner, last_stage=last_stage,
            on_generation=lambda gen, total, best: update(
                "MCMC steps" if gen < 0 else f"{optimizer.upper()} generations", abs(gen), total
            ),
        )  # fmt: skip
    data = result.to_json()
    for warning in data["warnings"]:
        err.print(f"emaphm: warning: {warning}", soft_wrap=True)
    if output is not None:
        with atomic_path(output) as tmp:
            tmp.write_text(json.dumps(data, indent=2) + "\n")
    if report is not None:
        from ..report import input_provenance, write_report

        provenance = input_provenance(
            reference, truth=truth, channel_map=map_file, conversion=data["settings"].get("conversion"),
            params=params, calibration=calibration,
        )  # fmt: skip
        page = write_report(result, report, provenance=provenance)
        err.print(f"wrote the report {page}")
    if json_out:
        typer.echo(json.dumps(data))
    else:
        print_identification(data)
    if data["verdict"] != "fits":
        raise typer.Exit(3)  # ran, but no diagnosis: scripts must not read it as one


def _checked_inputs(
    *, true_faults: str | None, reference: Path | None, map_file: Path | None, optimizer: str, seed: int,
    uncertainty: str, uq_calibration: Path | None, error_corner: str, last_stage: str, output: Path | None,
    report: Path | None, calibration: Path | None, params: Path | None,
) -> tuple[Any, float | str | None]:  # fmt: skip
    """Every check of `identify`'s options and files, before the work: (the truth or None, the corner).

    The settings first (so that a bad optimiser is named as such, not as a bad reference), then the
    input files, the output paths (none may be one of the files read) and the interval calibration.
    """
    from ..faults import parse_faults
    from ..identification.optimizers import check_optimizer
    from ..io import check_output_path, check_trace_path
    from ..models import check_seed

    if (true_faults is None) == (reference is None):
        raise InputError("give exactly one of --true-faults or --reference")
    if uncertainty not in UQ_METHODS:
        raise InputError(f"unknown --uncertainty {uncertainty!r}; use one of {', '.join(UQ_METHODS)}")
    check_optimizer(optimizer)  # before the reference is parsed, so the reason is the optimiser
    check_seed(seed)
    corner = _error_corner(error_corner)
    if last_stage not in LAST_STAGES:
        raise InputError(f"unknown --last-stage {last_stage!r}; use one of {', '.join(LAST_STAGES)}")
    truth = parse_faults(true_faults, option="--true-faults") if true_faults is not None else None
    if reference is not None and map_file is None:
        check_trace_path(reference, for_writing=False)
    if map_file is not None:
        from ..measured import ChannelMap

        if reference is None:
            raise InputError("--map reads a recording: give it with --reference")
        ChannelMap.load(map_file)  # a bad map: refused before the work
    if output is not None:
        check_output_path(
            output, suffixes=(".json",), inputs=(reference, calibration, uq_calibration, params, map_file)
        )
    if report is not None:
        from ..report import check_report_dir

        check_report_dir(report)
    if uncertainty == "none" and uq_calibration is not None:
        raise InputError("--uq-calibration needs --uncertainty laplace or mcmc")
    if uncertainty != "none":
        from ..identification.uncertainty import load_factors

        load_factors(uq_calibration)  # a bad file: refused before the work
    return truth, corner


def _error_corner(text: str) -> float | str | None:
    """--error-corner: 'auto', 'off' or a frequency > 0 [Hz] (`identify.parse_error_corner`)."""
    from ..identification.identify import parse_error_corner

    try:
        value: float | str = float(text)
    except ValueError:
        value = text
    return parse_error_corner(value, name="--error-corner")
