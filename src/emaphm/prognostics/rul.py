"""From a history of diagnoses in a campaign store to remaining useful life (issue 12).

For one actuator of a results store (`emaphm.campaign`), each fault is tracked from its first
detection (verdict "present"): its later identifications, each with its standard deviation
(the calibrated 90 % interval's), enter a `DegradationTrend` with the fault's law; a measurement
the identification could not size (flag ``non_identifiable``, no interval, or a verdict "does not
fit") carries no information and is left out. Diagnoses with verdict "doubtful" are left out too
(and counted, ``doubtful_left_out``) unless asked for (``include_doubtful``). The trend's crossing of the fault's failure
threshold gives the RUL in flights, per fault and for the first failure.

Failure thresholds, as distances from healthy in fault units: given (``--threshold``, or the
``[thresholds]`` table of the actuator file), or the placeholders of `PLACEHOLDER_THRESHOLDS`
(`emaphm.failure`, next-features §B.3), which every output marks ``"placeholder": true``: a
placeholder is not an airworthiness limit.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..failure import FAULTS, PLACEHOLDER_THRESHOLDS, parse_thresholds  # re-exported
from .measurements import correlations, detected, joint_normals, measurement
from .trend import DegradationTrend, RulEstimate, predict_many

__all__ = [
    "ESTIMATORS", "FAULTS", "PLACEHOLDER_THRESHOLDS", "history", "parse_thresholds", "rul_of_rows", "rul_report",
]  # fmt: skip

SAMPLES = 4000
_NO_RUL = {"rul_median": None, "rul_p05": None, "rul_p95": None}
ESTIMATORS = ("trend", "ukf")


def history(
    store: str | os.PathLike[str], actuator: str, campaign: str | None = None
) -> list[dict[str, Any]]:
    """The actuator's rows of a results store, sorted by flight (one-off measurements, flight 0, left out)."""
    from ..campaign.store import ResultStore

    rows = ResultStore(store).read("results", campaign, actuator=actuator).to_pylist()
    if not rows:
        raise InputError(
            f"{store}: no results for actuator {actuator!r}"
            + (f" in campaign {campaign!r}" if campaign else "")
        )
    campaigns = sorted({r["campaign"] for r in rows})
    if len(campaigns) > 1:
        raise InputError(
            f"actuator {actuator!r} is in campaigns {', '.join(campaigns)}: choose one with --campaign"
        )
    rows = [r for r in rows if r["flight"] >= 1]
    if not rows:
        raise InputError(f"actuator {actuator!r} has no history over flights (only one-off measurements)")
    return sorted(rows, key=lambda r: (r["flight"], r["seed"]))


def rul_report(
    store: str | os.PathLike[str],
    actuator: str,
    *,
    campaign: str | None = None,
    at_flight: int | None = None,
    thresholds: dict[str, float] | None = None,
    inspection_interval: float = 10.0,
    seed: int = 0,
    estimator: str = "trend",
    include_doubtful: bool = False,
    unit: str = "flights",
) -> dict[str, Any]:
    """The RUL of each tracked fault and of the first failure, as of flight `at_flight` (default:
    the last one stored), JSON-ready; see the module docstring. `estimator`: "trend"
    (`DegradationTrend`, no dependency) or "ukf" (ProgPy's unscented Kalman filter on the
    `progpy_model.FaultGrowth` model; the ``progpy`` extra). ``_trends`` and ``_estimates`` (not
    JSON) hold the fitted trends and the draws, for a plot.

    Parameters
    ----------
    store : str or path
        The campaign's results store (a directory, `emaphm.campaign`).
    actuator : str
        The actuator's id in the store.
    campaign : str, optional
        The campaign's name, when the store holds several.
    at_flight : int, optional
        The flight the RUL is computed as of (default: the last one stored).
    thresholds : dict of str to float, optional
        Failure threshold per fault, in fault units from healthy (default: the placeholders).
    inspection_interval : float
        Flights (or `unit`) to the next inspection, for the probability of failing before it.
    seed : int
        Seed of the draws of the first failure's distribution.
    estimator : {"trend", "ukf"}
        The tracker (above).
    include_doubtful : bool
        Use the diagnoses with verdict "doubtful" too (default: left out, and counted in
        ``doubtful_left_out``): their faults are what the monitor found, not a sure diagnosis.
    unit : {"flights", "hours", "cycles"}
        The unit of `inspection_interval` and of ``due`` (the first failure's RUL in hours or
        cycles and its date, from the campaign's usage per flight, `usage`; null without it).
    """
    from .usage import UNITS, due, interval_in_flights, rates, read_usage

    if unit not in UNITS:
        raise InputError(f"unknown unit {unit!r}; use one of {', '.join(UNITS)}")
    rows = history(store, actuator, campaign)
    now = float(at_flight if at_flight is not None else rows[-1]["flight"])
    rate = rates(read_usage(store, rows[0]["campaign"]).get((rows[0]["campaign"], actuator)), now)
    report = rul_of_rows(rows, actuator, at_flight=at_flight, thresholds=thresholds,
                         inspection_interval=interval_in_flights(inspection_interval, unit, rate, actuator),
                         seed=seed, estimator=estimator, include_doubtful=include_doubtful)  # fmt: skip
    report.update(unit=unit, inspection_interval=inspection_interval, due=due(report["first_failure"], rate, unit))
    return report


