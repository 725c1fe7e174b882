"""One actuator's line of the fleet (`fleet`): its latest diagnosis, its worst fault against its
failure threshold, its first-failure RUL, its remaining share of the inspection interval and colour
(the rules are `fleet`'s module docstring)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..errors import InputError
from ..failure import FAULTS, PLACEHOLDER_THRESHOLDS
from .fleet_series import series
from .measurements import USED_VERDICTS, parsed
from .rul import rul_of_rows
from .usage import due, interval_in_flights, rates

__all__ = ["BANDS", "COLOURS", "colour_of", "entry", "thresholds_of"]

COLOURS = ("red", "orange", "yellow", "green")
# remaining share of the inspection interval: red <= 0 < orange <= 0.25 < yellow <= 0.5 < green
BANDS = (0.0, 0.25, 0.5)


def colour_of(remaining: float | None) -> str:
    """The colour of a remaining share of the inspection interval (None: green, nothing predicted)."""
    if remaining is None:
        return "green"
    for colour, edge in zip(COLOURS, BANDS, strict=False):
        if remaining <= edge:
            return colour
    return "green"


def thresholds_of(
    row: dict[str, Any], given: dict[str, float] | None, own: dict[str | None, dict[str, float]]
) -> dict[str, float]:
    """The thresholds that apply to an actuator: those given, over its actuator file's (its latest
    row's ``params`` setting, read once per file), over none (the placeholders)."""
    path = (parsed(row, "settings") or {}).get("params")
    if path not in own:
        own[path] = {}
        if path is not None:
            from ..actuator import load_thresholds

            try:
                own[path] = load_thresholds(path)
            except (InputError, OSError):
                own[path] = {}  # a file moved since the campaign ran: the placeholders
    return {**own[path], **(given or {})}


def _shares(row: dict[str, Any], limits: dict[str, float]) -> dict[str, dict[str, Any]]:
    """Each fault of one diagnosis: its value, its share of its failure threshold and its verdict."""
    verdicts = parsed(row, "fault_verdicts") or {}
    out = {}
    for name, (column, _, healthy) in FAULTS.items():
        value = row.get(column)
        if value is None or not math.isfinite(value):
            continue
        threshold = limits.get(name, PLACEHOLDER_THRESHOLDS[name])
        out[name] = {"value": round(value, 5), "share": round(abs(value - healthy) / threshold, 4),
                     "verdict": verdicts.get(name)}  # fmt: skip
    return out


