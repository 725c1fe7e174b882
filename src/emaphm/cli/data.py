"""`emaphm convert` (a rig's recording into a reference trace) and `emaphm inspect` (what a recording holds)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .options import ParamsOption
from .output import err, status
from .render import print_inspection

__all__ = ["convert", "inspect_command"]


def convert(
    source: Annotated[
        Path, typer.Argument(help="A rig's recording: CSV, HDF5, MATLAB .mat (v5, v7.3) or Parquet.")
    ],
    map_file: Annotated[
        Path, typer.Option("--map", help="Channel map (TOML): which column is which signal, in which unit.")
    ],
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Reference trace to write: .h5 or .csv (+ .csv.json).")
    ],
    params: ParamsOption = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the conversion report as one JSON object.")
    ] = False,
) -> None:
    """Convert a recording into a reference trace on the model grid (SI, i_q, with its provenance)."""
    import json

    from ..actuator import resolve_params
    from ..io import TRACE_SUFFIXES, check_output_path
    from ..measured import ChannelMap, load_measurement, to_reference, write_reference

    check_output_path(output, suffixes=TRACE_SUFFIXES, inputs=(source, map_file, params))
    cmap = ChannelMap.load(map_file)
    actuator = resolve_params(params)
    with status(f"converting {source}"):
        ref = to_reference(load_measurement(source, cmap), actuator)
    write_reference(ref, output)
    report = ref.report
    if json_out:
        typer.echo(json.dumps(report, default=str))
    for warning in report.get("warnings", []):
        err.print(f"emaphm: warning: {warning}", soft_wrap=True)
    angle = report.get("angle") or {}
    if angle.get("offset_deg") is not None:
        err.print(f"angle offset {angle['offset_deg']:.2f} deg ({angle.get('offset_method', '')})")
    used = report["segments"]["used"]
    err.print(
        f"wrote {output} ({report['grid']['samples']} samples at {report['grid']['f_s']:g} Hz, "
        f"{used[0]:g}..{used[1]:g} s of the record)"
    )


def inspect_command(
    source: Annotated[Path, typer.Argument(help="A recording (CSV, HDF5, MATLAB .mat, Parquet).")],
    map_file: Annotated[
        Path | None, typer.Option("--map", help="Channel map (TOML) to check it against.")
    ] = None,
    params: ParamsOption = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print what was found as one JSON object.")
    ] = False,
) -> None:
    """What a recording holds (channels, rates, duration, ranges, saturation, problems); exit 0 if usable, 2 if not."""
    import json

    from ..actuator import resolve_params
    from ..measured import ChannelMap, inspect_file

    cmap = ChannelMap.load(map_file) if map_file is not None else None
    info = inspect_file(source, cmap, resolve_params(params))
    if json_out:
        typer.echo(json.dumps(info, default=str))
    else:
        print_inspection(info)
    if not info["usable"]:
        raise typer.Exit(2)
