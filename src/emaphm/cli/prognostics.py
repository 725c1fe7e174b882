"""`emaphm rul`: the remaining useful life of an actuator from its stored diagnoses."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError
from .options import IncludeDoubtfulOption, UnitOption
from .output import err
from .render import print_rul

__all__ = ["rul"]


def rul(
    store: Annotated[
        Path, typer.Argument(help="Folder of a campaign's results store (emaphm campaign run --out).")
    ],
    actuator: Annotated[str, typer.Option(help="The actuator's id in the store.")],
    campaign: Annotated[
        str | None, typer.Option(help="The campaign, when the actuator is in several.")
    ] = None,
    at_flight: Annotated[
        int | None, typer.Option(help="Predict as of this flight (default: the last stored).")
    ] = None,
    threshold: Annotated[
        list[str] | None,
        typer.Option(
            help="A failure threshold FAULT=DISTANCE from healthy, e.g. friction=0.45 (repeatable)."
        ),
    ] = None,
    params: Annotated[
        Path | None,
        typer.Option("--params", help="Actuator file whose [thresholds] table gives the thresholds."),
    ] = None,
    inspection_interval: Annotated[
        float, typer.Option(help="Flights to the next inspection, for the probability of failing before it.")
    ] = 10.0,
    unit: UnitOption = "flights",
    estimator: Annotated[
        str,
        typer.Option(
            help="trend: weighted regression per fault (no dependency); ukf: ProgPy's unscented "
            "Kalman filter (pip install 'emaphm[progpy]')."
        ),
    ] = "trend",
    include_doubtful: IncludeDoubtfulOption = False,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write the prognosis figure here (.png).")] = None,
) -> None:
    """Remaining useful life of an actuator from its history of diagnoses: per fault and for the first failure."""
    import json

    from ..io import check_output_path
    from ..prognostics.rul import parse_thresholds, rul_report

    if plot is not None:
        check_output_path(plot, suffixes=(".png",), option="--plot")
    if not inspection_interval > 0:
        raise InputError(f"--inspection-interval must be > 0 {unit}, got {inspection_interval}")
    given: dict[str, float] = {}
    if params is not None:
        from ..actuator import load_thresholds

        given.update(load_thresholds(params))
    given.update(parse_thresholds(threshold))
    report = rul_report(store, actuator, campaign=campaign, at_flight=at_flight, thresholds=given,
                        inspection_interval=inspection_interval, estimator=estimator, unit=unit,
                        include_doubtful=include_doubtful)  # fmt: skip
    data = {k: v for k, v in report.items() if not k.startswith("_")}
    if plot is not None:
        from ..plots import plot_rul

        plot_rul(report, plot, params=params)  # the actuator file's params, when given
        err.print(f"wrote {plot}")
    if json_out:
        typer.echo(json.dumps(data))
        return
    print_rul(data)
