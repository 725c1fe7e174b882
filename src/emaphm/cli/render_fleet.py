"""The printed form of ``emaphm fleet``: the most urgent actuators as a table, then the counts."""

from __future__ import annotations

from typing import Any

from .output import stdout_console

__all__ = ["due_text", "print_fleet"]

STYLE = {"red": "bold red", "orange": "dark_orange", "yellow": "yellow", "green": "green"}


def _num(v: Any, fmt: str = "{:.1f}") -> str:
    return "-" if v is None else fmt.format(v)


def print_fleet(data: dict[str, Any], top: int) -> None:
    """The first `top` actuators of `data` (`fleet.fleet_report`, urgency order) and the counts."""
    from rich.table import Table

    entries = data["actuators"]
    unit = data.get("unit", "flights")
    table = Table(title=f"fleet of {len(entries)} actuators, most urgent first (inspection every "
                        f"{data['inspection_interval']:g} {unit})")  # fmt: skip
    dues = any(e.get("due") for e in entries[:top])
    for column in ("", "actuator", "verdict", "worst fault", "of threshold", "RUL 5 / 50 / 95 % (flights)",
                   *(("due at 5 %",) if dues else ()), "P(fail before next)", "why"):  # fmt: skip
        table.add_column(column, justify="right" if column.startswith(("of", "RUL", "P(")) else "left")
    for e in entries[:top]:
        rul = " / ".join(_num(e[k]) for k in ("rul_p05", "rul_median", "rul_p95"))
        table.add_row(
            f"[{STYLE[e['colour']]}]{e['colour']}[/]", e["actuator"], e["verdict"], e["worst_fault"] or "-",
            _num(e["threshold_share"], "{:.0%}"), rul, *((_due_short(e.get("due")),) if dues else ()),
            _num(e["prob_fail_before_next_inspection"], "{:.2f}"), e["reason"],
        )  # fmt: skip
    out = stdout_console()
    out.print(table)
    if len(entries) > top:
        out.print(
            f"... {len(entries) - top} more (--top N, --json, or --output DIR for the page and the CSV)"
        )
    counts = data["counts"]
    out.print(
        ", ".join(f"{counts[c]} {c}" for c in ("red", "orange", "yellow", "green"))
        + f"; {counts['doubtful']} latest diagnoses doubtful, {counts['does not fit']} not fitting"
    )
    placeholders = [n for n, t in data["thresholds"].items() if t["placeholder"]]
    if placeholders:
        out.print(
            "failure thresholds are placeholders (not airworthiness limits) where no actuator file gives them: "
            "pass --params FILE or --threshold FAULT=DISTANCE"
        )


def _due_short(due: dict[str, Any] | None) -> str:
    """The 5 % RUL in hours or cycles and its date, for a table cell."""
    if not due:
        return "-"
    amount = f"{due['rul_p05']:.0f} {due['unit']}" if due.get("unit") and due.get("rul_p05") is not None else ""
    date = due.get("date_p05") or ""
    return " ".join(p for p in (amount, f"({date})" if amount and date else date) if p) or "beyond"


def due_text(due: dict[str, Any]) -> str:
    """The first failure's RUL in hours or cycles and its dates, in one line (`prognostics.usage.due`)."""
    parts = []
    if due.get("unit"):
        parts.append(f"{due['rul_p05'] if due['rul_p05'] is not None else 'beyond'} {due['unit']} at 5 %, "
                     f"{due['rul_median'] if due['rul_median'] is not None else 'beyond'} median")  # fmt: skip
    if due.get("date_p05") or due.get("date_median"):
        parts.append(f"on {due.get('date_p05') or 'no date'} at 5 % ({due.get('date_median') or 'beyond'} median)")
    return "; ".join(parts) or "no usage recorded"
