"""The inputs an actuator's own baseline gives a diagnosis (issue 33): its files and settings
(`with_baseline`), and the recording divided by the current sensor's gain it measured
(`divided_by_gain`)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from ..results import SimResult
from .recording import Measurement
from .settings import IdentifySettings

__all__ = ["divided_by_gain", "with_baseline"]


def with_baseline(
    baseline: Any, s: IdentifySettings, params: Any, calibration: Any, uq_calibration: Any, thresholds: Any
) -> tuple[Any, ...]:
    """The settings and the inputs a baseline folder gives (`baseline.baseline_inputs`), its
    record (with ``table_from``, the nameplate's files, or ``table_skipped``, why not) and the
    nameplate's monitor whose start table the search starts from; as given without one (and no
    monitor). A folder without the
    nameplate's files (made before them, or from another actuator's calibration) makes the start
    "auto" uniform: one actuator's own table would serve few diagnoses for its 9 s build
    (docs/identification.md §3)."""
    if baseline is None:
        return s, params, calibration, uq_calibration, thresholds, None, None
    from ..baseline import baseline_inputs

    b = baseline_inputs(baseline, params=params, calibration=calibration, uq_calibration=uq_calibration,
                        thresholds=thresholds)  # fmt: skip
    return (
        s.replace(start="random") if s.start == "auto" and b["table_from"] is None else s,  # recorded so
        b["params"],
        b["calibration"],
        b["uq_calibration"],
        b["thresholds"],
        {**b["record"], "current_gain": b["current_gain"], "table_from": b["table_from"],
         "table_skipped": b["table_skipped"]},
        b["table_monitor"],
    )


def divided_by_gain(m: Measurement, used: dict[str, Any] | None) -> Measurement:
    """The measurement with its current divided by the sensor's gain the baseline `used` measured."""
    if used is None or used["current_gain"] == 1.0:
        return m
    signals = {**m.trace.signals, "i_q": m.trace.i_q / used["current_gain"]}
    return replace(m, trace=SimResult(t=m.trace.t, signals=signals, metadata=m.trace.metadata))