def rul_of_rows(
    rows: list[dict[str, Any]],
    actuator: str,
    *,
    at_flight: int | None = None,
    thresholds: dict[str, float] | None = None,
    inspection_interval: float = 10.0,
    seed: int = 0,
    estimator: str = "trend",
    include_doubtful: bool = False,
) -> dict[str, Any]:
    """`rul_report` on an actuator's rows of a store (`history`: one campaign, flights >= 1,
    sorted by flight), for callers that read many actuators at once (`fleet`)."""
    if estimator not in ESTIMATORS:
        raise InputError(f"unknown estimator {estimator!r}; use one of {', '.join(ESTIMATORS)}")
    if estimator == "ukf":
        from . import progpy_model  # the extra is needed whether or not a fault is tracked
    if at_flight is not None:
        rows = [r for r in rows if r["flight"] <= at_flight]
        if not rows:
            raise InputError(f"actuator {actuator!r} has no flight at or before {at_flight}")
    t_now = float(at_flight if at_flight is not None else rows[-1]["flight"])
    rows, left_out = (rows, 0) if include_doubtful else _sure(rows, actuator)
    faults, tracked = _tracked(rows, dict(thresholds or {}))
    trends: dict[str, Any] = {}
    estimates: dict[str, RulEstimate] = {}
    # the faults' trends drawn together: estimates of one identification are correlated (its
    # corr), and so are the trends fitted to them; this matters for the first failure
    drawn = list(tracked)
    rho = correlations(rows, drawn) if drawn else np.eye(0)
    normals = joint_normals(rho, SAMPLES, 2, seed) if drawn else None
    if estimator == "trend" and drawn:  # all at once (`predict_many`: the same as one by one)
        assert normals is not None
        many = predict_many([tracked[n][0] for n in drawn], [tracked[n][1] for n in drawn], t_now, normals)
    for i, name in enumerate(drawn):
        trend, threshold, entry = tracked[name]
        assert normals is not None
        if estimator == "ukf":
            model, ukf = progpy_model.track(name, entry["law"], threshold, trend.t, trend.k, trend.sd)
            est = progpy_model.predict_rul(model, ukf, t_now, SAMPLES, z=normals[i])
            trends[name] = progpy_model.UkfTrend(trend, ukf)
        else:
            est, trends[name] = many[i], trend
        estimates[name] = est
        faults[name] = {**entry, "status": "tracked", **est.to_json(),
                        "prob_fail_before_next_inspection": round(est.prob_before(inspection_interval), 4)}  # fmt: skip
    faults = {name: faults[name] for name in FAULTS}  # in the order of FAULTS
    first = _first_failure(estimates, drawn, rho, faults, t_now, inspection_interval)
    return {
        "actuator": actuator, "campaign": rows[0]["campaign"], "at_flight": t_now, "estimator": estimator,
        "flights_stored": len({r["flight"] for r in rows}), "inspection_interval": inspection_interval,
        "include_doubtful": include_doubtful, "doubtful_left_out": left_out,
        "faults": faults, "first_failure": first, "_trends": trends, "_estimates": estimates,
    }  # fmt: skip


