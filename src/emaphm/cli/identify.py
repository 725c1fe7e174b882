"""`emaphm identify`: the fault vector from a recording, a trace or the HF twin, printed or as JSON.

The inputs' options are declared here, one type each; the settings' options are made from
`IdentifySettings` (`options.with_settings_options`), the one list of them. The command checks every input before the work
(`_checked_inputs`: exit 2 and nothing written), runs `emaphm.identify`, then
writes what was asked for: the JSON file, the report folder, the table or one JSON object.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..errors import InputError
from ..identification.settings import search_progress_label
from .options import (
    CalibrationOption,
    ParamsNeedCalibrationOption,
    settings_from_options,
    with_settings_options,
)
from .output import bracketed, err, progress
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
JsonOption = Annotated[bool, typer.Option("--json", help="Print one JSON object to stdout.")]
OutputOption = Annotated[Path | None, typer.Option("--output", "-o", help="Also write the JSON result here.")]
UqCalibrationOption = Annotated[
    Path | None,
    typer.Option(help="Interval calibration from 'emaphm calibrate-uq' (default: the packaged one)."),
]
DetectionOption = Annotated[
    Path | None,
    typer.Option(
        "--detection",
        help="Detection thresholds from 'emaphm calibrate-detection' for this actuator (default: the packaged ones).",
    ),
]
ReportOption = Annotated[
    Path | None,
    typer.Option(help="Also write a report to this folder: figures and a self-contained index.html."),
]
BaselineOption = Annotated[
    Path | None,
    typer.Option(
        "--baseline",
        help="This actuator's baseline folder from 'emaphm baseline': its actuator file, calibrations and "
        "thresholds (then not given otherwise).",
    ),
]
ActuatorIdOption = Annotated[
    str | None,
    typer.Option(
        "--actuator-id",
        help="The actuator's id (serial, position), recorded in the result and shown in the report.",
    ),
]


def identify(
    true_faults: TrueFaultsOption = None,
    reference: ReferenceOption = None,
    map_file: MapOption = None,
    json_out: JsonOption = False,
    output: OutputOption = None,
    calibration: CalibrationOption = None,
    uq_calibration: UqCalibrationOption = None,
    detection: DetectionOption = None,
    params: ParamsNeedCalibrationOption = None,
    report: ReportOption = None,
    actuator_id: ActuatorIdOption = None,
    baseline: BaselineOption = None,
    **options: Any,
) -> None:
    """Identify the fault vector from a measured (or simulated) quadrature current.

    Exit status 0 with a diagnosis (verdict "fits"), 4 with a doubtful one (verdict "doubtful":
    the faults are reported, each reason a warning), 3 when the monitor cannot explain the
    recording (verdict "does not fit": no faults are reported), 2 for bad input (nothing run).
    """
    import json

    from ..io import atomic_path

    run_identify = _imported_identify()

    settings = settings_from_options(options)
    if baseline is not None:  # its files stand for these options: refused beside it, or missing, now
        from ..baseline import baseline_inputs

        given = {"--params": params, "--calibration": calibration, "--uq-calibration": uq_calibration,
                 "--detection": detection}  # fmt: skip
        files = baseline_inputs(baseline, **given)
        if files["table_skipped"] is not None:  # slower, not less right: a note, not a warning
            err.print(f"emaphm: note: the search starts uniform, not from the nameplate's start table: "
                      f"{files['table_skipped']}", soft_wrap=True)  # fmt: skip
    truth, thresholds = _checked_inputs(
        true_faults=true_faults, reference=reference, map_file=map_file, uncertainty=settings.uncertainty,
        uq_calibration=uq_calibration, output=output, report=report, calibration=calibration, params=params,
        detection=detection,
    )  # fmt: skip
    failure = _failure_thresholds(params) if report is not None else None  # a bad table: refused now
    if baseline is not None:
        params, thresholds = files["params"], files["thresholds"]  # for the report
    with progress() as update:
        result = run_identify(
            truth, reference, settings=settings, calibration=calibration, uq_calibration=uq_calibration,
            params=None if baseline else params, channel_map=map_file, thresholds=None if baseline else thresholds,
            actuator_id=actuator_id, baseline=baseline,
            on_generation=lambda gen, total, best: update(
                "MCMC steps" if gen < 0 else search_progress_label(settings.optimizer), abs(gen), total
            ),
            on_progress=bracketed(update),  # a start table's build: a line at its start and end in a log
        )  # fmt: skip
    data = result.to_json()
    for warning in data["warnings"]:
        err.print(f"emaphm: warning: {warning}", soft_wrap=True)
    if output is not None:
        with atomic_path(output) as tmp:
            tmp.write_text(json.dumps(data, indent=2) + "\n")
    if report is not None:
        from ..actuator import resolve_params
        from ..report import input_provenance, write_report

        provenance = input_provenance(
            reference, truth=truth, channel_map=map_file, conversion=data["settings"].get("conversion"),
            params=params, calibration=calibration, detection=detection,
        )  # fmt: skip
        page = write_report(result, report, provenance=provenance, params=resolve_params(params),
                            thresholds=thresholds, failure_thresholds=failure)  # fmt: skip
        err.print(f"wrote the report {page}")
    if json_out:
        typer.echo(json.dumps(data))
    else:
        print_identification(data)
    if (
        data["verdict"] != "fits"
    ):  # ran, but no diagnosis, or a doubtful one: a script must not take it for sure
        raise typer.Exit(3 if data["verdict"] == "does not fit" else 4)


# the settings' options (`IdentifySettings`, the one list of them) after the inputs, in its order
with_settings_options(identify)


def _failure_thresholds(params: Path | None) -> dict[str, float] | None:
    """The failure thresholds of the actuator file's ``[thresholds]`` table (None: no file, or no table)."""
    if params is None:
        return None
    from ..actuator import load_thresholds

    return load_thresholds(params) or None


