"""An actuator's usage over its flights: hours, cycles and dates (issue 35 item 4).

A campaign's ``[[actuator]]`` or ``[[fleet]]`` table may carry a ``usage`` table::

    usage = { hours = 2.5, cycles = 1, first_date = 2026-01-05, days = 3 }      # per flight
    usage = { hours = [2.1, 4.4, 6.0], dates = [2026-01-05, 2026-01-09, 2026-01-12] }  # at each flight

``hours`` and ``cycles``: a number is the usage of each flight (flight n has used n times it), a
list the cumulative usage at flights 1..N (non-decreasing, one per flight). ``dates``: the date of
each flight (TOML dates or "YYYY-MM-DD"), or ``first_date`` and ``days`` (days between flights).
Usage does not change a diagnosis: it is not in the job keys. ``campaign run`` writes the usage of
every flight of the file into the store (`store.ResultStore.write_usage`) on each run, so usage
given later reaches the flights already done; ``emaphm fleet`` and ``emaphm rul`` read it there
to give RUL in hours or cycles and a due date (`emaphm.prognostics.usage`).
"""

from __future__ import annotations

import datetime as _dt
import itertools
import math
from typing import Any

from ..errors import InputError

__all__ = ["USAGE_KEYS", "flight_usages", "parse_usage"]

USAGE_KEYS = {"hours", "cycles", "dates", "first_date", "days"}


def _date(value: Any, where: str) -> _dt.date:
    if isinstance(value, _dt.datetime):
        return value.date()
    if isinstance(value, _dt.date):
        return value
    try:
        return _dt.date.fromisoformat(str(value))
    except ValueError:
        raise InputError(f"{where}: usage date {value!r} is not a date (YYYY-MM-DD)") from None


def _amount(value: Any, key: str, where: str) -> float | list[float]:
    def number(v: Any) -> bool:
        return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v >= 0

    if number(value) and value > 0:
        return float(value)
    if isinstance(value, list) and value and all(number(v) for v in value):
        if any(b < a for a, b in itertools.pairwise(value)):
            raise InputError(f"{where}: usage {key} at each flight must not decrease (cumulative), got {value!r}")
        return [float(v) for v in value]
    raise InputError(f"{where}: usage {key} must be a number > 0 (per flight) or a list (at each flight), got {value!r}")


def parse_usage(value: Any, where: str) -> dict[str, Any]:
    """The checked ``usage`` table of an actuator or fleet (module docstring); {} when absent."""
    if value is None:
        return {}
    if not isinstance(value, dict) or not value:
        raise InputError(f"{where}: usage must be a table of hours, cycles, dates or first_date and days")
    unknown = sorted(set(value) - USAGE_KEYS)
    if unknown:
        raise InputError(f"{where}: usage: unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(USAGE_KEYS))}")
    out: dict[str, Any] = {k: _amount(value[k], k, where) for k in ("hours", "cycles") if k in value}
    if "dates" in value:
        if "first_date" in value or "days" in value:
            raise InputError(f"{where}: usage: give dates, or first_date and days, not both")
        dates = value["dates"]
        if not isinstance(dates, list) or not dates:
            raise InputError(f"{where}: usage dates must be a list of dates, one per flight")
        out["dates"] = [_date(d, where) for d in dates]
        if any(b < a for a, b in itertools.pairwise(out["dates"])):
            raise InputError(f"{where}: usage dates must not go back in time")
    elif "first_date" in value or "days" in value:
        days = value.get("days")
        if "first_date" not in value or isinstance(days, bool) or not isinstance(days, (int, float)) or not days > 0:
            raise InputError(f"{where}: usage needs first_date and days (> 0, between flights) together")
        out["first_date"], out["days"] = _date(value["first_date"], where), float(days)
    return out


def flight_usages(usage: dict[str, Any], flights: list[int], where: str) -> list[dict[str, Any] | None]:
    """Hours, cycles (cumulative) and date of each of an actuator's `flights` (1..N; 0, a one-off
    measurement, has none) from its checked `usage`; None each without usage. `InputError` for a
    list of another length than the flights."""
    if not usage:
        return [None] * len(flights)
    n = sum(1 for f in flights if f >= 1)
    for key in ("hours", "cycles", "dates"):
        value = usage.get(key)
        if isinstance(value, list) and len(value) != n:
            raise InputError(f"{where}: usage {key} has {len(value)} values for {n} flights")
    return [None if f < 1 else _at(usage, f) for f in flights]


def _at(usage: dict[str, Any], flight: int) -> dict[str, Any]:
    out: dict[str, Any] = {"hours": None, "cycles": None, "date": None}
    for key in ("hours", "cycles"):
        value = usage.get(key)
        if value is not None:
            out[key] = value[flight - 1] if isinstance(value, list) else value * flight
    if "dates" in usage:
        out["date"] = usage["dates"][flight - 1].isoformat()
    elif "first_date" in usage:
        out["date"] = (usage["first_date"] + _dt.timedelta(days=usage["days"] * (flight - 1))).isoformat()
    return out
