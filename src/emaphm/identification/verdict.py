"""Stage 7: the verdict. Does the fit explain the recording, what does the result warn of, and which
faults are present.

Three verdicts (`verdict_of`). A fit whose NRMSE exceeds `limits.FIT_NRMSE_LIMIT` is not a
diagnosis ("does not fit": no faults are reported). A result is "doubtful" (its faults reported,
each reason a warning, `errors.Doubt`) when the recording is explained less well than this
actuator's monitor explains its own twin (`fit_limit`: from the interval calibration's measured
fits), when the search needed its second start, or when a precondition of the diagnosis is not met
(the recording starts in motion, a command the monitor was not calibrated on, little data
compared, a given angle offset the currents contradict). Otherwise it "fits". Faults are detected
by their 90 % intervals against the detection thresholds (`uncertainty.verdicts`), or by the
point rule without intervals (`detection.detect`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import Doubt
from . import limits
from .detection import detect, load_thresholds

if TYPE_CHECKING:
    from ..calibration import Calibration
    from .context import Context
    from .uncertainty import Uncertainty

__all__ = [
    "explains", "fit_distribution", "fit_doubts", "fit_limit", "fit_warnings", "judge", "recording_warnings",
    "verdict_of",
]  # fmt: skip


def fit_distribution(fits: Any) -> dict[str, Any]:
    """How well a monitor explains its own twin, from the fits' NRMSE of identified twin cases
    (`calibration.fit_intervals`): their count, median, p90, p99, max and the NRMSE above which a
    fit is doubtful (`limits.DOUBTFUL_MARGIN` x the `limits.DOUBTFUL_QUANTILE`)."""
    values = np.asarray(fits, dtype=np.float64)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return {"cases": 0}
    q = {name: float(np.quantile(values, p)) for name, p in (("median", 0.5), ("p90", 0.9), ("p99", 0.99))}
    return {
        "cases": int(values.size), **{k: round(v, 6) for k, v in q.items()}, "max": round(float(values.max()), 6),
        "doubtful_above": round(limits.DOUBTFUL_MARGIN * float(np.quantile(values, limits.DOUBTFUL_QUANTILE)), 6),
    }  # fmt: skip


def fit_limit(record: dict[str, Any] | None, monitor: str) -> tuple[float, str]:
    """The NRMSE above which a fit is "doubtful", and where it comes from: the interval
    calibration's measured fits (its record's ``data["fit_nrmse"]``, `fit_distribution`), else the
    monitor's second-search trigger (`limits.SECOND_SEARCH_NRMSE`); with a baseline's own healthy
    fits (``baseline["fit_nrmse"]``, `emaphm.baseline`), at least `limits.DOUBTFUL_MARGIN` x the
    poorest of them: how well the monitor explains this actuator when healthy."""
    record = record or {}
    fits = (record.get("data") or {}).get("fit_nrmse")
    limit, source = (
        limits.SECOND_SEARCH_NRMSE.get(monitor, limits.FIT_NRMSE_WARN),
        "no twin fits measured; the monitor's default",
    )
    if fits:
        measured = fit_distribution(fits)
        if measured["cases"] >= 20:
            limit, source = (
                measured["doubtful_above"],
                f"the interval calibration's {measured['cases']} twin cases",
            )
    own = [f for f in (record.get("baseline") or {}).get("fit_nrmse", []) if np.isfinite(f)]
    if own and limits.DOUBTFUL_MARGIN * max(own) > limit:
        limit, source = limits.DOUBTFUL_MARGIN * max(own), f"the baseline's {len(own)} healthy recordings"
    return limit, source


def explains(fit_nrmse: float | None) -> bool:
    """Whether a fit's NRMSE (`limits.FIT_NRMSE_LIMIT`) makes it a diagnosis; None (not measured) does."""
    return fit_nrmse is None or fit_nrmse <= limits.FIT_NRMSE_LIMIT


