"""RUL in hours or cycles, and a due date, from an actuator's usage per flight (issue 35 item 4).

The store keeps each flight's cumulative hours and cycles and its date (`emaphm.campaign.usage`,
written by ``campaign run``). An actuator's rate of each is its mean per flight over the flights
recorded up to now (the last minus the first over the flights between; from 0 with one flight).
A RUL of r flights is r times the rate in hours or cycles, and is due r times the days per flight
after the latest flight's date. An inspection interval given in hours or cycles is that many
flights at the actuator's rate, for the probability of failing before it.
"""

from __future__ import annotations

import datetime as _dt
import os
from typing import Any

from ..errors import InputError

__all__ = ["UNITS", "due", "interval_in_flights", "rates", "read_usage"]

UNITS = ("flights", "hours", "cycles")


def read_usage(store: str | os.PathLike[str], campaign: str | None = None) -> dict[tuple[str, str], list[dict[str, Any]]]:
    """Each actuator's usage rows ({flight, hours, cycles, date}) by (campaign, actuator), by flight."""
    from ..campaign.store import ResultStore

    out: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for row in ResultStore(store).read_usage(campaign).to_pylist():
        out.setdefault((row["campaign"], row["actuator"]), []).append(row)
    for rows in out.values():
        rows.sort(key=lambda r: r["flight"])
    return out


def _rate(points: list[tuple[float, float]]) -> float | None:
    """Usage per flight from (flight, cumulative usage) points."""
    if not points:
        return None
    (f0, u0), (f1, u1) = points[0], points[-1]
    return (u1 - u0) / (f1 - f0) if f1 > f0 else (u1 / f1 if f1 > 0 else None)


def rates(rows: list[dict[str, Any]] | None, now: float) -> dict[str, Any]:
    """Hours, cycles and days per flight over the flights up to `now`, and the date of flight `now`
    (None where not recorded)."""
    rows = [r for r in rows or [] if r["flight"] <= now]
    out: dict[str, Any] = {}
    for key in ("hours", "cycles"):
        out[key] = _rate([(float(r["flight"]), float(r[key])) for r in rows if r[key] is not None])
    dated = [(float(r["flight"]), _dt.date.fromisoformat(r["date"]).toordinal()) for r in rows if r["date"]]
    out["days"] = _rate([(f, float(d - dated[0][1])) for f, d in dated]) if len(dated) >= 2 else None
    out["date"] = None
    if dated:
        f_last, d_last = dated[-1]
        days = out["days"] or 0.0
        out["date"] = _dt.date.fromordinal(round(d_last + days * (now - f_last)))
    return out


def interval_in_flights(interval: float, unit: str, rate: dict[str, Any], actuator: str) -> float:
    """An inspection interval given in `unit` as flights at this actuator's rate; `InputError` when
    the actuator has no such usage recorded, or none accrues."""
    if unit == "flights":
        return interval
    r = rate.get(unit)
    if r is None:
        raise InputError(
            f"actuator {actuator!r} has no {unit} recorded: give its usage in the campaign (usage = "
            f"{{{unit} = ...}}) and run it again, or use --unit flights"
        )
    if not r > 0:
        raise InputError(f"actuator {actuator!r}: no {unit} accrue over its recorded flights")
    return interval / r


def due(first: dict[str, Any], rate: dict[str, Any], unit: str) -> dict[str, Any] | None:
    """The first failure's RUL (5 %, median) in `unit` (or, for flights, the first of hours or
    cycles recorded) and the dates they fall on; None when no usage is recorded."""
    unit = unit if unit != "flights" else next((u for u in ("hours", "cycles") if rate.get(u)), "flights")
    r = rate.get(unit) if unit != "flights" else None
    if r is None and rate.get("date") is None:
        return None
    out: dict[str, Any] = {"unit": unit if r is not None else None}
    for q in ("rul_p05", "rul_median"):
        flights = first.get(q)
        out[q] = None if flights is None or r is None else round(flights * r, 3)
        key = "date_" + q.removeprefix("rul_")
        out[key] = None
        if flights is not None and rate.get("date") is not None and rate.get("days") is not None:
            days = (rate.get("days") or 0.0) * flights
            out[key] = (rate["date"] + _dt.timedelta(days=round(days))).isoformat()
    return out
