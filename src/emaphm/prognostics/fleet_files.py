"""The files of ``emaphm fleet --output DIR``: fleet.json, fleet.csv (for a maintenance system) and
index.html (`emaphm.fleet_page`), each written whole or not at all (`atomic.atomic_path`)."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import Any

from ..atomic import atomic_path

__all__ = ["CSV_COLUMNS", "public", "write_fleet"]

CSV_COLUMNS = (
    "actuator", "campaign", "colour", "remaining_share", "verdict", "worst_fault", "threshold_share", "exceeded",
    "rul_p05", "rul_median", "rul_p95", "prob_fail_before_next_inspection", "most_likely_fault", "flight",
    "flights", "doubtful_left_out", "reason",
)  # fmt: skip
DUE_COLUMNS = ("unit", "rul_p05", "rul_median", "date_p05", "date_median")


def public(report: dict[str, Any]) -> dict[str, Any]:
    """The report without its private keys (each entry's ``_series``, the charts' data)."""
    return {
        **report,
        "actuators": [{k: v for k, v in e.items() if not k.startswith("_")} for e in report["actuators"]],
    }


def _csv_row(entry: dict[str, Any]) -> list[Any]:
    row = [";".join(entry[c]) if c == "exceeded" else entry.get(c) for c in CSV_COLUMNS]
    due = entry.get("due") or {}
    return [*("" if v is None else v for v in row), *(due.get(c, "") for c in DUE_COLUMNS)]


def write_fleet(
    report: dict[str, Any], folder: str | os.PathLike[str], params: Any = None, failure: dict[str, float] | None = None
) -> Path:
    """Write fleet.json, fleet.csv, index.html of `report` (`fleet.fleet_report`) and the latest
    diagnosis of each actuator with a chart (`fleet_diagnosis`, faults in the units of `params`)
    into `folder` (made if new); the page's path."""
    from ..fleet_diagnosis import write_diagnosis_pages
    from ..fleet_page import write_fleet_page

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    write_diagnosis_pages(report, out, params, failure)
    data = public(report)
    with atomic_path(out / "fleet.json") as tmp:
        tmp.write_text(json.dumps(data, separators=(",", ":")) + "\n", encoding="utf-8")
    with atomic_path(out / "fleet.csv") as tmp, tmp.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow([*CSV_COLUMNS, *(f"due_{c}" for c in DUE_COLUMNS)])
        writer.writerows(_csv_row(e) for e in data["actuators"])
    return write_fleet_page(report, out)