def entry(
    campaign: str,
    actuator: str,
    rows: list[dict[str, Any]],
    limits: dict[str, float],
    options: dict[str, Any],
    usage: list[dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """One actuator's line of the fleet (module docstring): `rows` its diagnoses by flight, `limits`
    its failure thresholds, `options` the fleet's (interval, unit, seed, include_doubtful, charts),
    `usage` its flights' hours, cycles and dates (`usage.read_usage`)."""
    latest = rows[-1]
    sizing = next((r for r in reversed(rows) if r.get("verdict") in USED_VERDICTS), None)
    faults = _shares(sizing, limits) if sizing is not None else {}
    worst = max(faults, key=lambda n: faults[n]["share"]) if faults else None
    share = faults[worst]["share"] if worst is not None else None
    rate = rates(usage, float(latest["flight"]))
    history = any(r["flight"] >= 1 for r in rows)  # a one-off measurement has no RUL to convert
    interval = interval_in_flights(options["interval"], options["unit"], rate, actuator) if history else options["interval"]
    first, left_out, make_series = _rul(actuator, rows, limits, interval, options)
    p05 = first.get("rul_p05")
    if first.get("status") == "tracked":
        remaining, basis = (None, "rul") if p05 is None else (p05 / interval, "rul")
    else:
        remaining, basis = (None, "none") if share is None else (1.0 - share, "margin")
    if share is not None and share >= 1.0:
        remaining, basis = min(1.0 - share, remaining if remaining is not None else 0.0), "exceeded"
    colour = "yellow" if sizing is None else colour_of(remaining)
    reason = _reason(basis, worst, share, first, sizing, remaining)
    if basis in ("exceeded", "margin") and sizing is not None and sizing["verdict"] == "doubtful":
        reason += " (a doubtful diagnosis)"
    # charts: "all", or "urgent" (a large fleet: every actuator but the green ones, whose _series is
    # None: left out, the page says so), or none
    wanted = options["charts"] == "all" or (options["charts"] == "urgent" and colour != "green")
    return {
        "actuator": actuator, "campaign": campaign, "flight": latest["flight"],
        "flights": len({r["flight"] for r in rows if r["flight"] >= 1}), "verdict": latest.get("verdict"),
        "doubts": parsed(latest, "doubts") or [], "fit_nrmse": latest.get("fit_nrmse"),
        "sized_at_flight": None if sizing is None else sizing["flight"],
        "worst_fault": worst, "threshold_share": share,
        "exceeded": sorted(n for n, f in faults.items() if f["share"] >= 1.0), "faults": faults,
        "rul_p05": p05, "rul_median": first.get("rul_median"), "rul_p95": first.get("rul_p95"),
        "prob_fail_before_next_inspection": first.get("prob_fail_before_next_inspection"),
        "most_likely_fault": first.get("most_likely_fault"), "rul_status": first.get("status"),
        "remaining_share": None if remaining is None else round(remaining, 4), "remaining_basis": basis,
        "colour": colour, "reason": reason, "doubtful_left_out": left_out, "due": due(first, rate, options["unit"]),
        "report": None, "_series": make_series() if wanted else (None if options["charts"] else {}),
        "_latest": latest if wanted else None,  # for its diagnosis page (`fleet_diagnosis`)
    }  # fmt: skip


def _rul(
    actuator: str,
    rows: list[dict[str, Any]],
    limits: dict[str, float],
    interval: float,
    options: dict[str, Any],
) -> tuple[dict[str, Any], int, Callable[[], dict[str, Any]]]:
    """The first failure's RUL of an actuator's history (`rul.rul_of_rows`; {"status": why not}
    when there is none), the doubtful diagnoses left out and what makes each tracked fault's
    chart series (`fleet_series.series`, called only for an entry that gets a chart)."""
    flights = [r for r in rows if r["flight"] >= 1]
    if not flights:
        return {"status": "one-off measurement"}, 0, dict
    try:
        report = rul_of_rows(flights, actuator, thresholds=limits, inspection_interval=interval,
                             seed=options["seed"], include_doubtful=options["include_doubtful"])  # fmt: skip
    except InputError as exc:  # all diagnoses doubtful
        return {"status": str(exc)}, sum(r.get("verdict") == "doubtful" for r in flights), dict
    include = options["include_doubtful"]
    return report["first_failure"], report["doubtful_left_out"], lambda: series(flights, report, include)


def _reason(
    basis: str,
    worst: str | None,
    share: float | None,
    first: dict[str, Any],
    sizing: dict[str, Any] | None,
    remaining: float | None,
) -> str:
    """One line: why the actuator has its colour."""
    if sizing is None:
        return "no diagnosis sizes its faults (the recordings do not fit): re-measure"
    if basis == "exceeded":
        return f"{worst} at {100 * (share or 0):.0f} % of its threshold"
    if basis == "rul":
        p05 = first.get("rul_p05")
        if p05 is None:
            return "no failure predicted (the 5 % RUL is beyond the trend's reach)"
        return (f"first failure ({first.get('most_likely_fault') or 'a fault'}) in {p05:.1f} flights at 5 %: "
                f"{100 * (remaining or 0.0):.0f} % of the inspection interval")  # fmt: skip
    if worst is None:
        return "no fault sized"
    return f"no trend yet ({first.get('status')}); {worst} at {100 * (share or 0):.0f} % of its threshold"
