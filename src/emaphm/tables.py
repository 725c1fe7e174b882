"""The per-fault table of a diagnosis, shared by ``emaphm identify`` and ``emaphm demo``."""

from __future__ import annotations

from typing import Any

from rich.table import Table

__all__ = ["fault_table"]


def fault_table(data: dict[str, Any], title: str) -> Table:
    """One row per fault of an identification's JSON (`IdentificationResult.to_json`): its value,
    the ± half-width, interval and flags of its 90 % interval when there is one, the true value
    when known, and its verdict (present / absent / cannot tell; "-" when the monitor does not
    explain the recording)."""
    from .identification.uncertainty import half_widths

    intervals = data["ci90_low"] is not None
    table = Table(title=title)
    columns = ["fault", "identified"]
    if intervals:
        columns += ["± half-width", "90 % interval", "flags"]
        half = half_widths(data["ci90_low"], data["ci90_high"])
    if data["truth"] is not None:
        columns.append("true")
    columns.append("verdict")
    for name in columns:
        table.add_column(name, justify="left" if name in ("fault", "flags", "verdict") else "right")
    verdicts = data.get("fault_verdicts") or {}
    for i, name in enumerate(data["fault_names"]):
        row = [f"k{i + 1} {name}", f"{data['estimate'][i]:.4f}"]
        if intervals:
            lo, hi = data["ci90_low"][i], data["ci90_high"][i]
            whole = name == "eccentricity_phase" and (lo, hi) == (0.0, 1.0)
            row += [
                f"{half[i]:.4f}",
                "whole circle" if whole else f"[{lo:.4f}, {hi:.4f}]",
                " ".join(data["uq_flags"][i]),
            ]
        if data["truth"] is not None:
            row.append(f"{data['truth'][i]:.4f}")
        if data["verdict"] != "fits":
            row.append("-")
        elif verdicts:
            row.append(verdicts.get(name, "(direction)"))
        else:
            row.append("present" if name in data["detected"] else "-")
        table.add_row(*row)
    return table
