"""`emaphm fleet`: every actuator of a results store ranked by urgency (issue 35)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError
from .options import IncludeDoubtfulOption, UnitOption
from .output import err

__all__ = ["fleet"]


def fleet(
    store: Annotated[
        Path, typer.Argument(help="Folder of a campaign's results store (emaphm campaign run --out).")
    ],
    campaign: Annotated[str | None, typer.Option(help="Only this campaign's actuators.")] = None,
    threshold: Annotated[
        list[str] | None,
        typer.Option(help="A failure threshold FAULT=DISTANCE from healthy for every actuator (repeatable)."),
    ] = None,
    params: Annotated[
        Path | None,
        typer.Option(
            "--params",
            help="Actuator file whose [thresholds] apply to every actuator (default: each actuator's own "
            "file from its campaign, else the placeholders).",
        ),
    ] = None,
    inspection_interval: Annotated[
        float, typer.Option(help="Flights (or --unit) to the next inspection: the colours are shares of it.")
    ] = 10.0,
    unit: UnitOption = "flights",
    include_doubtful: IncludeDoubtfulOption = False,
    seed: Annotated[int, typer.Option(help="Seed of the RUL draws (as emaphm rul).")] = 0,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output", "-o", help="Write the fleet page here: index.html, fleet.json and fleet.csv."
        ),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help='Print {"actuators": [...]} as one JSON object.')
    ] = False,
    top: Annotated[int, typer.Option(help="Rows of the table printed (the most urgent first).")] = 30,
) -> None:
    """Every actuator of a store, most urgent first: latest verdict, worst fault against its failure
    threshold, first-failure RUL (5-95 %), and a colour by the share of the inspection interval left
    (red <= 0 %, orange <= 25 %, yellow <= 50 %, green above)."""
    from ..prognostics.fleet import fleet_report
    from ..prognostics.fleet_files import public, write_fleet

    if not inspection_interval > 0:
        raise InputError(f"--inspection-interval must be > 0 {unit}, got {inspection_interval}")
    if top < 0:
        raise InputError(f"--top must be >= 0, got {top}")
    if not store.is_dir():
        raise InputError(f"{store}: no such results store (a folder made by 'emaphm campaign run --out')")
    if output is not None:
        from ..report import check_report_dir

        check_report_dir(output, option="--output")
    given = _thresholds(params, threshold)
    _compact(store)
    report = fleet_report(store, campaign=campaign, thresholds=given, inspection_interval=inspection_interval,
                          seed=seed, include_doubtful=include_doubtful, charts=output is not None, unit=unit,
                          progress=_progress())  # fmt: skip
    if output is not None:
        from ..actuator import resolve_params

        page = write_fleet(report, output, params=resolve_params(params) if params is not None else None,
                           failure=given)  # fmt: skip
        err.print(f"wrote the fleet page {page}")
    if json_out:
        import json

        typer.echo(json.dumps(public(report)))
        return
    from .render_fleet import print_fleet

    print_fleet(public(report), top)


def _thresholds(params: Path | None, items: list[str] | None) -> dict[str, float] | None:
    from ..failure import parse_thresholds

    given: dict[str, float] = {}
    if params is not None:
        from ..actuator import load_thresholds

        given.update(load_thresholds(params))
    given.update(parse_thresholds(items))
    return given or None


def _progress():  # type: ignore[no-untyped-def]
    """A line on stderr now and then for a large store (none for a small one)."""
    import time

    start = time.perf_counter()

    def report(done: int, total: int) -> None:
        if total >= 2000 and done < total:
            err.print(f"fleet: {done} of {total} actuators ({time.perf_counter() - start:.0f} s)")

    return report


def _compact(store: Path) -> None:
    """Compact a store of many loose part files first (`ResultStore.compact`, as ``campaign run``
    does at its end): 10 000 actuators' folders take ~10 s to read each time, one file 0.1 s."""
    from ..campaign.store import ResultStore

    results = ResultStore(store)
    loose = results.loose_parts()
    if loose >= 64:
        err.print(
            f"compacting the store's {loose} part files into one per campaign (once: later reads are fast)"
        )
        try:
            results.compact()
        except OSError as exc:  # a store we may not write: read it as it is
            err.print(f"not compacted ({exc}); reading the {loose} part files as they are")
