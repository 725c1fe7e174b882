"""ProgPy's metrics of a sequence of RUL predictions (issue 12): α-λ, prognostic horizon,
cumulative relative accuracy.

`toe_profile` turns predictions (flight of prediction -> draws of the crossing flight per event)
into ProgPy's ``ToEPredictionProfile``; `progpy_metrics` scores it against the true crossing
flights. ProgPy is the optional ``progpy`` extra (see `emaphm.prognostics.progpy_model`); without
it this module raises `InputError` naming the extra.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._progpy import ToEPredictionProfile, UnweightedSamples

__all__ = ["progpy_metrics", "toe_profile"]


def toe_profile(predictions: Mapping[float, Mapping[str, ArrayLike]], never: float) -> Any:
    """ProgPy's ``ToEPredictionProfile`` of a sequence of predictions: flight of prediction ->
    {event: draws of the absolute crossing flight}. ProgPy's metrics take neither ``None`` nor
    ``inf``: a draw that never crosses counts as the flight `never` (past any end of life)."""
    profile = ToEPredictionProfile()
    for t_pred, events in predictions.items():
        cols = {
            e: np.where(np.isfinite(v := np.asarray(s, dtype=np.float64)), v, never)
            for e, s in events.items()
        }
        n = len(next(iter(cols.values())))
        profile.add_prediction(
            float(t_pred), UnweightedSamples([{e: float(c[i]) for e, c in cols.items()} for i in range(n)])
        )
    return profile


def progpy_metrics(
    profile: Any,
    ground_truth: Mapping[str, float],
    *,
    lambda_value: float,
    alpha: float = 0.2,
    beta: float = 0.5,
    onset: float | None = None,
) -> dict[str, dict[str, Any]]:
    """ProgPy's metrics of a `toe_profile` against the true crossing flights: α-λ (the first
    prediction at or after `lambda_value`: at least `beta` of the draws within α of the true RUL),
    the prognostic horizon (from the first prediction whose median lies within α·(life) of the
    truth, where life counts from `onset`, default the first prediction) and the cumulative relative
    accuracy (ProgPy's: of the time of event, from the *mean* of the draws, so a draw that never
    crosses pulls it by the `never` it was given in `toe_profile`). Returns {event:
    {"alpha_lambda", "prognostic_horizon", "cra"}}."""
    from progpy.metrics import alpha_lambda, cumulative_relative_accuracy, prognostic_horizon

    first = min(profile.keys()) if onset is None else float(onset)
    life = {e: gt - first for e, gt in ground_truth.items()}

    def criterion(tte: Any, gt_tte: Mapping[str, float]) -> dict[str, bool]:
        # the median of each event's draws: ProgPy's own ``UnweightedSamples.median`` is the draw
        # nearest the mean, found in O(n²) Python (minutes for 4 000 draws), not a median
        return {e: abs(float(np.median(tte.key(e))) - gt_tte[e]) <= alpha * life[e] for e in gt_tte}

    al = alpha_lambda(profile, dict(ground_truth), lambda_value, alpha, beta) or {}
    ph = prognostic_horizon(profile, criterion, dict(ground_truth))
    cra = cumulative_relative_accuracy(profile, dict(ground_truth))
    return {
        e: {"alpha_lambda": bool(al.get(e, False)), "prognostic_horizon": ph.get(e), "cra": float(cra[e])}
        for e in ground_truth
    }
