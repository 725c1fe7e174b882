"""The fleet at a glance: every actuator of a results store ranked by urgency (issue 35).

For each actuator (of each campaign) of the store:

- its **latest diagnosis** (the highest flight, then the last finished) and its verdict;
- its **worst fault** as a share of that fault's failure threshold, from the latest diagnosis that
  sizes faults (verdict "fits" or "doubtful"; "does not fit" sizes nothing), so that one
  measurement already over a threshold is flagged now (`exceeded`);
- its **first-failure RUL** (5 %, median, 95 %) and the probability of failing before the next
  inspection, from the history of its diagnoses (`rul.rul_of_rows`: the same numbers as
  ``emaphm rul``; doubtful diagnoses left out unless `include_doubtful`);
- the **remaining share** of the inspection interval: the RUL's 5 % quantile over the interval;
  without a trend (one flight, or no fault tracked) the worst fault's margin to its threshold,
  1 − share; a fault at or over its threshold makes it ≤ 0. Its colour is the code of aviation
  fleet dashboards: red ≤ 0, orange ≤ 0.25, yellow ≤ 0.5, green above. An actuator none of whose
  diagnoses sizes its faults is yellow: its state is unknown, re-measure it.

Sorted by urgency: the remaining share, lowest first (unknown last within its colour), then the
share of the threshold, highest first.

Thresholds per fault: `thresholds` given (``--threshold``, ``--params``), else the ``[thresholds]``
of the actuator file its jobs identified with (the campaign's ``params``), else the placeholders
(`failure.PLACEHOLDER_THRESHOLDS`, marked ``placeholder``).
"""

from __future__ import annotations

import datetime as _dt
import math
import os
from collections.abc import Callable
from typing import Any

from .._threads import usable_cores
from ..errors import InputError
from ..failure import FAULTS, PLACEHOLDER_THRESHOLDS
from .fleet_entry import BANDS, COLOURS, colour_of, entry, thresholds_of
from .usage import UNITS, read_usage

__all__ = ["BANDS", "COLOURS", "colour_of", "fleet_report"]

K = [f"k{i}" for i in range(1, 9)]
# what every diagnosis of a history is read for (its trend), and what only its latest one is
CORE = [
    "campaign", "actuator", "flight", "seed", "finished", "verdict", "fault_verdicts", "uq_flags", "corr",
    "detected", *K, *(f"std_{k}" for k in K),
]  # fmt: skip
BOUNDS = [*(f"ci90_low_{k}" for k in K), *(f"ci90_high_{k}" for k in K)]  # the charts' whiskers
LATEST = ["doubts", "fit_nrmse", "settings", "warnings", "reference", "reference_sha256", "job_key", "identify_seed",
          "version"]  # fmt: skip


