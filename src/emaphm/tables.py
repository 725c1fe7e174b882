"""The per-fault table of a diagnosis, shared by ``emaphm identify`` and ``emaphm demo``."""

from __future__ import annotations

from typing import Any

from rich.table import Table

__all__ = ["fault_rows", "fault_table"]


def fault_rows(data: dict[str, Any]) -> tuple[list[str], list[list[str]]]:
    """The column names and the text rows of the per-fault table of an identification's JSON
    (`IdentificationResult.to_json`): one row per fault with its value, the ± half-width,
    interval and flags of its 90 % interval when there is one, the true value when known, and
    its verdict (present / absent / cannot tell; "-" when the monitor does not explain the
    recording)."""
    from .identification.uncertainty import half_widths

    intervals = data["ci90_low"] is not None
    columns = ["fault", "identified"]
    if intervals:
        columns += ["± half-width", "90 % interval", "flags"]
        half = half_widths(data["ci90_low"], data["ci90_high"])
    if data["truth"] is not None:
        columns.append("true")
    columns.append("verdict")
    verdicts = data.get("fault_verdicts") or {}
    rows = []
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
        if data["verdict"] == "does not fit":
            row.append("-")
        elif verdicts:
            row.append(verdicts.get(name, "(direction)"))
        else:
            row.append("present" if name in data["detected"] else "-")
        rows.append(row)
    return columns, rows


def fault_table(data: dict[str, Any], title: str) -> Table:
    """The per-fault table (`fault_rows`) as a rich table."""
    columns, rows = fault_rows(data)
    table = Table(title=title)
    for name in columns:
        table.add_column(name, justify="left" if name in ("fault", "flags", "verdict") else "right")
    for row in rows:
        table.add_row(*row)
    return table
