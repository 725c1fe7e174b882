"""The printed form of ``emaphm campaign status``: jobs done, failed and missing per actuator."""

from __future__ import annotations

from typing import Any

from .output import stdout_console

__all__ = ["print_campaign_status"]

STATUS_ROWS = 40  # actuators listed by campaign status


def print_campaign_status(data: dict[str, Any]) -> None:
    """`emaphm campaign status`: jobs, done, failed and missing per actuator and in all."""
    from rich.table import Table

    table = Table(title=f"campaign {data['campaign']} in {data['store']}")
    for column in ("actuator", "jobs", "done", "failed", "missing"):
        table.add_column(column, justify="left" if column == "actuator" else "right")
    # a fleet's actuators: those not done, up to STATUS_ROWS (--json has every one)
    rows = [(n, c) for n, c in data["actuators"].items() if len(data["actuators"]) <= STATUS_ROWS or c["done"] < c["jobs"]]
    for name, c in rows[:STATUS_ROWS]:
        table.add_row(name, *(str(c[k]) for k in ("jobs", "done", "failed", "missing")))
    left = len(data["actuators"]) - min(len(rows), STATUS_ROWS)
    if left:
        table.add_row(f"({left} more: --json)", "", "", "", "")
    table.add_row("all", *(str(data[k]) for k in ("jobs", "done", "failed", "missing")), style="bold")
    out_console = stdout_console()
    out_console.print(table)
    if data.get("stale"):
        out_console.print(
            f"{data['stale']} done job(s) were made by other code, packaged data or settings "
            "(another fingerprint): 'emaphm campaign run' redoes them, --keep-stale keeps them"
        )
    if data.get("waiting_for_baseline"):
        out_console.print(f"{len(data['waiting_for_baseline'])} actuator(s) wait for a baseline ('campaign run' makes it)")
    if data["other_rows"]:
        out_console.print(
            f"{data['other_rows']} stored row(s) belong to no job of this file (an older file or version)"
        )