def fleet_report(
    store: str | os.PathLike[str],
    *,
    campaign: str | None = None,
    thresholds: dict[str, float] | None = None,
    inspection_interval: float = 10.0,
    seed: int = 0,
    include_doubtful: bool = False,
    charts: bool = False,
    unit: str = "flights",
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Every actuator of the results store `store` (of `campaign`), ranked by urgency (module
    docstring), JSON-ready but for each entry's ``_series`` (for the page's charts).

    Parameters
    ----------
    store : str or path
        A campaign's results store (``emaphm campaign run --out``).
    campaign : str, optional
        Only this campaign's actuators.
    thresholds : dict of str to float, optional
        Failure thresholds per fault (distance from healthy, fault units), for every actuator.
    inspection_interval : float
        Flights (or `unit`) to the next inspection.
    seed : int
        Seed of the RUL draws (as ``emaphm rul --seed``).
    include_doubtful : bool
        Track the doubtful diagnoses too (default: left out of the trends, and counted).
    unit : {"flights", "hours", "cycles"}
        The unit of `inspection_interval`, and of each entry's ``due`` RUL (`usage`: the campaign's
        usage per flight; `InputError` for an actuator without it).
    charts : bool
        Give each entry the data of its trend chart (``_series``, `fleet_series.series`; else {});
        in a fleet of more than `ALL_CHARTS` actuators only those that are not green (the others'
        ``_series`` is None: left out).
    progress : callable, optional
        Called with (actuators done, actuators) now and then.
    """
    from .._version import __version__
    from ..campaign.store import ResultStore

    if not inspection_interval > 0:
        raise InputError(f"the inspection interval must be > 0 flights, got {inspection_interval}")
    if unit not in UNITS:
        raise InputError(f"unknown unit {unit!r}; use one of {', '.join(UNITS)}")
    ids = ResultStore(store).actuators(campaign)
    if not ids:
        raise InputError(f"{store}: no results" + (f" of campaign {campaign!r}" if campaign else ""))
    options = {"store": str(store), "campaign": campaign, "thresholds": thresholds, "interval": inspection_interval,
               "seed": seed, "unit": unit, "include_doubtful": include_doubtful, "usage": read_usage(store, campaign),
               # every chart for a small fleet, the ones not green for a large one
               "charts": None if not charts else "all" if len(ids) <= ALL_CHARTS else "urgent"}  # fmt: skip
    entries = _ranked_parts(ids, options, progress)
    counts = {c: sum(e["colour"] == c for e in entries) for c in COLOURS}
    counts.update({v: sum(e["verdict"] == v for e in entries) for v in ("doubtful", "does not fit")})
    return {
        "store": str(store), "campaign": campaign, "version": __version__,
        "generated": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"), "unit": unit,
        "inspection_interval": inspection_interval, "include_doubtful": include_doubtful, "seed": seed,
        "thresholds": _threshold_table(thresholds), "counts": counts, "actuators": entries,
    }  # fmt: skip


def _ranked_parts(
    ids: list[str], options: dict[str, Any], progress: Callable[[int, int], None] | None
) -> list[Any]:
    """The entries of the actuators `ids`, ranked; a large fleet's second half read and computed
    in a second process (`PARALLEL_FROM` actuators or more, and more than one core)."""
    if len(ids) >= PARALLEL_FROM and usable_cores() > 1:
        import concurrent.futures
        import multiprocessing

        half = len(ids) // 2
        with concurrent.futures.ProcessPoolExecutor(
            1, mp_context=multiprocessing.get_context("spawn")
        ) as pool:
            future = pool.submit(_entries_of, ids[half:], options, None)
            entries = _entries_of(ids[:half], options, progress, scale=len(ids) / half)
            entries += future.result()
    else:
        entries = _entries_of(None, options, progress)
    if progress is not None:
        progress(len(ids), len(ids))
    entries.sort(key=_urgency)
    return entries


def _entries_of(
    ids: list[str] | None,
    options: dict[str, Any],
    progress: Callable[[int, int], None] | None,
    scale: float = 1.0,
) -> list[dict[str, Any]]:
    """The entries of the actuators `ids` (None: all) of the store, read here (each process reads
    its own half of a large fleet: no table crosses between them)."""
    from ..campaign.store import ResultStore

    columns = CORE + LATEST + (BOUNDS if options["charts"] else [])  # the bounds draw the charts' whiskers
    table = ResultStore(options["store"]).read("results", options["campaign"], columns=columns, actuators=ids)
    table = table.sort_by([(c, "ascending") for c in ("campaign", "actuator", "flight", "finished", "seed")])
    return _entries(table, _groups(table), options, progress, scale)


ALL_CHARTS = 1000  # actuators up to which every one's chart data is made (above: the ones not green)
PARALLEL_FROM = 2000  # actuators from which a second process computes half the fleet


def _groups(table: Any) -> list[tuple[int, int]]:
    """(start, length) of each actuator's rows in a table sorted by campaign and actuator."""
    keys = list(zip(table.column("campaign").to_pylist(), table.column("actuator").to_pylist(), strict=True))
    bounds, start = [], 0
    for i in range(1, len(keys) + 1):
        if i == len(keys) or keys[i] != keys[start]:
            bounds.append((start, i - start))
            start = i
    return bounds


def _entries(
    table: Any,
    bounds: list[tuple[int, int]],
    options: dict[str, Any],
    progress: Callable[[int, int], None] | None,
    scale: float = 1.0,
) -> list[dict[str, Any]]:
    """One entry per actuator (`bounds`: its rows of the sorted `table`), on one BLAS thread (its
    pool's threads spin beside the other process's: 8.4 s against 14.6 s for 10 000 actuators)."""
    from threadpoolctl import threadpool_limits

    own: dict[str | None, dict[str, float]] = {}
    entries = []
    # the columns of every row, then the latest row's others: 200 000 rows x 55 columns as Python
    # objects cost seconds
    core, rest = table.select(CORE + (BOUNDS if options["charts"] else [])), table.select(LATEST)
    with threadpool_limits(limits=1, user_api="blas"):
        for i, (start, length) in enumerate(bounds):
            rows = core.slice(start, length).to_pylist()
            rows[-1].update(rest.slice(start + length - 1, 1).to_pylist()[0])
            limits = thresholds_of(rows[-1], options["thresholds"], own)
            key = (rows[0]["campaign"], rows[0]["actuator"])
            entries.append(entry(key[0], key[1], rows, limits, options, options["usage"].get(key)))
            if progress is not None and i % 500 == 0:
                progress(int(i * scale), int(len(bounds) * scale))
    return entries


def _threshold_table(given: dict[str, float] | None) -> dict[str, dict[str, Any]]:
    given = given or {}
    return {
        n: {"threshold": given.get(n, PLACEHOLDER_THRESHOLDS[n]), "placeholder": n not in given}
        for n in FAULTS
    }


def _urgency(entry: dict[str, Any]) -> tuple[int, float, float, str]:
    remaining = entry["remaining_share"]
    return (
        COLOURS.index(entry["colour"]),
        math.inf if remaining is None else remaining,
        -(entry["threshold_share"] or 0.0),
        entry["actuator"],
    )
