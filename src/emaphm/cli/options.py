"""Options that several commands share: their help texts and typer types.

A command writes ``params: ParamsOption = None`` for the option every command spells the same way;
an option only one command has stays in that command's module.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from ..choices import COMMAND_NAMES, OPTIMIZERS

__all__ = [
    "CALIBRATION_HELP",
    "COMMANDS_TEXT",
    "MONITOR_HELP",
    "PARAMS_HELP",
    "CalibrationOption",
    "IncludeDoubtfulOption",
    "MonitorOption",
    "OptimizerOption",
    "ParamsNeedCalibrationOption",
    "ParamsOption",
    "UnitOption",
    "WorkersOption",
    "settings_from_options",
    "with_settings_options",
]

CALIBRATION_HELP = "LF calibration file from 'emaphm calibrate' (default: the packaged one)."
PARAMS_HELP = "Actuator file (TOML, from 'emaphm params --template'); default: the paper's nominal actuator."
MONITOR_HELP = (
    "Monitor model: 'default', or 'paper' (the paper's single-phase model, eqs. 1-2 alone); "
    "default: the calibration's."
)
COMMANDS_TEXT = ", ".join(COMMAND_NAMES)  # the position commands, for a help text

CalibrationOption = Annotated[Path | None, typer.Option(help=CALIBRATION_HELP)]
MonitorOption = Annotated[str | None, typer.Option(help=MONITOR_HELP)]
ParamsOption = Annotated[Path | None, typer.Option("--params", help=PARAMS_HELP)]
# a non-nominal actuator needs a calibration made for it (the monitor refuses another's)
ParamsNeedCalibrationOption = Annotated[
    Path | None, typer.Option("--params", help=PARAMS_HELP + " Needs its --calibration.")
]
OptimizerOption = Annotated[str, typer.Option(help=f"{', '.join(OPTIMIZERS[:-1])} or {OPTIMIZERS[-1]}.")]
WorkersOption = Annotated[int, typer.Option(help="Threads for the population kernel (0: all cores).")]
UnitOption = Annotated[
    str,
    typer.Option(
        help="flights, hours or cycles: the unit of --inspection-interval and of the due RUL (hours and "
        "cycles from the campaign's usage per flight)."
    ),
]  # emaphm rul, emaphm fleet
IncludeDoubtfulOption = Annotated[
    bool,
    typer.Option(
        "--include-doubtful",
        help='Track the diagnoses with verdict "doubtful" too (default: left out, and counted).',
    ),
]  # emaphm rul, emaphm fleet


# the CLI type of each `IdentifySettings` field type (the error corner is text: "auto", "off" or Hz)
_CLI_TYPES: dict[str, Any] = {
    "str": str, "int": int, "bool": bool, "int | None": int | None, "str | None": str | None,
    "float": float, "float | str | None": str,
}  # fmt: skip


def with_settings_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Give `command` (whose settings arrive in ``**options``) one option per `IdentifySettings`
    field shown on the command line, with its flag, default and help: the options are listed once,
    in the settings, and typer reads them from the signature made here."""
    import dataclasses
    import inspect

    from ..identification.settings import IdentifySettings

    signature = inspect.signature(command, eval_str=True)
    inputs = [p for p in signature.parameters.values() if p.kind is not p.VAR_KEYWORD]
    added = []
    for f in dataclasses.fields(IdentifySettings):
        if not f.metadata["cli"]:
            continue
        flag = f.metadata["flag"] or "--" + f.name.replace("_", "-")
        annotation = Annotated[_CLI_TYPES[str(f.type)], typer.Option(flag, help=f.metadata["help"])]
        added.append(inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=f.default, annotation=annotation))
    command.__signature__ = signature.replace(parameters=[*inputs, *added])  # type: ignore[attr-defined]
    command.__annotations__ = {**{p.name: p.annotation for p in [*inputs, *added]}, "return": None}
    return command


def settings_from_options(options: dict[str, Any]) -> Any:
    """The `IdentifySettings` of the command line's settings options; a refusal names the option
    as typed (``unknown --last-stage 'fast'``, ``--error-corner must be ...``)."""
    from ..errors import InputError
    from ..identification.settings import IdentifySettings

    try:
        return IdentifySettings.from_mapping(options, where="identify")
    except InputError as exc:
        text = str(exc)
        for name in options:
            flag = "--" + name.replace("_", "-")
            for before in (f"unknown {name} ", f"{name} must "):
                if text.startswith(before):
                    raise InputError(text.replace(name, flag, 1)) from None
        raise