def _sure(rows: list[dict[str, Any]], actuator: str) -> tuple[list[dict[str, Any]], int]:
    """The rows whose verdict is not "doubtful" and how many were; `InputError` when none is left."""
    doubtful = sum(r.get("verdict") == "doubtful" for r in rows)
    if doubtful == len(rows):
        raise InputError(
            f'all {doubtful} diagnoses of actuator {actuator!r} are doubtful (verdict "doubtful"): pass '
            "--include-doubtful to track them anyway"
        )
    return [r for r in rows if r.get("verdict") != "doubtful"], doubtful


def _tracked(
    rows: list[dict[str, Any]], given: dict[str, float]
) -> tuple[dict[str, Any], dict[str, tuple[DegradationTrend, float, dict[str, Any]]]]:
    """Each fault's entry of the report when it cannot be tracked (not detected, or too few
    measurements), and the trend, threshold and entry of each one that can."""
    faults: dict[str, Any] = {}
    tracked: dict[str, tuple[DegradationTrend, float, dict[str, Any]]] = {}
    for name, (_, law, healthy) in FAULTS.items():
        threshold = given.get(name, PLACEHOLDER_THRESHOLDS[name])
        entry: dict[str, Any] = {"law": law, "threshold": threshold, "placeholder": name not in given}
        onset = next((r["flight"] for r in rows if detected(r, name)), None)
        if onset is None:
            faults[name] = {**entry, "status": "not detected", **_NO_RUL}
            continue
        trend = DegradationTrend(law, healthy)
        used = [
            (r["flight"], m) for r in rows if r["flight"] >= onset and (m := measurement(r, name)) is not None
        ]
        trend.update([f for f, _ in used], [m[0] for _, m in used], [m[1] for _, m in used])
        entry.update(tracked_from=onset, measurements=len(trend))
        if len(set(trend.t)) < 2:
            faults[name] = {**entry, "status": "too few measurements", **_NO_RUL}
            continue
        tracked[name] = (trend, threshold, entry)
    return faults, tracked


def _first_failure(
    estimates: dict[str, RulEstimate],
    drawn: list[str],
    rho: NDArray[np.float64],
    faults: dict[str, Any],
    t_now: float,
    inspection_interval: float,
) -> dict[str, Any]:
    """The RUL of the first failure (the earliest crossing of each joint draw), added to
    `estimates` as "first failure"."""
    first: dict[str, Any] = {"status": "no fault tracked"}
    if estimates:
        stacked = np.vstack([e.samples for e in estimates.values()])
        est = RulEstimate.from_samples(stacked.min(axis=0), t_now)
        first = {
            "status": "tracked", **est.to_json(),
            "correlations": {f"{a}/{b}": round(float(rho[i, j]), 3) for i, a in enumerate(drawn)
                             for j, b in enumerate(drawn) if j > i},
            "prob_fail_before_next_inspection": round(est.prob_before(inspection_interval), 4),
            "most_likely_fault": most_likely_fault(list(estimates), stacked),
            "placeholder_thresholds": sorted(n for n in estimates if faults[n]["placeholder"]),
        }  # fmt: skip
        estimates["first failure"] = est
    return first


def most_likely_fault(names: list[str], draws: np.ndarray) -> str | None:
    """The fault that fails first in most of the draws in which one fails (rows: `names`, columns:
    draws of its time to failure, inf: never); None when most draws never fail. Review M6: argmin
    over a column of inf picked the first fault, counting never-failing draws as its failures."""
    finite = np.isfinite(draws).any(axis=0)
    if not finite.any() or finite.mean() < 0.5:
        return None
    first = np.argmin(draws[:, finite], axis=0)
    return str(names[int(np.argmax(np.bincount(first, minlength=len(names))))])
