"""Options that several commands share: their help texts and typer types.

A command writes ``params: ParamsOption = None`` for the option every command spells the same way;
an option only one command has stays in that command's module.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..choices import COMMAND_NAMES, OPTIMIZERS

__all__ = [
    "CALIBRATION_HELP",
    "COMMANDS_TEXT",
    "MONITOR_HELP",
    "PARAMS_HELP",
    "CalibrationOption",
    "MonitorOption",
    "OptimizerOption",
    "ParamsNeedCalibrationOption",
    "ParamsOption",
    "WorkersOption",
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