def _checked_inputs(
    *, true_faults: str | None, reference: Path | None, map_file: Path | None, uncertainty: str,
    uq_calibration: Path | None, output: Path | None, report: Path | None, calibration: Path | None,
    params: Path | None, detection: Path | None = None,
) -> tuple[Any, dict[str, float] | None]:  # fmt: skip
    """Every check of `identify`'s inputs and files, before the work (the settings are checked
    when made, first): the truth or None, and the detection thresholds of --detection or None. The
    input files, the output paths (none may be one of the files read), the detection thresholds
    and the interval calibration.
    """
    from ..faults import parse_faults
    from ..io import check_output_path, check_trace_path

    if (true_faults is None) == (reference is None):
        raise InputError("give exactly one of --true-faults or --reference")
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
            output,
            suffixes=(".json",),
            inputs=(reference, calibration, uq_calibration, params, map_file, detection),
        )
    if report is not None:
        from ..report import check_report_dir

        check_report_dir(report)
    thresholds = None
    if detection is not None:
        from ..identification.detection import load_thresholds

        thresholds = dict(load_thresholds(detection)["thresholds"])  # a bad file: refused before the work
    if uncertainty == "none" and uq_calibration is not None:
        raise InputError("--uq-calibration needs --uncertainty laplace or mcmc")
    if uncertainty != "none":
        from ..identification.uncertainty import load_factors

        load_factors(uq_calibration)  # a bad file: refused before the work
    return truth, thresholds


def _imported_identify() -> Any:
    """`api.identify`, imported; then the collector settled (`emaphm._gc.settled`: the imports'
    objects frozen out of later collections, the thresholds back)."""
    from .._gc import settled
    from .._lean_numba import import_numba
    from .._threads import runtime_meanwhile

    import_numba()  # without what its import loads for nothing here (`emaphm._lean_numba`)
    runtime_meanwhile()  # numba's runtime compiled while the rest imports (`emaphm._threads`)
    from ..identification.api import identify

    settled()
    return identify
