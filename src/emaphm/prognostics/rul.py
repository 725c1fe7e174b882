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

import json
import math
import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..failure import FAULTS, PLACEHOLDER_THRESHOLDS, parse_thresholds  # re-exported
from .trend import DegradationTrend, RulEstimate

__all__ = ["ESTIMATORS", "FAULTS", "PLACEHOLDER_THRESHOLDS", "history", "parse_thresholds", "rul_report"]

SAMPLES = 4000
_NO_RUL = {"rul_median": None, "rul_p05": None, "rul_p95": None}
ESTIMATORS = ("trend", "ukf")
USED_VERDICTS = ("fits", "doubtful")  # of the rows kept (`rul_report`'s include_doubtful)


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


def _measurement(row: dict[str, Any], name: str) -> tuple[float, float] | None:
    """(value, sd) of a fault in one row, or None where the row tells nothing about it."""
    column = FAULTS[name][0]
    j = int(column[1:]) - 1
    if row.get("verdict") not in USED_VERDICTS:  # "does not fit" sizes nothing; doubtful ones chosen before
        return None
    flags = json.loads(row["uq_flags"]) if row.get("uq_flags") else None
    if flags is not None and "non_identifiable" in flags[j]:
        return None
    sd = row.get(f"std_{column}")
    if sd is None or not math.isfinite(sd) or sd <= 0:
        return None
    return float(row[column]), float(sd)


def _correlations(rows: list[dict[str, Any]], names: list[str]) -> NDArray[np.float64]:
    """The mean correlation between the estimates of faults `names` over the rows that sized both
    (each identification's ``corr``; none recorded: 0), as a correlation matrix."""
    n = len(names)
    total, count = np.zeros((n, n)), np.zeros((n, n))
    for row in rows:
        corr = json.loads(row["corr"]) if row.get("corr") else None
        if corr is None:
            continue
        used = [_measurement(row, name) is not None for name in names]
        for a in range(n):
            for b in range(a + 1, n):
                ja, jb = (int(FAULTS[names[i]][0][1:]) - 1 for i in (a, b))
                value = corr[ja][jb]
                if used[a] and used[b] and value is not None and math.isfinite(value):
                    total[a, b] += value
                    count[a, b] += 1
    rho = np.divide(total, count, out=np.zeros((n, n)), where=count > 0)
    rho = rho + rho.T + np.eye(n)
    w, V = np.linalg.eigh(rho)  # a mean of correlation matrices is one; clip rounding below 0
    rho = (V * np.maximum(w, 1e-9)) @ V.T
    d = np.sqrt(np.diag(rho))
    return np.asarray(rho / np.outer(d, d), dtype=np.float64)


def _joint_normals(rho: NDArray[np.float64], n: int, dims: int, seed: int) -> NDArray[np.float64]:
    """(faults, n, dims) standard normal draws, fault f's correlated with fault g's by rho[f, g]
    component by component (a Gaussian copula on the trends' posteriors)."""
    L = np.linalg.cholesky(rho)
    z = np.random.default_rng(seed).standard_normal((n, dims, len(rho)))
    return np.asarray(np.moveaxis(z @ L.T, -1, 0), dtype=np.float64)


def _detected(row: dict[str, Any], name: str) -> bool:
    verdicts = json.loads(row["fault_verdicts"]) if row.get("fault_verdicts") else None
    if verdicts is not None:
        return bool(verdicts.get(name) == "present")
    return name in (row.get("detected") or "").split(",")


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
        Flights to the next inspection, for the probability of failing before it [flights].
    seed : int
        Seed of the draws of the first failure's distribution.
    estimator : {"trend", "ukf"}
        The tracker (above).
    include_doubtful : bool
        Use the diagnoses with verdict "doubtful" too (default: left out, and counted in
        ``doubtful_left_out``): their faults are what the monitor found, not a sure diagnosis.
    """
    if estimator not in ESTIMATORS:
        raise InputError(f"unknown estimator {estimator!r}; use one of {', '.join(ESTIMATORS)}")
    if estimator == "ukf":
        from . import progpy_model  # the extra is needed whether or not a fault is tracked
    rows = history(store, actuator, campaign)
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
    rho = _correlations(rows, drawn) if drawn else np.eye(0)
    normals = _joint_normals(rho, SAMPLES, 2, seed) if drawn else None
    for i, name in enumerate(drawn):
        trend, threshold, entry = tracked[name]
        assert normals is not None
        if estimator == "ukf":
            model, ukf = progpy_model.track(name, entry["law"], threshold, trend.t, trend.k, trend.sd)
            est = progpy_model.predict_rul(model, ukf, t_now, SAMPLES, z=normals[i])
            trends[name] = progpy_model.UkfTrend(trend, ukf)
        else:
            est = trend.predict_rul(threshold, t_now, SAMPLES, z=normals[i])
            trends[name] = trend
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
            f"all {doubtful} diagnoses of actuator {actuator!r} are doubtful (verdict \"doubtful\"): pass "
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
        onset = next((r["flight"] for r in rows if _detected(r, name)), None)
        if onset is None:
            faults[name] = {**entry, "status": "not detected", **_NO_RUL}
            continue
        trend = DegradationTrend(law, healthy)
        used = [
            (r["flight"], m)
            for r in rows
            if r["flight"] >= onset and (m := _measurement(r, name)) is not None
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
