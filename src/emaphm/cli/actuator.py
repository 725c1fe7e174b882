"""`emaphm params` (the actuator file: write, check, show) and `emaphm thresholds` (failure thresholds from requirements)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError
from .options import COMMANDS_TEXT, ParamsOption
from .output import err, progress
from .render import print_params, print_thresholds

__all__ = ["params_command", "thresholds"]


def params_command(
    file: Annotated[Path | None, typer.Argument(help="An actuator file to check.")] = None,
    template: Annotated[
        bool,
        typer.Option(
            "--template",
            help="Print a complete actuator file: every parameter with its unit and meaning "
            "(the nominal values, or FILE's).",
        ),
    ] = False,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the parameters as one JSON object.")
    ] = False,
) -> None:
    """Write an actuator file (--template), or check one and show its parameters and their hash."""
    import json

    from ..actuator import resolve_params
    from ..calibration import params_hash

    if template and json_out:
        raise InputError("give --template or --json, not both")
    actuator = resolve_params(file)
    if template:
        from ..actuator import params_template

        typer.echo(params_template(actuator), nl=False)
        return
    if json_out:
        typer.echo(json.dumps({"params": actuator.to_dict(), "params_hash": params_hash(actuator)}))
        return
    print_params(actuator, str(file) if file is not None else "the nominal actuator")


def thresholds(
    require: Annotated[
        list[str] | None,
        typer.Option(
            help="A requirement KIND=LIMIT (repeatable): tracking=0.5deg (max |θ_u − θ_cmd|), "
            "tracking_rms=0.2deg, current=I_max (or 0.9I_max, 8A: the current demand), free_play=1.5mrad "
            "(total at the surface). A bare number is SI."
        ),
    ] = None,
    params: ParamsOption = None,
    command: Annotated[str, typer.Option(help=f"Reference command: {COMMANDS_TEXT}.")] = "chirp",
    fault: Annotated[
        list[str] | None, typer.Option(help="Derive only this fault (repeatable); default: all.")
    ] = None,
    resolution: Annotated[
        float, typer.Option(help="Width of the final bisection interval, in fault units.")
    ] = 0.005,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help="Write the [thresholds] table (TOML) here, to paste into the actuator file.",
        ),
    ] = None,
) -> None:
    """Failure thresholds per fault from the HF twin and requirements: the smallest distance from healthy that breaks one."""
    import json

    from ..actuator import resolve_params
    from ..io import atomic_path, check_output_path
    from ..prognostics.thresholds import derive_thresholds, parse_requirement, thresholds_toml

    if not require:
        raise InputError(
            "give at least one --require KIND=LIMIT, e.g. --require tracking=1.6deg --require current=I_max"
        )
    if output is not None:
        check_output_path(output, suffixes=(".toml",), inputs=(params,))
    actuator = resolve_params(params)
    requirements = [parse_requirement(text, params=actuator) for text in require]
    with progress() as update:
        result = derive_thresholds(
            requirements, params=actuator, command=command, faults=fault, resolution=resolution,
            progress=lambda done, total: update("HF simulations", done, total),
        )  # fmt: skip
    for warning in result["warnings"]:
        err.print(f"emaphm: warning: {warning}", soft_wrap=True, markup=False)
    if output is not None:
        with atomic_path(output) as tmp:
            tmp.write_text(thresholds_toml(result), encoding="utf-8")
        err.print(f"wrote {output}: paste its [thresholds] table into the actuator file", markup=False)
    if json_out:
        typer.echo(json.dumps(result))
        return
    print_thresholds(result, str(params) if params is not None else "the nominal actuator")