def recording_warnings(
    context: Context,
    t: Any,
    theta_cmd: Any,
    calibration: Calibration,
    thresholds: dict[str, float] | None,
    command_rate: float | None = None,
) -> list[str]:
    """What the recording and the inputs leave doubtful: a command the monitor was not calibrated
    on, motion above the band, little data compared, thresholds measured with another monitor."""
    from .coverage import command_warnings

    # a command the monitor was not calibrated on is a precondition not met
    warnings: list[str] = [Doubt(w) for w in command_warnings(t, theta_cmd, calibration, command_rate)]
    if context.above_band > 0:
        warnings.append(
            f"{100 * context.above_band:.0f} % of the recording commands motion faster than the "
            f"{limits.BAND_HZ:g} Hz the monitor was fitted on; it is left out of the comparison (docs/identification.md §3)"
        )
    if context.compared < limits.MIN_COMPARED:
        warnings.append(
            Doubt(
                f"only {100 * context.compared:.0f} % of the recording is compared: the rest is a hold where the surface "
                "rests, whose current does not depend on the faults, or motion faster than the monitor was fitted on; "
                "the diagnosis rests on little data"
            )
        )
    if thresholds is None:
        from ..calibration.files import params_hash
        from ..params import EmaParams

        # the packaged thresholds were measured on the nominal actuator (older files do not say so)
        made_for = load_thresholds().get("params_hash") or params_hash(EmaParams())
        this = params_hash(context.monitor.params)
        if made_for is not None and made_for != this:
            drive = context.monitor.params.inverter.control
            warnings.append(
                f"the detection thresholds were measured on another actuator (hash {made_for}; this one "
                f"{this}, a {drive} drive): run 'emaphm calibrate-detection --params FILE' and pass its "
                "file with --detection"
            )
    measured_with = load_thresholds().get("monitor", "default") if thresholds is None else None
    if measured_with is not None and measured_with != context.monitor.monitor:
        warnings.append(
            f"the detection thresholds were measured with the {measured_with!r} monitor, not the "
            f"{context.monitor.monitor!r} one: faults near them may be reported wrongly"
        )
    return warnings


def fit_warnings(fit_nrmse: float) -> list[str]:
    """The warning of a fit that does not explain the recording (a poor one's is `fit_doubts`')."""
    if not explains(fit_nrmse):
        return [
            f"the monitor cannot explain this recording (NRMSE {100 * fit_nrmse:.3g} % of the "
            f"filtered current, at most {100 * limits.FIT_NRMSE_LIMIT:g} % for a diagnosis): check the units, "
            "signs and command of the trace; no faults are reported"
        ]
    return []


def fit_doubts(fit_nrmse: float, limit: float, source: str, second: dict[str, Any] | None) -> list[str]:
    """The fit's reasons for "doubtful": an NRMSE above this actuator's `limit` (`fit_limit`, from
    `source`; at most `limits.FIT_NRMSE_WARN`), a search that needed its second start
    (`second_search`'s record)."""
    if not explains(fit_nrmse):
        return []  # "does not fit" says it (`fit_warnings`)
    doubts: list[str] = []
    if limit > limits.FIT_NRMSE_WARN:
        limit, source = limits.FIT_NRMSE_WARN, "the cap on every actuator's limit"
    if np.isfinite(fit_nrmse) and fit_nrmse > limit:
        doubts.append(
            Doubt(
                f"the recording is explained less well than this actuator's monitor explains its own twin: "
                f"NRMSE {100 * fit_nrmse:.2f} % against at most {100 * limit:.2f} % ({source}); the faults "
                "are doubtful: check the current's gain, the segment, the command and the actuator file"
            )
        )
    if second is not None and second.get("ran"):
        doubts.append(
            Doubt(
                f"the search needed its second start (its first fit {100 * second['first_fit_nrmse']:.2f} % "
                f"was above {100 * second['trigger']:.2f} %): more than one set of faults nearly explains this "
                "recording, or none does well"
            )
        )
    return doubts


def verdict_of(fit_nrmse: float | None, doubts: list[str]) -> str:
    """ "does not fit" (`explains`), "doubtful" (any reason in `doubts`) or "fits"."""
    if not explains(fit_nrmse):
        return "does not fit"
    return "doubtful" if doubts else "fits"


def judge(
    faults: np.ndarray,
    fit_nrmse: float,
    interval: Uncertainty | None,
    thresholds: dict[str, float] | None,
    balanced: float = 0.0,
) -> tuple[list[str], dict[str, str] | None]:
    """The faults detected and, with intervals, the verdict per fault ("present", "absent",
    "cannot tell"); none when the fit does not explain the recording. `thresholds` overrides the
    shipped detection thresholds ({} reports nothing). Without intervals the point rule judges the
    shorts less the balanced part `balanced` a ψ_m off its nameplate may explain
    (`uncertainty.balanced`; with intervals, their lower ends hold it)."""
    from .uncertainty import verdicts
    from .uncertainty.balanced import discounted

    limits_ = thresholds if thresholds is not None else load_thresholds()["thresholds"]
    if not explains(fit_nrmse):
        return [], None
    if interval is None:
        return detect(discounted(faults, balanced), limits_), None
    judged = verdicts(faults, interval.ci90_low, interval.ci90_high, limits_)
    return [name for name, v in judged.items() if v == "present"], judged
